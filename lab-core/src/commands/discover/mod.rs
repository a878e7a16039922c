//! `discover`: the model against a run; the effects it misses named,
//! added, and the gap shown to shrink (model/discovery/). What it found,
//! as the JSON, the text, the model file's text, the residual and the
//! report, for the CLI and Python alike.

mod json;
pub mod report;
mod text;

use crate::commands::checks::{self, Checked};
use crate::commands::model_file::{model_text, ModelFile};
use crate::data::read_spec::ReadSpec;
use crate::data::run_file::{Column, Reference, RunFile};
use crate::data::source::{Origin, Source};
use crate::error::LabError;
use crate::model::discovery::{discover, discover_library, Discovery, Options, Run, WINDOW_S};
use crate::model::effects::Effect;
use crate::model::grade::Grade;
use crate::model::gyro_kind::GyroKind;
use crate::model::gyro_model::Model;
use crate::model::inputs::Inputs;
use crate::model::ranges::Extent;
use crate::report::document::Report;

use json::estimate_json;
pub use json::json;

/// What `discover` is asked.
pub struct Request<'a> {
    /// The run.
    pub source: Source<'a>,
    pub spec: &'a ReadSpec,
    pub gyro: GyroKind,
    /// The model (the ideal gyro without it), and what the user calls it.
    pub model: Option<(ModelFile, String)>,
    /// The gyro's grade (judged from the run's white noise without it).
    pub grade: Option<Grade>,
    /// Another run of the same gyro the model written must predict.
    pub validate: Option<Source<'a>>,
}

/// The model written, on another run of the same gyro.
pub struct Validation {
    pub name: String,
    pub discovery: Discovery,
    /// Each named term, with and without it on that run.
    pub terms: Vec<SecondRun>,
    /// The gap the model written leaves there with its bias alone
    /// refitted (the 1 s means less their mean): what it predicts of a
    /// run it was not fitted on, up to a bias.
    pub bias_removed_dph: f64,
    /// The gap that run's own discovery leaves, from the model given:
    /// what one run's model is held against on another.
    pub own_dph: f64,
}

/// What `discover` found.
pub struct DiscoverOutcome {
    pub d: Discovery,
    pub data: Run,
    pub checked: Checked,
    /// The run and the model as the user names them.
    pub name: String,
    pub model_name: Option<String>,
    pub validation: Option<Validation>,
    pub elapsed_s: f64,
}

/// Reads a run for discovery, with the record checks.
pub fn read_run(source: Source, spec: &ReadSpec) -> Result<(Run, Checked), LabError> {
    let mut r = RunFile::read_long(
        source,
        spec,
        Reference::ZeroIfAbsent,
        10,
        &[
            Column::Temp,
            Column::MonoA,
            Column::MonoB,
            Column::Case,
            Column::RefAcc,
        ],
    )?;
    let checked = checks::run(&mut r, spec)?;
    let mono = match (r.t_mono_a_c, r.t_mono_b_c) {
        (Some(a), Some(b)) => Some((a, b)),
        _ => None,
    };
    Ok((
        Run {
            inputs: Inputs::new(
                r.t_s,
                r.ref_rate_dps,
                r.temp_c,
                mono,
                r.t_case_c,
                r.ref_acc_dps2,
            ),
            rate: r.rate_dps,
        },
        checked,
    ))
}

/// The model's effects need columns the run has: else an error
/// naming the first effect and what it lacks.
fn computable(model: &Model, run: &Run, origin: &Origin) -> Result<(), LabError> {
    match model.missing_inputs(&run.inputs).first() {
        Some((e, cols)) => Err(origin.whole(format!(
            "the model's effect `{}` needs column(s) {} that this run lacks",
            e.name(),
            cols.iter()
                .map(|c| format!("`{}`", c.name()))
                .collect::<Vec<_>>()
                .join(", ")
        ))),
        None => Ok(()),
    }
}

