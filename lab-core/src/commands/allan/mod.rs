//! `allan`: noise analysis of a rate column of a run (IEEE 952 Allan
//! variance, noise/): what the command found, as the JSON, the text, the
//! rows of allan.csv and the report (report.rs), for the CLI and Python
//! alike.

mod report;
mod words;

use crate::commands::checks::{self, Checked};
use crate::data::allan_file::AllanRow;
use crate::data::read_spec::ReadSpec;
use crate::data::run_file::{Column, Series as RunSeries};
use crate::data::source::Source;
use crate::error::LabError;
use crate::noise::analysis::{analyse, Allan};
use crate::noise::gaps::{fill_gaps_owned, Filled};
use crate::noise::model::Interval;
use crate::noise::record_checks;
use crate::noise::terms::{self, shape_name, COUNT, MARKOV_NAME, NAMES, SIN_NAME, UNITS};
use crate::record::Warning;
use crate::report::document::Report;
use crate::report::text::sig;

const DPH: f64 = 3600.0;

/// What `allan` found on a run.
pub struct AllanOutcome {
    pub an: Allan,
    /// The source, as a user names it (the path, or the caller's name).
    pub name: String,
    /// The column asked for, and what was analysed (less the reference
    /// rate where the run has one).
    pub column: String,
    pub analysed: String,
    pub filled: Filled,
    pub warnings: Vec<Warning>,
    pub checked: Checked,
    /// The first time analysed (after a warm-up left out), s.
    pub analysed_from_s: Option<f64>,
    /// Time to read and to compute, s.
    pub timing: (f64, f64),
}

/// The Allan analysis of `column` of a run: read and checked, a warm-up
/// the temperatures show left out (unless a stretch was given), less the
/// reference rate, gaps filled.
pub fn allan(source: Source, column: &str, spec: &ReadSpec) -> Result<AllanOutcome, LabError> {
    let t_start = std::time::Instant::now();
    let mut series = RunSeries::read(source, column, spec)?;
    let read_s = t_start.elapsed().as_secs_f64();
    let checked = checks::series(&mut series, spec)?;
    let mut warnings = checked.warnings.clone();
    // A warm-up the temperatures show settling is left out unless the
    // stretch was given: the noise of the gyro, not its warm-up.
    let warm_up = match spec.from_s {
        None => crate::record::stationarity::settled_from(&checked.drifts),
        Some(_) => None,
    };
    if let Some(from) = warm_up {
        let k = series.t_s.partition_point(|&t| t < from);
        series.keep_from(k);
        warnings.push(Warning::new(
            "warm_up",
            format!(
                "analysed from {} s on, after the warm-up the temperatures show ({k} rows left out); --from-s 0 analyses the whole record",
                sig(from)
            ),
        ));
    }
    // The gyro's error, not the table's motion: the output less the
    // reference rate where the run has one.
    let analysed = match &series.reference {
        Some(r) => {
            warnings.extend(record_checks::not_static(r));
            for (v, r) in series.values.iter_mut().zip(r) {
                *v -= r;
            }
            format!("{column} - {}", Column::RefRate.name())
        }
        None => column.to_owned(),
    };
    // The unit check measured the white noise on these very rows unless a
    // warm-up was cut since.
    let white = checked.white_sd_dps.filter(|_| warm_up.is_none());
    warnings.extend(crate::record::stationarity::mean_rate_with(
        &series.t_s,
        &series.values,
        white,
    ));
    let values = std::mem::take(&mut series.values);
    // The median interval the checks found, where they kept every row and
    // moved none (a uniform record).
    let median = (warm_up.is_none() && checked.sampling.kind == "uniform")
        .then_some(checked.sampling.period_s);
    let filled = fill_gaps_owned(&series.t_s, values, median)
        .map_err(|e| series.time_error(e.row(), e.to_string()))?;
    let an = analyse(&filled.values, filled.tau0)
        .map_err(|e| source.origin().whole(format!("column `{analysed}`: {e}")))?;
    warnings.extend(record_checks::too_short(&an));
    let compute_s = t_start.elapsed().as_secs_f64() - read_s;
    Ok(AllanOutcome {
        an,
        name: source.name(),
        column: column.to_owned(),
        analysed,
        analysed_from_s: series.t_s.first().copied(),
        filled,
        warnings,
        checked,
        timing: (read_s, compute_s),
    })
}

impl AllanOutcome {
    /// The JSON object (docs/interfaces.md keys and more).
    pub fn json(&self) -> serde_json::Value {
        let mut j = json(&self.an, &self.column, &self.filled, self.timing);
        j["analysed"] = self.analysed.clone().into();
        j["analysed_from_s"] = self.analysed_from_s.into();
        j["warnings"] = serde_json::to_value(&self.warnings).unwrap_or_default();
        self.checked.json(&mut j);
        j
    }

    /// The text the command prints: the analysis, where its files were
    /// `written`, its warnings, the gaps.
    pub fn text(&self, written: Option<&str>) -> Vec<String> {
        let mut lines = words::text(&self.an, &self.name, &self.analysed, self.timing);
        lines.extend(written.map(|w| format!("written: {w}")));
        for w in &self.warnings {
            lines.push(format!("WARNING ({}): {}", w.code, w.message));
        }
        if self.filled.gaps + self.filled.stretched > 0 {
            lines.push(words::gaps_text(&self.filled));
        }
        lines
    }

    /// The first lines of [`AllanOutcome::text`] a person reads: what was
    /// analysed and the figures in short.
    pub fn summary(&self) -> Vec<String> {
        vec![
            words::first_line(&self.an, &self.name, &self.analysed),
            words::headline(&self.an),
            words::verdict(&self.an),
        ]
    }

