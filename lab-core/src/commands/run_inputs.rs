//! Run files turned into what each calibration takes, with the record
//! checks (checks.rs) and the checks a calibration makes of a run placed
//! at the file's columns.

use crate::calibration::scale_factor::fit::{check_run, RunCheck, MIN_ROTATING_ROWS};
use crate::calibration::scale_factor::input::{prepare, SfInput, MIN_RATE_DPS, MIN_SPAN_C};
use crate::calibration::thermal::fit::ThermalData;
use crate::commands::checks::{self, Checked};
use crate::data::read_spec::ReadSpec;
use crate::data::run_file::{Column, Reference, RunFile, RunText};
use crate::data::source::Source;
use crate::error::LabError;

/// A chamber run for the RLG thermal model: at least 200 rows with the two
/// monoblock sensors and the case sensor (a run without `ref_rate_dps` is
/// a static one, and said so).
pub fn thermal_run<'a>(
    source: Source<'a>,
    spec: &ReadSpec,
) -> Result<(RunText<'a>, ThermalData, Checked), LabError> {
    let (mut text, [a, b, case]) = RunFile::read(
        source,
        spec,
        Reference::ZeroIfAbsent,
        200,
        [Column::MonoA, Column::MonoB, Column::Case],
    )?;
    let c = checks::run(&mut text.run, spec)?;
    let r = &text.run;
    let d = ThermalData::new(r.t_s.clone(), (a, b), case, &r.rate_dps, &r.ref_rate_dps);
    Ok((text, d, c))
}

/// A run for the scale-factor fit, checked: `t_s`, `ref_rate_dps`,
/// `rate_dps`, `temp_c`; rotation present; a temperature span the model
/// can use.
pub fn scale_factor_run(source: Source, spec: &ReadSpec) -> Result<(SfInput, Checked), LabError> {
    let (mut text, [temp]) = RunFile::read(source, spec, Reference::Required, 30, [Column::Temp])?;
    let c = checks::run(&mut text.run, spec)?;
    let r = &text.run;
    if let Some(w) = c.warnings.iter().find(|w| w.code == "sign") {
        return Err(text.column_error(
            Column::Rate,
            format!(
                "{}; a scale factor cannot be fitted across the sign: negate the rate column (or the reference) so they agree",
                w.message
                    .split(';')
                    .next()
                    .unwrap_or(&w.message)
            ),
        ));
    }
    let peak = r.ref_rate_dps.iter().fold(0.0f64, |a, v| a.max(v.abs()));
    check_run(&r.ref_rate_dps, &temp).map_err(|e| match e {
        RunCheck::NoRotation(rows) => text.column_error(
            Column::RefRate,
            format!(
                "no rotation: {rows} rows with |{}| >= {} deg/s, at least {MIN_ROTATING_ROWS} needed to measure a scale factor{}",
                Column::RefRate.name(),
                MIN_RATE_DPS,
                if spec.rate_unit.is_none() && peak > 0.0 && peak * crate::data::units::DEG_PER_RAD >= MIN_RATE_DPS {
                    format!(" (the table reaches {peak:.4}: if the file is in rad/s, give --rate-unit rad/s)")
                } else {
                    String::new()
                }
            ),
        ),
        RunCheck::Span(span) => text.column_error(
            Column::Temp,
            format!(
                "temperature span {span:.2} degC over the rotating rows; the scale-factor-over-temperature model needs at least {MIN_SPAN_C} degC"
            ),
        ),
    })?;
    Ok((prepare(&r.t_s, &r.ref_rate_dps, &r.rate_dps, &temp), c))
}
