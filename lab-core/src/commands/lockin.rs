//! `lockin`: the RLG lock-in rate of a fringe record by the exact
//! harmonic relation (calibration/lockin.rs): the JSON, the text and the
//! report.

use super::reports;
use crate::calibration::lockin::lock_in;
use crate::data::fringe_file::FringeFile;
use crate::data::read_spec::ReadSpec;
use crate::data::source::Source;
use crate::error::LabError;
use crate::report::document::Report;

/// The least lock-in rate a ring laser gyro has, deg/s (physics.md 2.1
/// gives 0.01 .. 0.5 for the reference gyros).
pub const LOCK_IN_MIN_DPS: f64 = 0.002;

/// What `lockin` found.
pub struct LockinOutcome {
    pub json: serde_json::Value,
    pub text: Vec<String>,
    pub report: Option<Report>,
}

/// The lock-in rate of a fringe record: `pulses_per_deg` the scale factor
/// K, the input rate given or estimated from the record.
pub fn lockin(
    source: Source,
    spec: &ReadSpec,
    pulses_per_deg: f64,
    input_rate_dps: Option<f64>,
    report: bool,
) -> Result<LockinOutcome, LabError> {
    if !(pulses_per_deg.is_finite() && pulses_per_deg > 0.0) {
        return Err(LabError::Usage(format!(
            "pulses per degree {pulses_per_deg}: must be positive"
        )));
    }
    if let Some(w) = input_rate_dps {
        if !w.is_finite() || w == 0.0 {
            return Err(LabError::Usage(format!(
                "input rate {w} deg/s: must be finite and non-zero"
            )));
        }
    }
    let mut f = FringeFile::read(source, spec, 64)?;
    let sampling = crate::record::sampling::regularise(&mut f.t_s);
    let mut r = lock_in(
        &f.t_s,
        &f.signal,
        f.signal_q.as_deref(),
        pulses_per_deg,
        input_rate_dps,
    )
    .map_err(|e| source.origin().whole(e.to_string()))?;
    // Lock-in rates of real RLGs are 0.01 .. 1 deg/s (physics.md 2.1): far
    // below, the record's time or K is likely in another unit.
    if r.lock_in_dps < LOCK_IN_MIN_DPS {
        r.warnings.push(crate::calibration::warning::Warning::new(
            "unit",
            format!(
                "a lock-in of {} deg/s is below any RLG's ({LOCK_IN_MIN_DPS} deg/s at least): is the time column in ms (--time-unit ms, a factor of 1000) or K in another unit?",
                crate::report::text::sig(r.lock_in_dps)
            ),
        ));
    }
    let rep = report.then(|| reports::lockin::report(&source.name(), &f.t_s, &f.signal, &r));
    let mut j = serde_json::to_value(&r).unwrap_or_default();
    j["sampling"] = serde_json::to_value(&sampling).unwrap_or_default();
    if let Some(w) = sampling.warning() {
        let mut list = j["warnings"].as_array().cloned().unwrap_or_default();
        list.push(serde_json::to_value(w).unwrap_or_default());
        j["warnings"] = list.into();
    }
    let mut out = vec![];
    if let Some(w) = sampling.warning() {
        out.push(format!("WARNING ({}): {}", w.code, w.message));
    }
    out.push(format!(
        "lock-in {:.6} deg/s (+-{:.6}), input rate {:.6} deg/s ({}), beat {:.3} Hz, rho {:.6}",
        r.lock_in_dps,
        r.lock_in_std_dps,
        r.input_rate_dps,
        if r.input_rate_given {
            "given"
        } else {
            "estimated"
        },
        r.beat_hz,
        r.harmonic_ratio
    ));
    out.push(format!(
        "published approximate formula on the same record: {:.6} deg/s",
        r.lock_in_approx_dps
    ));
    out.push(format!(
        "relative one-sigma {:.4} % against the Cramer-Rao bound {:.4} % (Omega_I/Omega_L {:.1})",
        100.0 * r.lock_in_rel_std,
        100.0 * r.cramer_rao_rel,
        r.rate_ratio
    ));
    for w in &r.warnings {
        out.push(format!("warning: {}", w.message));
    }
    Ok(LockinOutcome {
        json: j,
        text: out,
        report: rep,
    })
}
