//! `gyro-lab discover`: reads the model and the run, hands them to the
//! discovery (model/discovery/), and writes what it found: the model with
//! the effects added, residual.csv, the report and the JSON.

pub mod bench;
pub mod report;

use crate::cli::args::{Json, Out, RunRead};
use crate::cli::checks::{self, Checked};
use crate::cli::model_file::{read_model_file, write_model};
use crate::cli::out_path::{self, FileKind};
use crate::cli::output::write_report;
use crate::data::read_spec::ReadSpec;
use crate::data::residual_file;
use crate::data::run_file::{Column, Reference, RunFile};
use crate::error::LabError;
use crate::model::discovery::estimates::Estimate;
use crate::model::discovery::result::TermFound;
use crate::model::discovery::terms::Kind;
use crate::model::discovery::{discover, discover_library, Discovery, Options, Run, WINDOW_S};
use crate::model::effects::Effect;
use crate::model::grade::Grade;
use crate::model::gyro_kind::GyroKind;
use crate::model::gyro_model::Model;
use crate::model::inputs::Inputs;
use crate::model::ranges::Extent;
use crate::report::text::sig;
use clap::{Args, ValueEnum};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// The gyro kinds, as the command line names them.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum GyroArg {
    Fog,
    Rlg,
    /// A MEMS rate gyro with one temperature sensor (temp_c).
    Mems,
}

impl From<GyroArg> for GyroKind {
    fn from(g: GyroArg) -> Self {
        match g {
            GyroArg::Fog => GyroKind::Fog,
            GyroArg::Rlg => GyroKind::Rlg,
            GyroArg::Mems => GyroKind::Mems,
        }
    }
}

/// The grades, as the command line names them.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum GradeArg {
    Navigation,
    Tactical,
    Industrial,
    Consumer,
}

impl From<GradeArg> for Grade {
    fn from(g: GradeArg) -> Self {
        match g {
            GradeArg::Navigation => Grade::Navigation,
            GradeArg::Tactical => Grade::Tactical,
            GradeArg::Industrial => Grade::Industrial,
            GradeArg::Consumer => Grade::Consumer,
        }
    }
}

#[derive(Args, Debug, Clone)]
#[command(mut_arg("out", |a| a.help("A folder: model.toml, residual.csv and report.html are written in it")))]
pub struct DiscoverArgs {
    /// The gyro the run is from: its kind sets the ideal model and the library of effects.
    #[arg(long, value_enum)]
    pub gyro: GyroArg,
    /// The gyro's grade: sets the physical ranges of the effects'
    /// parameters (judged from the run's white noise without it).
    #[arg(long, value_enum)]
    pub grade: Option<GradeArg>,
    /// Another run of the same gyro: the model written must predict it
    /// too (up to a bias).
    #[arg(long)]
    pub validate: Option<PathBuf>,
    /// The model (model.toml); the ideal gyro without it.
    #[arg(long)]
    pub model: Option<PathBuf>,
    /// Run file (t_s, rate_dps, ref_rate_dps unless static; temp_c,
    /// t_mono_a_c, t_mono_b_c, t_case_c, ref_acc_dps2 where the effects
    /// need them).
    #[arg(long)]
    pub data: PathBuf,
    #[command(flatten)]
    pub read: RunRead,
    #[command(flatten)]
    pub out: Out,
    #[command(flatten)]
    pub json: Json,
}