    /// The rows of allan.csv.
    pub fn rows(&self) -> Vec<AllanRow<'_>> {
        let an = &self.an;
        (0..an.taus.len())
            .map(|i| AllanRow {
                tau_s: an.taus[i],
                adev_dph: an.avar[i].sqrt() * DPH,
                adev_lo_dph: an.avar_lo[i].sqrt() * DPH,
                adev_hi_dph: an.avar_hi[i].sqrt() * DPH,
                edf: an.terms.edf[i],
                noise_type: shape_name(an.terms.dominant[i]),
                model_adev_dph: an.terms.model[i].sqrt() * DPH,
            })
            .collect()
    }

    /// The report.
    pub fn report(&self) -> Report {
        report::report(&self.an, &self.name, &self.analysed, &self.warnings)
    }
}

#[derive(serde::Serialize)]
struct TermJson {
    value: f64,
    lo: f64,
    hi: f64,
}

/// The terms as JSON values: {value, lo, hi, reliable} or null; the
/// sinusoid and the Markov term with each parameter's interval.
fn terms_json(a: &Allan) -> serde_json::Map<String, serde_json::Value> {
    let mut m = serde_json::Map::new();
    let t = &a.terms;
    let iv = |i: &Interval, k: f64| serde_json::json!({"value": i.value * k, "lo": i.lo * k, "hi": i.hi * k});
    for j in 0..COUNT {
        let v = if t.present[j] {
            let mut v = serde_json::to_value(TermJson {
                value: terms::to_units(j, t.c[j]),
                lo: terms::to_units(j, t.lo[j]),
                hi: terms::to_units(j, t.hi[j]),
            })
            .unwrap_or(serde_json::Value::Null);
            v["reliable"] = t.reliable[j].into();
            if j == 2 {
                v["upper_bound"] = t.bias_upper_bound.into();
            }
            if let (1, Some(f)) = (j, &t.arw_filter_s) {
                v["filter_tau_s"] = iv(f, 1.0);
            }
            v
        } else {
            serde_json::Value::Null
        };
        m.insert(NAMES[j].into(), v);
    }
    m.insert(
        SIN_NAME.into(),
        t.sinusoid.as_ref().map_or(serde_json::Value::Null, |s| {
            serde_json::json!({
                "amplitude_dph": iv(&s.amplitude_dps, DPH),
                "frequency_hz": iv(&s.frequency_hz, 1.0),
                "reliable": s.reliable,
            })
        }),
    );
    m.insert(
        MARKOV_NAME.into(),
        t.correlated.as_ref().map_or(serde_json::Value::Null, |c| {
            serde_json::json!({
                "sigma_dph": iv(&c.sigma_dph, 1.0),
                "tau_s": iv(&c.tau_s, 1.0),
                "white_limit_dpsh": iv(&c.white_limit_dpsh, 1.0),
                "reliable": c.reliable,
            })
        }),
    );
    m
}

/// The goodness of fit as JSON.
fn fit_json(an: &Allan) -> serde_json::Value {
    let g = &an.terms.goodness;
    serde_json::json!({
        "consistent": g.consistent,
        "chi2_per_dof": g.chi2_per_dof,
        "chi2_per_dof_limit": g.limit_per_dof,
        "dof": g.dof,
        "outside_taus_s": g.outside.iter().map(|&i| an.taus[i]).collect::<Vec<f64>>(),
        "outside_fraction": g.outside.len() as f64 / an.taus.len().max(1) as f64,
    })
}

/// The conventional readings as JSON.
fn readings_json(an: &Allan) -> serde_json::Value {
    let r = &an.readings;
    serde_json::json!({
        "arw_dpsh": r.arw_dpsh,
        "arw_region_s": r.arw_region_s.map(|(a, b)| vec![a, b]),
        "floor_dph": r.floor_dph,
        "floor_tau_s": r.floor_tau_s,
        "bias_instability_dph": r.bias_instability_dph,
        "resolved": r.resolved,
        "rise_after_floor": r.rise.map(|(t, v)| serde_json::json!({"tau_s": t, "adev_dph": v})),
    })
}

/// The JSON of the analysis (deviations in deg/h), with the read and
/// compute times.
fn json(
    an: &Allan,
    column: &str,
    filled: &Filled,
    (read_s, compute_s): (f64, f64),
) -> serde_json::Value {
    let dph = |v: &[f64]| -> Vec<f64> { v.iter().map(|v| v.sqrt() * DPH).collect() };
    let (adev, lo, hi) = (dph(&an.avar), dph(&an.avar_lo), dph(&an.avar_hi));
    let mut units = serde_json::Map::new();
    for j in 0..COUNT {
        units.insert(NAMES[j].into(), UNITS[j].into());
    }
    serde_json::json!({
        "taus_s": an.taus,
        "adev_dph": adev,
        "adev_lo_dph": lo,
        "adev_hi_dph": hi,
        "terms": terms_json(an),
        "model_adev_dph": an.terms.model.iter().map(|v| v.sqrt() * DPH).collect::<Vec<f64>>(),
        "fit": fit_json(an),
        "readings": readings_json(an),
        "units": units,
        "confidence": terms::CONF,
        "edf": an.terms.edf,
        "noise_type": an.terms.dominant.iter().map(|&d| shape_name(d)).collect::<Vec<_>>(),
        "samples": an.n,
        "tau0_s": an.tau0,
        "mean_dps": an.mean_dps,
        "mean_se_dps": an.mean_se_dps,
        "column": column,
        "gaps": {
            "count": filled.gaps,
            "stretched_intervals": filled.stretched,
            "filled_samples": filled.filled,
            "filled_fraction": filled.filled_fraction(),
        },
        "read_s": read_s,
        "compute_s": compute_s,
    })
}