/// Discovery on a run (docs/interfaces.md): the run read and checked, the
/// model checked on it, the missing effects named, the model written
/// checked on the validation run.
pub fn discover_run(req: Request) -> Result<DiscoverOutcome, LabError> {
    let t0 = std::time::Instant::now();
    let (data, checked) = read_run(req.source, req.spec)?;
    let model = match &req.model {
        Some((f, _)) => {
            f.check_on_run(&run_extent(&data))?;
            f.check_terms(&data.inputs)?;
            f.model.clone()
        }
        None => Model::ideal(req.gyro),
    };
    // The model's own effects must be computable on this run.
    computable(&model, &data, &req.source.origin())?;
    let opts = Options::with_grade(req.grade);
    let d = discover(&model, &data, &opts);
    // The model written, on another run of the same gyro: what it still
    // misses there.
    let validation = match req.validate {
        Some(src) => {
            let (v, _) = read_run(src, req.spec)?;
            computable(&d.model_after, &v, &src.origin())?;
            let opts_v = Options::with_grade(Some(d.grade.value));
            // The model held as written (its terms not refitted): what
            // it predicts of a run it was not fitted on.
            let terms = second_run_terms(&d, &v);
            Some(Validation {
                name: src.name(),
                discovery: discover_library(&d.model_after, &v, &opts_v),
                terms,
                bias_removed_dph: bias_removed_gap(&d.model_after, &v),
                own_dph: discover(&model, &v, &opts).gap_after_dph,
            })
        }
        None => None,
    };
    Ok(DiscoverOutcome {
        d,
        data,
        checked,
        name: req.source.name(),
        model_name: req.model.map(|m| m.1),
        validation,
        elapsed_s: t0.elapsed().as_secs_f64(),
    })
}

impl DiscoverOutcome {
    /// The JSON object (docs/interfaces.md keys and more).
    pub fn json(&self) -> serde_json::Value {
        let mut j = json(&self.d);
        if let Some(v) = &self.validation {
            j["validation"] = validation_json(&v.name, &v.discovery);
            j["validation"]["gap_bias_removed_dph"] = v.bias_removed_dph.into();
            j["validation"]["own_gap_after_dph"] = v.own_dph.into();
            j["validation"]["prediction_ratio"] = (v.bias_removed_dph / v.own_dph).into();
            let mut k = 0;
            for f in j["found"].as_array_mut().into_iter().flatten() {
                if f["effect"] == "term" {
                    if let Some(t) = v.terms.get(k) {
                        f["validation"]["second_run"] = t.json(&v.name);
                    }
                    k += 1;
                }
            }
        }
        j["elapsed_s"] = self.elapsed_s.into();
        self.checked.json(&mut j);
        j
    }

    /// The text the command prints; `written`: where the files went.
    pub fn text(&self, written: Option<&str>) -> Vec<String> {
        let d = &self.d;
        let mut out = self.checked.lines();
        out.extend(text::lines(&self.name, d, written));
        if let Some(v) = &self.validation {
            out.push(validation_text(&v.name, &v.discovery));
            out.push(format!(
                "  as written, its bias alone refitted, the model leaves {:.4} deg/h on {}; that run's own discovery leaves {:.4}: {:.3} times it",
                v.bias_removed_dph,
                v.name,
                v.own_dph,
                v.bias_removed_dph / v.own_dph
            ));
            for (t, s) in d
                .terms
                .iter()
                .filter(|t| t.proposed && t.carried.is_none())
                .zip(&v.terms)
            {
                out.push(format!(
                    "  the term {} on {}: the gap (bias removed) {:.4} deg/h with it, {:.4} without: {}",
                    t.term.formula,
                    v.name,
                    s.with_dph,
                    s.without_dph,
                    if s.with_dph < s.without_dph { "it predicts that run" } else { "it does NOT predict that run" }
                ));
            }
        }
        out
    }

    /// The verdict in short: the gap before and after, what was named.
    pub fn summary(&self) -> Vec<String> {
        let d = &self.d;
        let mut names: Vec<String> = d.found.iter().map(|e| e.effect.name().to_owned()).collect();
        names.extend(
            d.terms
                .iter()
                .filter(|t| t.proposed && t.carried.is_none())
                .map(|t| format!("term {}", t.term.formula)),
        );
        vec![
            format!(
                "{}: gap {:.4} -> {:.4} deg/h (noise floor {:.4}); {}",
                self.name,
                d.gap_before_dph,
                d.gap_after_dph,
                d.noise_floor_dph,
                if names.is_empty() {
                    "nothing named".to_owned()
                } else {
                    format!("named {}", names.join(", "))
                }
            ),
            match &d.unexplained {
                Some(u) => format!("unexplained: {:.4} deg/h above the noise", u.excess_dph),
                None => "nothing left unexplained above the noise".to_owned(),
            },
        ]
    }

    /// The model with the effects found: the model file's text.
    pub fn model_toml(&self) -> String {
        let d = &self.d;
        let mut names: Vec<&str> = d.found.iter().map(|e| e.effect.name()).collect();
        names.extend(
            d.terms
                .iter()
                .filter(|t| t.proposed && t.carried.is_none())
                .map(|t| t.term.formula.as_str()),
        );
        let carried: Vec<String> = d
            .carried
            .iter()
            .map(|c| format!("{} ({})", c.estimate.effect.name(), c.why))
            .collect();
        let mut comment = format!(
            "gyro-lab discover on {}: the model{} with {} added",
            self.name,
            self.model_name
                .as_ref()
                .map_or(" (ideal)".into(), |p| format!(" {p}")),
            if names.is_empty() {
                "nothing named".to_owned()
            } else {
                names.join(", ")
            }
        );
        if !carried.is_empty() {
            comment.push_str(&format!("\ncarried, not named: {}", carried.join("; ")));
        }
        model_text(&d.model_after, &comment)
    }

