//! The record checks every command that reads a run makes (record/), in
//! one place: the sampling judged and a jittered record put on its grid,
//! the rate's unit checked against the data (a refusal placed at the
//! column), and the temperatures' drift. What they found goes into the
//! JSON (`warnings`, `sampling`, `units`) and the reports.

use crate::data::header::Places;
use crate::data::read_spec::ReadSpec;
use crate::data::run_file::{Column, RunFile, Series};
use crate::error::LabError;
use crate::record::sampling::{regularise, Sampling};
use crate::record::stationarity::{self, TempDrift};
use crate::record::units::{self, RateColumn};
use crate::record::Warning;

/// What the checks found.
#[derive(Clone, Debug)]
pub struct Checked {
    pub warnings: Vec<Warning>,
    pub sampling: Sampling,
    pub unit_basis: String,
    /// The white noise of the rate less its reference, deg/s, where the
    /// unit check measured it (on these rows).
    pub white_sd_dps: Option<f64>,
    pub drifts: Vec<TempDrift>,
    spec: ReadSpec,
    rows: usize,
    has_reference: bool,
}

impl Checked {
    /// Adds `sampling`, `units`, `stretch` and `rows` to a command's JSON,
    /// and the warnings to its `warnings` (made where it has none).
    pub fn json(&self, j: &mut serde_json::Value) {
        j["sampling"] = serde_json::to_value(&self.sampling).unwrap_or_default();
        j["units"] = serde_json::json!({
            "rate": self.spec.rate_unit.unwrap_or_default().name(),
            "rate_given": self.spec.rate_unit.is_some(),
            "ref_rate": self.spec.ref_rate_unit.or(self.spec.rate_unit).unwrap_or_default().name(),
            "temperature": self.spec.temp_unit.unwrap_or_default().name(),
            "temperature_given": self.spec.temp_unit.is_some(),
            "rate_checked": self.unit_basis,
        });
        j["stretch"] = serde_json::json!({
            "from_s": self.spec.from_s,
            "to_s": self.spec.to_s,
            "rows": self.rows,
        });
        j["reference_in_file"] = self.has_reference.into();
        let mut list = match j.get("warnings").and_then(|w| w.as_array()) {
            Some(a) => a.clone(),
            None => vec![],
        };
        for w in &self.warnings {
            let v = serde_json::to_value(w).unwrap_or_default();
            if !list.contains(&v) {
                list.push(v);
            }
        }
        j["warnings"] = list.into();
    }

    /// The warnings as a calibration's (for its report and JSON).
    pub fn calibration_warnings(&self) -> Vec<crate::calibration::warning::Warning> {
        self.warnings
            .iter()
            .map(|w| crate::calibration::warning::Warning::new(w.code, w.message.clone()))
            .collect()
    }

    /// The warnings as text lines.
    pub fn lines(&self) -> Vec<String> {
        self.warnings
            .iter()
            .map(|w| format!("WARNING ({}): {}", w.code, w.message))
            .collect()
    }
}

/// The checks on times `t` (put on their grid where jittered), a rate and
/// its reference, and temperature columns; `refuse` places a refusal.
fn check(
    t: &mut [f64],
    rate: &[f64],
    reference: Option<&[f64]>,
    rate_name: &str,
    temps: &[(String, &[f64])],
    spec: &ReadSpec,
    refuse: &dyn Fn(String) -> LabError,
) -> Result<Checked, LabError> {
    let sampling = regularise(t);
    let mut warnings: Vec<Warning> = sampling.warning().into_iter().collect();
    let u = units::check(&RateColumn {
        t,
        rate_dps: rate,
        reference_dps: reference,
        name: rate_name,
        given: spec.rate_unit,
        reference_given: spec.ref_rate_unit,
        period_s: Some(sampling.period_s),
    })
    .map_err(|r| refuse(r.0))?;
    warnings.extend(u.warnings);
    let span = t.last().copied().unwrap_or(0.0) - t.first().copied().unwrap_or(0.0);
    if span > 30.0 * 86_400.0 && sampling.period_s >= 1.0 {
        warnings.push(Warning::new(
            "unit",
            format!(
                "the record spans {:.0} days at {} s a row: is the time column in ms (--time-unit ms, a factor of 1/1000)?",
                span / 86_400.0,
                crate::report::text::sig(sampling.period_s)
            ),
        ));
    }
    let drifts: Vec<TempDrift> = temps
        .iter()
        .filter_map(|(n, v)| stationarity::temperature(t, n, v))
        .collect();
    warnings.extend(hot(temps, spec));
    Ok(Checked {
        warnings,
        sampling,
        unit_basis: u.basis,
        white_sd_dps: u.white_sd_dps,
        drifts,
        spec: spec.clone(),
        rows: t.len(),
        has_reference: reference.is_some(),
    })
}

