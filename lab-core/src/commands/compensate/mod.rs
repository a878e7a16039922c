//! `compensate`: a coefficient set (by its `kind`) applied to a run as the
//! firmware applies it (the same code, the same fixed-point arithmetic),
//! or a model from `discover` (model.rs): the compensated rate, the
//! figures before and after, the report.

mod coeffs;
mod model;
mod outcome;

pub use coeffs::{read_coeffs, CoeffSet, KINDS};
pub use outcome::{CompensateOutcome, Request};

use crate::calibration::scale_factor::validation::validate;
use crate::calibration::thermal::compensation::compensate;
use crate::calibration::thermal::fit::CubicModel;
use crate::calibration::thermal::summary::{compensation_summary, CalibratedRange};
use crate::commands::checks::{self, Checked};
use crate::commands::reports;
use crate::commands::run_inputs::thermal_run;
use crate::data::run_file::{Column, Reference, RunFile};
use crate::error::LabError;
use gyro_coeffs::ScaleFactorTable;
use gyro_sp::rlg::ThermalCoeffs;

/// Applies the coefficient set to the run.
pub fn compensate_run<'a>(req: &Request<'a>) -> Result<CompensateOutcome<'a>, LabError> {
    let comment = format!(
        "gyro-lab compensate: {} applied to {}",
        req.coeffs_name,
        req.source.name()
    );
    let mut o = match req.coeffs {
        CoeffSet::RlgThermal(c, range) => rlg_thermal(req, c, *range)?,
        CoeffSet::FogScaleFactor(t) => fog_scale_factor(req, t)?,
        CoeffSet::Model(m, gyro) => model::apply(req, m, *gyro)?,
    };
    o.comment = comment;
    Ok(o)
}

fn with_checks(v: serde_json::Value, c: &Checked) -> serde_json::Value {
    let mut j = v;
    c.json(&mut j);
    j
}

fn rlg_thermal<'a>(
    req: &Request<'a>,
    c: &ThermalCoeffs,
    range: Option<CalibratedRange>,
) -> Result<CompensateOutcome<'a>, LabError> {
    let (run, d, checked) = thermal_run(req.source, req.spec)?;
    let (comp, flags) = compensate(c, &d, &run.run.rate_dps);
    let cubic = match req.cubic_from {
        Some(src) => {
            let (_, dc, _) = thermal_run(src, req.spec)?;
            Some(
                CubicModel::fit(&dc.a, &dc.drift_dph)
                    .ok_or_else(|| src.origin().whole("cubic fit failed"))?,
            )
        }
        None => None,
    };
    let mut s = compensation_summary(
        c,
        &d,
        &run.run.ref_rate_dps,
        (&comp, &flags),
        cubic.as_ref(),
        range,
    );
    s.warnings.splice(0..0, checked.calibration_warnings());
    let report = req.report.then(|| {
        let names = (req.coeffs_name.to_owned(), req.source.name());
        reports::compensate::thermal(&names, &d, &s)
    });
    let mut text = vec![format!(
        "std of 100 s means: raw {:.4} +- {:.4} deg/h, compensated {:.4} +- {:.4} deg/h ({:.2}x the noise floor {:.4} +- {:.4}){}",
        s.raw_std_100s_dph,
        s.raw_std_100s_se_dph,
        s.comp_std_100s_dph,
        s.comp_std_100s_se_dph,
        s.comp_over_floor,
        s.noise_floor_100s_dph,
        s.noise_floor_100s_se_dph,
        s.cubic_std_100s_dph
            .map_or(String::new(), |v| format!(", classic cubic {v:.4}"))
    )];
    if s.coeffs_refused {
        text.push(
            "coefficients refused by the firmware check: ran on the safe set (no compensation)"
                .into(),
        );
    }
    text.extend(s.warnings.iter().map(|w| format!("warning: {}", w.message)));
    let json = with_checks(serde_json::to_value(&s).unwrap_or_default(), &checked);
    Ok(CompensateOutcome {
        run,
        comp_dps: comp,
        json,
        text,
        report,
        comment: String::new(),
    })
}

fn fog_scale_factor<'a>(
    req: &Request<'a>,
    table: &ScaleFactorTable,
) -> Result<CompensateOutcome<'a>, LabError> {
    let (mut run, [temp]) = RunFile::read(
        req.source,
        req.spec,
        Reference::ZeroIfAbsent,
        2,
        [Column::Temp],
    )?;
    let checked = checks::run(&mut run.run, req.spec)?;
    let (t, w, y) = (&run.run.t_s, &run.run.ref_rate_dps, &run.run.rate_dps);
    let mut v = validate(table, t, w, y, &temp);
    v.warnings.splice(0..0, checked.calibration_warnings());
    let report = req.report.then(|| {
        let names = (req.coeffs_name.to_owned(), req.source.name());
        reports::compensate::scale_factor(&names, &v)
    });
    let (raw, raw_se, c, c_se, m) = (
        v.raw_ppm.value,
        v.raw_ppm.se,
        v.comp_ppm.value,
        v.comp_ppm.se,
        v.windows,
    );
    let mut text = vec![];
    if m == 0 {
        text.push("no 60 s stretch at a constant nonzero rate: no scale-factor figure".into());
    } else {
        text.push(format!(
            "scale-factor error, RMS of {m} 60 s means: raw {raw:.2} +- {raw_se:.2} ppm, compensated {c:.3} +- {c_se:.3} ppm (noise floor {:.3})",
            v.noise_floor_ppm.value
        ));
    }
    if v.flags_seen != 0 {
        text.push(format!(
            "flags seen {:#04x} (1 coil sensor bad, 2 outside the calibrated range, 4 table refused)",
            v.flags_seen
        ));
    }
    text.extend(v.warnings.iter().map(|w| format!("warning: {}", w.message)));
    // RMS of the scale-factor error over 60 s means of the rotating rows,
    // ppm, before and after, with standard errors; the validation's keys.
    let mut j = serde_json::to_value(&v).unwrap_or_default();
    for (k, x) in [
        ("raw_ppm", serde_json::json!(raw)),
        ("raw_ppm_se", serde_json::json!(raw_se)),
        ("comp_ppm", serde_json::json!(c)),
        ("comp_ppm_se", serde_json::json!(c_se)),
        ("windows", serde_json::json!(m)),
        ("flags_seen", serde_json::json!(v.flags_seen)),
    ] {
        j[k] = x;
    }
    let comp = v.comp_dps.clone();
    Ok(CompensateOutcome {
        run,
        comp_dps: comp,
        json: with_checks(j, &checked),
        text,
        report,
        comment: String::new(),
    })
}