    /// The report.
    pub fn report(&self) -> Report {
        report::report(&self.d, &self.data, &self.name, &self.checked.warnings)
    }
}

/// A named term judged on a second run: the gap of the model written with
/// and without it, each with its mean removed (the bias may change from
/// run to run), deg/h.
pub struct SecondRun {
    pub with_dph: f64,
    pub without_dph: f64,
}

impl SecondRun {
    fn json(&self, name: &str) -> serde_json::Value {
        serde_json::json!({
            "data": name,
            "gap_with_term_dph": self.with_dph,
            "gap_without_term_dph": self.without_dph,
            "predicts": self.with_dph < self.without_dph,
        })
    }
}

/// The gap `m` leaves on `v` up to a bias: the RMS of the 1 s means of
/// its residual less their mean, deg/h.
fn bias_removed_gap(m: &Model, v: &Run) -> f64 {
    let win = crate::model::discovery::windows::Windows::new(&v.inputs.t, WINDOW_S);
    let sim = m.evaluate(&v.inputs);
    let r: Vec<f64> = v.rate.iter().zip(&sim).map(|(a, b)| a - b).collect();
    let w = win.mean(&r);
    let n = w.len().max(1) as f64;
    let mean = w.iter().sum::<f64>() / n;
    (w.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / n).sqrt() * 3600.0
}

/// [`SecondRun`] of each named term of `d`'s model on `v`.
fn second_run_terms(d: &Discovery, v: &Run) -> Vec<SecondRun> {
    let gap = |m: &Model| bias_removed_gap(m, v);
    let with = gap(&d.model_after);
    d.terms
        .iter()
        .enumerate()
        .filter(|(_, t)| t.proposed && t.carried.is_none())
        .map(|(i, _)| {
            let mut m = d.model_after.clone();
            m.terms.remove(i);
            SecondRun {
                with_dph: with,
                without_dph: gap(&m),
            }
        })
        .collect()
}

/// Whether the model written predicts another run of the same gyro: there
/// it needs nothing more than a bias, and leaves nothing unexplained.
pub fn predicts(v: &Discovery) -> bool {
    v.found.iter().all(|e| e.effect == Effect::Bias)
        && !v.terms.iter().any(|t| t.proposed && t.carried.is_none())
        && v.unexplained.is_none()
}

/// The JSON of the validation run: the model written, on it.
fn validation_json(name: &str, v: &Discovery) -> serde_json::Value {
    let bias = v
        .found
        .iter()
        .chain(v.carried.iter().map(|c| &c.estimate))
        .find(|e| e.effect == Effect::Bias)
        .map(estimate_json);
    serde_json::json!({
        "data": name,
        "gap_before_dph": v.gap_before_dph,
        "gap_after_dph": v.gap_after_dph,
        "noise_floor_dph": v.noise_floor_dph,
        "found": v.found.iter().map(|e| e.effect).collect::<Vec<_>>(),
        "bias": bias,
        "unexplained": v.unexplained.is_some(),
        "predicts": predicts(v),
    })
}

fn validation_text(name: &str, v: &Discovery) -> String {
    let names: Vec<&str> = v.found.iter().map(|e| e.effect.name()).collect();
    format!(
        "validation on {}: the model written leaves a gap of {:.4} deg/h (noise floor {:.4}); {} -> {:.4} deg/h; {}",
        name,
        v.gap_before_dph,
        v.noise_floor_dph,
        if names.is_empty() {
            "nothing more needed".to_owned()
        } else {
            format!("it still needs {}", names.join(", "))
        },
        v.gap_after_dph,
        if predicts(v) {
            "it predicts this run up to a bias"
        } else {
            "it does NOT predict this run up to a bias"
        }
    )
}

/// What a run covers, for the model's domains that depend on it.
fn run_extent(data: &Run) -> Extent {
    let t = &data.inputs.t;
    Extent {
        grade: Grade::Navigation,
        record_s: t.last().copied().unwrap_or(0.0) - t.first().copied().unwrap_or(0.0),
        temp_c: data.inputs.temp.as_ref().map(|v| {
            v.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |a, &x| {
                (a.0.min(x), a.1.max(x))
            })
        }),
    }
}