/// Above what most gyros are rated for (+85 degC): a degF file read as
/// degC reads 68 to 185 for 20 to 85 degC, inside the sensors' range.
pub const RATED_MAX_C: f64 = 90.0;

/// A warning where a temperature column reads hotter than gyros run and
/// its values as degF would be ordinary ones.
fn hot(temps: &[(String, &[f64])], spec: &ReadSpec) -> Option<Warning> {
    if spec.temp_unit.is_some() {
        return None;
    }
    let (name, max) = temps
        .iter()
        .map(|(n, v)| (n, v.iter().copied().fold(f64::NEG_INFINITY, f64::max)))
        .max_by(|a, b| a.1.total_cmp(&b.1))?;
    let as_c = crate::data::units::TempUnit::Fahrenheit.to_c(max);
    (max > RATED_MAX_C).then(|| {
        Warning::new(
            "unit",
            format!(
                "`{name}` reaches {max:.1} degC, above the +85 degC most gyros are rated for; as degF it would be {as_c:.1} degC: is the file in degF? (--temp-unit F, degC = (degF - 32) * 5/9)"
            ),
        )
    })
}

/// The checks on a series read for `allan`; its temperature drifts as
/// `non_stationary` warnings.
pub fn series(s: &mut Series, spec: &ReadSpec) -> Result<Checked, LabError> {
    let temps: Vec<(String, &[f64])> = s
        .temperatures
        .iter()
        .map(|(n, v)| (n.clone(), v.as_slice()))
        .collect();
    let name = s.shown().to_owned();
    let mut t = std::mem::take(&mut s.t_s);
    let out = check(
        &mut t,
        &s.values,
        s.reference.as_deref(),
        &name,
        &temps,
        spec,
        &|m| s.column_error(m),
    );
    s.t_s = t;
    let mut c = out?;
    let w = stationarity::warning(&c.drifts);
    c.warnings.extend(w);
    Ok(c)
}

/// The checks on a run read for a fit, a compensation or a discovery.
pub fn run(r: &mut RunFile, spec: &ReadSpec) -> Result<Checked, LabError> {
    let mut t = std::mem::take(&mut r.t_s);
    let temps: Vec<(String, &[f64])> = [
        (Column::Temp, &r.temp_c),
        (Column::MonoA, &r.t_mono_a_c),
        (Column::MonoB, &r.t_mono_b_c),
        (Column::Case, &r.t_case_c),
    ]
    .into_iter()
    .filter_map(|(c, v)| v.as_deref().map(|v| (c.name().to_owned(), v)))
    .collect();
    let places: Places = r.places.clone();
    let name = places.shown(Column::Rate.name());
    let reference = r.has_reference.then_some(r.ref_rate_dps.as_slice());
    let out = check(&mut t, &r.rate_dps, reference, &name, &temps, spec, &|m| {
        places.column_error(Column::Rate.name(), m)
    });
    r.t_s = t;
    let mut c = out?;
    if !r.has_reference {
        c.warnings.push(Warning::new(
            "no_reference",
            format!(
                "the file has no `{}`: read as a static record (reference 0), so the Earth-rate component is part of the bias",
                Column::RefRate.name()
            ),
        ));
    }
    Ok(c)
}