/// Reads a run file for discovery, with the record checks.
pub fn read_run(path: &Path, spec: &ReadSpec) -> Result<(Run, Checked), LabError> {
    let mut r = RunFile::read_long(
        path,
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

/// An estimate's JSON: parameters and their 95 % intervals.
fn estimate_json(e: &Estimate) -> serde_json::Value {
    let parameters: BTreeMap<&str, f64> = e.params.iter().map(|p| (p.0, p.1)).collect();
    let intervals: BTreeMap<&str, [f64; 2]> = e.params.iter().map(|p| (p.0, [p.2, p.3])).collect();
    serde_json::json!({
        "effect": e.effect,
        "parameters": parameters,
        "parameter_intervals": intervals,
        "delta_bic": e.delta_bic,
        "explained_share": e.explained_share,
    })
}

/// A term outside the library's JSON (docs/interfaces.md): its formula,
/// parameters with intervals, and how it was validated.
fn term_json(t: &TermFound) -> serde_json::Value {
    let intervals: BTreeMap<&str, [f64; 2]> = t
        .intervals
        .iter()
        .map(|(k, v)| (k.as_str(), [v.0, v.1]))
        .collect();
    let v = &t.validation;
    serde_json::json!({
        "effect": "term",
        "library": false,
        "label": t.label,
        "proposed": t.proposed,
        "formula": t.term.formula,
        "parameters": t.term.params,
        "parameter_intervals": intervals,
        "validation": {
            "method": "blocked cross-validation on the whitened 1 s means: the coefficients fitted on all folds but one, the held-out fold predicted, in turn",
            "folds": v.folds,
            "held_out_gain": v.held_out_gain,
            "fold_gains": v.fold_gains,
            "threshold": v.threshold,
            "held_out_share": v.held_out_share,
            "passed": v.held_out_gain >= v.threshold,
            "units": "noise variances of the whitened residual",
        },
        "disguise": t.disguise,
        "gap_closed": t.closure.map(|c| serde_json::json!({
            "gap_without_dph": c.0, "gap_with_dph": c.1, "excess_closed_share": c.2,
        })),
    })
}

/// The JSON of a discovery (docs/interfaces.md keys and more).
pub fn json(d: &Discovery) -> serde_json::Value {
    let mut found: Vec<serde_json::Value> = d.found.iter().map(estimate_json).collect();
    // Added: the terms proposed and named. A user's terms were not added
    // (they were in the model given): they are under `model_terms`, with
    // their parameters as fitted here.
    found.extend(
        d.terms
            .iter()
            .filter(|t| t.proposed && t.carried.is_none())
            .map(term_json),
    );
    let model_terms: Vec<serde_json::Value> = d
        .terms
        .iter()
        .filter(|t| !t.proposed)
        .map(|t| {
            let mut j = term_json(t);
            j["named"] = t.carried.is_none().into();
            j["why"] = t.carried.clone().into();
            j
        })
        .collect();
    let mut carried: Vec<serde_json::Value> = d
        .carried
        .iter()
        .map(|c| {
            let mut j = estimate_json(&c.estimate);
            j["why"] = c.why.clone().into();
            j
        })
        .collect();
    carried.extend(d.terms.iter().filter(|t| t.proposed).filter_map(|t| {
        t.carried.as_ref().map(|why| {
            let mut j = term_json(t);
            j["why"] = why.clone().into();
            j
        })
    }));
    let skipped: Vec<serde_json::Value> = d
        .skipped
        .iter()
        .map(|s| {
            let names: Vec<&str> = s.missing.iter().map(|c| c.name()).collect();
            serde_json::json!({"effect": s.effect.name(), "missing": names, "reason": s.reason})
        })
        .collect();
    let implausible: Vec<serde_json::Value> = d
        .implausible
        .iter()
        .map(|i| {
            let p: BTreeMap<&str, f64> = i.parameters.iter().map(|(k, v)| (k.as_str(), *v)).collect();
            let out: Vec<serde_json::Value> = i
                .outside
                .iter()
                .map(|(k, v, r)| serde_json::json!({"parameter": k, "value": v, "range": [r.0, r.1]}))
                .collect();
            serde_json::json!({"effect": i.effect, "parameters": p, "outside": out})
        })
        .collect();
    let n = &d.noise;
    serde_json::json!({
        "found": found,
        "gap_before_dph": d.gap_before_dph,
        "gap_after_dph": d.gap_after_dph,
        "gap_window_s": report::gap_window_s(d),
        "residual_mean": {
            "value_dph": d.residual_mean_dph,
            "sd_dph": d.residual_mean_sd_dph,
            "lo_dph": d.residual_mean_dph - 1.96 * d.residual_mean_sd_dph,
            "hi_dph": d.residual_mean_dph + 1.96 * d.residual_mean_sd_dph,
            "centred_by_dph": d.centred_by_dph,
        },
        "noise_floor_dph": d.noise_floor_dph,
        "noise_floor_hi_dph": d.noise_floor_hi_dph,
        "noise_floor_white_dph": d.noise_floor_white_dph,
        "ambiguous": d.ambiguous,
        "unexplained": d.unexplained,
        "carried": carried,
        "model_terms": model_terms,
        "implausible": implausible,
        "dropped": d.dropped,
        "not_confirmed": d
            .not_confirmed
            .iter()
            .map(|(k, g)| {
                let e = match k {
                    Kind::Constant => Some(Effect::Bias),
                    k => k.effect(),
                };
                serde_json::json!({"effect": e, "term": k.describe(), "gain": g})
            })
            .collect::<Vec<_>>(),
        "skipped": skipped,
        "proposal": {
            "tried": d.proposals.tried.iter().take(12).map(|t| serde_json::json!({
                "label": t.label, "formula": t.formula, "held_out_gain": t.held_out_gain,
            })).collect::<Vec<_>>(),
            "note": d.proposals.note,
            "space_size": d.proposals.space,
            "threshold": d.proposals.threshold,
        },
        "disagreements": d.disagreements,
        "noise": {
            "white_1s_dph": n.white.sqrt() * 3600.0,
            "bias_instability_dph": n.flicker.sqrt() * 3600.0,
            "rate_random_walk_dph_per_sqrt_h": n.random_walk.sqrt() * 3600.0 * 60.0,
            "passes": d.passes,
        },
        "fallback": d.fallback,
        "intervals_reliable": d.short.is_none(),
        "intervals_note": d.short,
        "windows": d.windows.len(),
        "fit_window_s": crate::model::discovery::fit_window_s(
            d.windows.t.last().copied().unwrap_or(0.0) - d.windows.t.first().copied().unwrap_or(0.0)
        ),
        "gyro": d.gyro.name(),
        "grade": d.grade,
    })
}

/// The model's effects need columns the run at `path` has: else an error
/// naming the first effect and what it lacks.
fn computable(model: &Model, run: &Run, path: &Path) -> Result<(), LabError> {
    match model.missing_inputs(&run.inputs).first() {
        Some((e, cols)) => Err(LabError::input(
            path,
            format!(
                "the model's effect `{}` needs column(s) {} that this run lacks",
                e.name(),
                cols.iter()
                    .map(|c| format!("`{}`", c.name()))
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
        )),
        None => Ok(()),
    }
}

pub fn run(a: &DiscoverArgs) -> Result<(), LabError> {
    let t0 = std::time::Instant::now();
    let spec = a.read.spec()?;
    let mut inputs: Vec<(&str, &Path)> = vec![("--data", &a.data)];
    if let Some(p) = &a.model {
        inputs.push(("--model", p));
    }
    if let Some(p) = &a.validate {
        inputs.push(("--validate", p));
    }
    out_path::folder(
        "discover",
        &a.out.out,
        &[
            ("model.toml", FileKind::Toml("gyro_model")),
            ("residual.csv", FileKind::Csv),
            ("report.html", FileKind::Html),
        ],
        &inputs,
        a.out.force,
    )?;
    let gyro = GyroKind::from(a.gyro);
    let file = match &a.model {
        Some(p) => Some(read_model_file(p, gyro)?),
        None => None,
    };
    let (data, checked) = read_run(&a.data, &spec)?;
    let model = match &file {
        Some(f) => {
            f.check_on_run(&run_extent(&data))?;
            f.check_terms(&data.inputs)?;
            f.model.clone()
        }
        None => Model::ideal(gyro),
    };
    // The model's own effects must be computable on this run.
    computable(&model, &data, &a.data)?;
    let opts = Options {
        grade: a.grade.map(Grade::from),
    };
    let d = discover(&model, &data, &opts);
    // The model written, on another run of the same gyro: what it still
    // misses there.
    let validation = match &a.validate {
        Some(p) => {
            let (v, _) = read_run(p, &spec)?;
            computable(&d.model_after, &v, p)?;
            let opts_v = Options {
                grade: Some(d.grade.value),
            };
            // The model held as written (its terms not refitted): what
            // it predicts of a run it was not fitted on.
            let terms = second_run_terms(&d, &v);
            Some((
                p.clone(),
                discover_library(&d.model_after, &v, &opts_v),
                terms,
            ))
        }
        None => None,
    };
    write_files(a, &d, &data, &checked.warnings)?;
    if a.json.json {
        let mut j = json(&d);
        if let Some((p, v, terms)) = &validation {
            j["validation"] = validation_json(p, v);
            let mut k = 0;
            for f in j["found"].as_array_mut().into_iter().flatten() {
                if f["effect"] == "term" {
                    if let Some(t) = terms.get(k) {
                        f["validation"]["second_run"] = t.json(p);
                    }
                    k += 1;
                }
            }
        }
        j["elapsed_s"] = t0.elapsed().as_secs_f64().into();
        checked.json(&mut j);
        println!("{j}");
        return Ok(());
    }
    checked.print();
    print_text(a, &d);
    if let Some((p, v, terms)) = &validation {
        print_validation(p, v);
        for (t, s) in d
            .terms
            .iter()
            .filter(|t| t.proposed && t.carried.is_none())
            .zip(terms)
        {
            println!(
                "  the term {} on {}: the gap (bias removed) {:.4} deg/h with it, {:.4} without: {}",
                t.term.formula,
                p.display(),
                s.with_dph,
                s.without_dph,
                if s.with_dph < s.without_dph { "it predicts that run" } else { "it does NOT predict that run" }
            );
        }
    }
    Ok(())
}

/// A named term judged on a second run: the gap of the model written with
/// and without it, each with its mean removed (the bias may change from
/// run to run), deg/h.
struct SecondRun {
    with_dph: f64,
    without_dph: f64,
}

impl SecondRun {
    fn json(&self, path: &Path) -> serde_json::Value {
        serde_json::json!({
            "data": path,
            "gap_with_term_dph": self.with_dph,
            "gap_without_term_dph": self.without_dph,
            "predicts": self.with_dph < self.without_dph,
        })
    }
}

/// [`SecondRun`] of each named term of `d`'s model on `v`.
fn second_run_terms(d: &Discovery, v: &Run) -> Vec<SecondRun> {
    let win = crate::model::discovery::windows::Windows::new(&v.inputs.t, WINDOW_S);
    let gap = |m: &Model| -> f64 {
        let sim = m.evaluate(&v.inputs);
        let r: Vec<f64> = v.rate.iter().zip(&sim).map(|(a, b)| a - b).collect();
        let w = win.mean(&r);
        let n = w.len().max(1) as f64;
        let mean = w.iter().sum::<f64>() / n;
        (w.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / n).sqrt() * 3600.0
    };
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
fn validation_json(path: &Path, v: &Discovery) -> serde_json::Value {
    let bias = v
        .found
        .iter()
        .chain(v.carried.iter().map(|c| &c.estimate))
        .find(|e| e.effect == Effect::Bias)
        .map(estimate_json);
    serde_json::json!({
        "data": path,
        "gap_before_dph": v.gap_before_dph,
        "gap_after_dph": v.gap_after_dph,
        "noise_floor_dph": v.noise_floor_dph,
        "found": v.found.iter().map(|e| e.effect).collect::<Vec<_>>(),
        "bias": bias,
        "unexplained": v.unexplained.is_some(),
        "predicts": predicts(v),
    })
}

fn print_validation(path: &Path, v: &Discovery) {
    let names: Vec<&str> = v.found.iter().map(|e| e.effect.name()).collect();
    println!(
        "validation on {}: the model written leaves a gap of {:.4} deg/h (noise floor {:.4}); {} -> {:.4} deg/h; {}",
        path.display(),
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
    );
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

/// model.toml (the model with the effects found), residual.csv and the
/// report, in `--out`.
fn write_files(
    a: &DiscoverArgs,
    d: &Discovery,
    data: &Run,
    warnings: &[crate::record::Warning],
) -> Result<(), LabError> {
    let out = &a.out.out;
    out_path::make(out)?;
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
        a.data.display(),
        a.model
            .as_ref()
            .map_or(" (ideal)".into(), |p| format!(" {}", p.display())),
        if names.is_empty() {
            "nothing named".to_owned()
        } else {
            names.join(", ")
        }
    );
    if !carried.is_empty() {
        comment.push_str(&format!("\ncarried, not named: {}", carried.join("; ")));
    }
    write_model(&out.join("model.toml"), &d.model_after, &comment)?;
    residual_file::write(
        &out.join("residual.csv"),
        &data.inputs.t,
        &d.residual_before,
        &d.residual_after,
    )?;
    write_report(
        &report::report(d, data, &a.data, warnings),
        &out.join("report.html"),
    )?;
    Ok(())
}

fn term_params_text(t: &TermFound) -> String {
    t.term
        .params
        .iter()
        .map(|(n, v)| match t.intervals.get(n) {
            Some((lo, hi)) => format!("{n} {} [{} .. {}]", sig(*v), sig(*lo), sig(*hi)),
            None => format!("{n} {}", sig(*v)),
        })
        .collect::<Vec<_>>()
        .join(", ")
}

fn params_text(e: &Estimate) -> String {
    e.params
        .iter()
        .map(|(n, v, lo, hi)| format!("{n} {} [{} .. {}]", sig(*v), sig(*lo), sig(*hi)))
        .collect::<Vec<_>>()
        .join(", ")
}

fn print_text(a: &DiscoverArgs, d: &Discovery) {
    let out = &a.out.out;
    println!(
        "{}: gap (RMS of {} of measured - model) {:.4} deg/h; noise floor there {:.4} deg/h",
        a.data.display(),
        report::gap_means_text(d),
        d.gap_before_dph,
        d.noise_floor_dph
    );
    println!(
        "grade: {} ({})",
        d.grade.value,
        if d.grade.inferred {
            d.grade.reason.clone()
        } else {
            "given".into()
        }
    );
    for s in &d.skipped {
        let names: Vec<&str> = s.missing.iter().map(|c| c.name()).collect();
        if names.is_empty() {
            println!("skipped {}: {}", s.effect.name(), s.reason);
        } else {
            println!(
                "skipped {}: the run has no {}",
                s.effect.name(),
                names.join(", ")
            );
        }
    }
    if let Some(s) = &d.short {
        println!("short record: {s}");
    }
    for e in &d.found {
        println!(
            "found {}: {} (delta BIC {:.1}, explains {:.1} % of the residual variance)",
            e.effect.name(),
            params_text(e),
            e.delta_bic,
            100.0 * e.explained_share
        );
    }
    for t in &d.terms {
        let ps = term_params_text(t);
        match &t.carried {
            None => println!(
                "{} {} ({}): {ps}; it predicts blocks of the record it was not fitted on by {:.1} noise variances (threshold {}, {} folds){}",
                if t.proposed { "found term, a proposal outside the physics library:" } else { "fitted term written in the model:" },
                t.term.formula,
                t.label,
                t.validation.held_out_gain,
                t.validation.threshold,
                t.validation.folds,
                t.disguise.as_ref().map_or(String::new(), |g| format!("; it is {g}"))
            ),
            Some(why) => println!("carried term {}: {ps} ({why})", t.term.formula),
        }
    }
    if let Some(n) = &d.proposals.note {
        println!("proposal: {n}");
    }
    for c in &d.carried {
        println!(
            "carried {}: {} ({})",
            c.estimate.effect.name(),
            params_text(&c.estimate),
            c.why
        );
    }
    for g in &d.ambiguous {
        println!(
            "ambiguous: {} (correlation {:.3}), carried as {}: {}",
            Effect::names(&g.effects, " / "),
            g.correlation.get(1).copied().unwrap_or(1.0),
            g.carried_as.name(),
            g.suggestion
        );
    }
    for (k, g) in &d.not_confirmed {
        let what = match k {
            Kind::Constant => "bias".to_owned(),
            k => k.describe(),
        };
        println!(
            "set aside {what}: it paid on the selection's noise, but once the noise (random walk, flicker, Markov) is re-fitted without it, it gains only {g:.1} (threshold {}): the noise imitates it",
            crate::model::discovery::select::THRESHOLD
        );
    }
    for i in &d.implausible {
        let o: Vec<String> = i
            .outside
            .iter()
            .map(|(k, v, r)| format!("{k} {} outside {} .. {}", sig(*v), sig(r.0), sig(r.1)))
            .collect();
        println!(
            "implausible {}: {} (not named: no {} is that)",
            i.effect.name(),
            o.join(", "),
            i.effect.name()
        );
    }
    match &d.unexplained {
        Some(u) => {
            println!(
                "no effect of the library explains this: {:.4} deg/h above the noise ({})",
                u.excess_dph,
                u.carried_by.join("; ")
            );
            for s in u.spans.iter().take(8) {
                println!(
                    "  {:.0} .. {:.0} s (peak {:+.4} deg/h)",
                    s.from_s, s.to_s, s.peak_dph
                );
            }
            if u.spans.len() > 8 {
                println!(
                    "  ... {} more spans (in the JSON and the report)",
                    u.spans.len() - 8
                );
            }
            let c: Vec<String> = u
                .correlates
                .iter()
                .take(4)
                .map(|c| format!("{} (r = {:+.2})", c.input, c.correlation))
                .collect();
            println!("  it follows most: {}", c.join(", "));
        }
        None if d.found.is_empty() && d.ambiguous.is_empty() && d.terms.is_empty() => {
            println!("nothing is missing: no effect of the library beats the noise, and nothing stands out of it");
        }
        None => {}
    }
    if let Some(f) = &d.fallback {
        println!("note: {f}");
    }
    println!(
        "the residual after the model averages {:.4} deg/h over the record (95 % interval {:.4} .. {:.4}{})",
        d.residual_mean_dph,
        d.residual_mean_dph - 1.96 * d.residual_mean_sd_dph,
        d.residual_mean_dph + 1.96 * d.residual_mean_sd_dph,
        if d.centred_by_dph != 0.0 {
            format!("; the model's constant moved by {:.4} deg/h to the residual's mean", d.centred_by_dph)
        } else {
            String::new()
        }
    );
    println!(
        "gap {:.4} -> {:.4} deg/h; written {}, residual.csv, report.html",
        d.gap_before_dph,
        d.gap_after_dph,
        out.join("model.toml").display()
    );
}
