//! `fit thermal`: the RLG thermal bias model fitted on a chamber run
//! (calibration/thermal/): the coefficient file the firmware loads, the
//! JSON, the text and the report.

use super::checks::Checked;
use super::reports;
use super::run_inputs::thermal_run;
use crate::calibration::thermal::summary::{calibrate, FitSummary};
use crate::data::read_spec::ReadSpec;
use crate::data::source::Source;
use crate::error::LabError;
use crate::report::document::Report;
use gyro_coeffs::file::{CoeffFile, FittedRange};

/// What a fit found: the coefficient file's text, the JSON, the text and
/// the report (when asked).
pub struct FitOutcome {
    pub coeffs_toml: String,
    /// The CRC of the record the firmware loads.
    pub record_crc32: String,
    pub json: serde_json::Value,
    pub text: Vec<String>,
    pub report: Option<Report>,
}

/// The JSON with the record checks added.
pub(super) fn with_checks(v: serde_json::Value, c: &Checked) -> serde_json::Value {
    let mut j = v;
    c.json(&mut j);
    j
}

/// The RLG thermal model fitted on a chamber run.
pub fn fit_thermal(source: Source, spec: &ReadSpec, report: bool) -> Result<FitOutcome, LabError> {
    let (_, d, checked) = thermal_run(source, spec)?;
    let mut s: FitSummary = calibrate(&d).map_err(|e| source.origin().whole(e.to_string()))?;
    s.warnings.splice(0..0, checked.calibration_warnings());
    let c = s.coefficients;
    let mut info = toml::Table::new();
    info.insert("data".into(), source.name().into());
    info.insert("rows".into(), (d.t.len() as i64).into());
    for (k, v) in [
        ("raw_std_100s_dph", s.raw_std_100s_dph),
        ("residual_std_100s_dph", s.residual_std_100s_dph),
        ("cubic_std_100s_dph", s.cubic_std_100s_dph),
        ("noise_floor_100s_dph", s.noise_floor_100s_dph),
    ] {
        info.insert(k.into(), v.into());
    }
    for (k, [lo, hi]) in [
        ("mono_a_range_c", s.mono_a_range_c),
        ("case_range_c", s.case_range_c),
    ] {
        info.insert(k.into(), toml::Value::Array(vec![lo.into(), hi.into()]));
    }
    let record_crc32 = format!("0x{:08x}", gyro_coeffs::record::crc_of(&c.to_record()));
    info.insert("record_crc32".into(), record_crc32.clone().into());
    let mut file = CoeffFile::rlg_thermal(c, info);
    let lo = s.mono_a_range_c[0].min(s.case_range_c[0]);
    let hi = s.mono_a_range_c[1].max(s.case_range_c[1]);
    file.range = Some(FittedRange { temp_c: [lo, hi] });
    let coeffs_toml = gyro_coeffs::file::to_text(
        &file,
        "RLG thermal bias model (docs/rlg.md), written by gyro-lab fit thermal.\n\
         B = bias0 + k1*dT + k2*grad(dT) + k3*dT^2 + k4*T_K + k5*(1 - exp(-t/tau_warm)), deg/h;\n\
         dT = t_mono_a - t_mono_b. Load with `gyro-lab compensate` or build the firmware with RLG_COEFFS=<this file>.",
    )
    .map_err(|e| LabError::Io { file: None, msg: e })?;
    let report = report.then(|| reports::thermal::report(&source.name(), &d, &s));
    let mut text = vec![];
    let v = s.coefficients.values();
    let e = s.coefficient_se.map(|c| c.values());
    let names = gyro_sp::rlg::ThermalCoeffs::NAMES;
    for (k, n) in names.iter().enumerate() {
        text.push(match e {
            Some(e) => format!("  {n:<20} {:>12.6} +- {:.6}", v[k], e[k]),
            None => format!("  {n:<20} {:>12.6} (standard error not available)", v[k]),
        });
    }
    let se = s.std_100s_se_dph;
    text.push(format!(
        "std of 100 s means (+- standard error): raw {:.4} +- {:.4} deg/h, classic cubic {:.4} +- {:.4}, \
         improved model {:.4} +- {:.4}, noise floor {:.4} +- {:.4}",
        s.raw_std_100s_dph,
        se[0],
        s.cubic_std_100s_dph,
        se[2],
        s.residual_std_100s_dph,
        se[1],
        s.noise_floor_100s_dph,
        se[3]
    ));
    text.extend(s.warnings.iter().map(|w| format!("warning: {}", w.message)));
    let json = with_checks(serde_json::to_value(&s).unwrap_or_default(), &checked);
    Ok(FitOutcome {
        coeffs_toml,
        record_crc32,
        json,
        text,
        report,
    })
}
