//! `gyro-lab discover`: where the model and the measured data disagree, the
//! named effect that is missing, the model with it added, and the gap
//! shrinking (docs/discovery.md).
//!
//! 1. The model (model.rs; without `--model` the ideal gyro) is evaluated on
//!    the run's inputs; the residual is measured minus model.
//! 2. The noise floor comes from the residual itself: its Allan deviation at
//!    the gap's 1 s averaging, robustly (the median of the squared
//!    differences of consecutive 1 s means, so slow effects and a few steps
//!    are differenced away), or the Allan noise model's where lower. The stretches
//!    where the residual, smoothed over 60 s, stands more than three floors
//!    out are listed; the floor there is the Allan noise terms
//!    (quantization, angle random walk, bias instability: a missing
//!    effect's drift shows as the others) at 60 s.
//! 3. Every applicable effect of the library (effects.rs) is a candidate;
//!    select.rs chooses among them by BIC, names ambiguous pairs, and gives
//!    the parameters with intervals.
//! 4. The model with the found effects added is written back, with the
//!    residual before and after and a report.

pub mod bench;
pub mod report;
pub mod select;
pub mod trials;

use crate::allan;
use crate::data::residual_file;
use crate::data::run_file::{Column, RunFile};
use crate::effects::{Effect, GyroKind, Inputs};
use crate::error::LabError;
use crate::model::{Model, ModelEffect};
use clap::Args;
use select::{Design, Estimate, Selection, Windows};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// The gap's averaging, s.
pub const WINDOW_S: f64 = 1.0;
/// Smoothing of the disagreement search, s.
pub const SMOOTH_S: f64 = 60.0;

#[derive(Args, Debug, Clone)]
pub struct DiscoverArgs {
    #[arg(long, value_enum)]
    pub gyro: GyroKind,
    /// The model (model.toml); the ideal gyro without it.
    #[arg(long)]
    pub model: Option<PathBuf>,
    /// Run file (t_s, ref_rate_dps, rate_dps; temp_c, t_mono_a_c,
    /// t_mono_b_c, t_case_c, ref_acc_dps2 where the effects need them).
    #[arg(long)]
    pub data: PathBuf,
    #[arg(long)]
    pub out: PathBuf,
    #[arg(long)]
    pub json: bool,
}

/// A run's inputs and measured rate.
pub struct Run {
    pub inputs: Inputs,
    pub rate: Vec<f64>,
}

/// Reads a run file for discovery.
pub fn read_run(path: &Path) -> Result<Run, LabError> {
    let r = RunFile::read_long(
        path,
        10,
        &[
            Column::Temp,
            Column::MonoA,
            Column::MonoB,
            Column::Case,
            Column::RefAcc,
        ],
    )?;
    let mono = match (r.t_mono_a_c, r.t_mono_b_c) {
        (Some(a), Some(b)) => Some((a, b)),
        _ => None,
    };
    Ok(Run {
        inputs: Inputs::new(
            r.t_s,
            r.ref_rate_dps,
            r.temp_c,
            mono,
            r.t_case_c,
            r.ref_acc_dps2,
        ),
        rate: r.rate_dps,
    })
}

/// A stretch where the model and the data disagree.
#[derive(Clone, Debug, serde::Serialize)]
pub struct Disagreement {
    pub from_s: f64,
    pub to_s: f64,
    /// Largest smoothed residual there, deg/h.
    pub peak_dph: f64,
}

pub struct Discovery {
    pub gyro: GyroKind,
    pub found: Vec<Estimate>,
    pub selection: Selection,
    pub skipped: Vec<(Effect, &'static [Column])>,
    pub residual_before: Vec<f64>,
    pub residual_after: Vec<f64>,
    pub windows: Windows,
    pub gap_before_dph: f64,
    pub gap_after_dph: f64,
    pub noise_floor_dph: f64,
    pub disagreements: Vec<Disagreement>,
    pub model_after: Model,
    pub allan_before: Option<allan::Allan>,
    pub allan_after: Option<allan::Allan>,
}

/// RMS of the window means of `r` (deg/s) in deg/h.
fn gap(win: &Windows, r: &[f64]) -> f64 {
    let m = win.mean(r);
    (m.iter().map(|v| v * v).sum::<f64>() / m.len().max(1) as f64).sqrt() * 3600.0
}

/// The Allan analysis of a residual when its sampling allows.
fn allan_of(t: &[f64], r: &[f64]) -> Option<allan::Allan> {
    if t.len() < 10 {
        return None;
    }
    let dt: Vec<f64> = t.windows(2).map(|w| w[1] - w[0]).collect();
    let mut s = dt.clone();
    s.sort_by(f64::total_cmp);
    let med = s[s.len() / 2];
    if dt
        .iter()
        .any(|h| (h - med).abs() > allan::SAMPLING_TOLERANCE * med)
    {
        return None;
    }
    allan::analyse(r, med).ok()
}

/// The noise of a mean over `tau` from a residual's Allan model
/// (quantization 2Q^2/tau^2, the variance of a mean of white angle noise;
/// angle random walk N^2/tau; bias instability its floor), deg/h; a robust
/// scatter of first differences when the Allan analysis is not possible.
fn noise_at(a: Option<&allan::Allan>, t: &[f64], r: &[f64], tau: f64) -> f64 {
    if let Some(a) = a {
        let c = &a.terms.c;
        let v = 2.0 * c[0] / (tau * tau) + c[1] / tau + c[2] * allan::terms::basis(2, tau);
        if v > 0.0 {
            return v.sqrt() * 3600.0;
        }
    }
    let mut d: Vec<f64> = r.windows(2).map(|w| (w[1] - w[0]).abs()).collect();
    d.sort_by(f64::total_cmp);
    let sigma = d.get(d.len() / 2).copied().unwrap_or(0.0) * 1.4826 / 2f64.sqrt();
    let dt = (t[t.len() - 1] - t[0]) / (t.len() - 1).max(1) as f64;
    sigma * (dt / tau).min(1.0).sqrt() * 3600.0
}

pub fn discover(model: &Model, run: &Run) -> Discovery {
    let inp = &run.inputs;
    let sim = model.evaluate(inp);
    let r: Vec<f64> = run.rate.iter().zip(&sim).map(|(y, s)| y - s).collect();
    let win = Windows::new(&inp.t, WINDOW_S);
    let allan_before = allan_of(&inp.t, &r);
    // The measured Allan deviation at the window (a periodic error, the
    // FOG's under vibration, averages out of a 1 s mean and out of it; it
    // reads white angle noise sqrt(3/2) high), or the model's noise of a
    // window mean where that is lower.
    let model_floor = noise_at(allan_before.as_ref(), &inp.t, &r, WINDOW_S);
    let means = win.mean(&r);
    let mut d2: Vec<f64> = means.windows(2).map(|p| (p[1] - p[0]).powi(2)).collect();
    d2.sort_by(f64::total_cmp);
    // Median of chi-square with one degree of freedom: 0.4549.
    let measured = d2
        .get(d2.len() / 2)
        .map_or(f64::INFINITY, |m| (m / (2.0 * 0.454_936)).sqrt() * 3600.0);
    let floor = if d2.len() >= 10 {
        measured.min(model_floor)
    } else {
        model_floor
    };
    // Disagreements: the residual smoothed over SMOOTH_S against three floors there.
    let smooth = Windows::new(&inp.t, SMOOTH_S);
    let sm = smooth.mean(&r);
    let floor_s = noise_at(allan_before.as_ref(), &inp.t, &r, SMOOTH_S);
    let mut disagreements: Vec<Disagreement> = vec![];
    let half = 0.5 * SMOOTH_S;
    // A window's span, clipped to the record (a record shorter than a window
    // is one window).
    let (t_first, t_last) = (inp.t[0], inp.t[inp.t.len() - 1]);
    let span = |t: f64| ((t - half).max(t_first), (t + half).min(t_last));
    for (i, v) in sm.iter().enumerate() {
        let dph = v * 3600.0;
        if dph.abs() > 3.0 * floor_s {
            let t = smooth.t[i];
            // Stretches a smoothing window or two apart are one.
            match disagreements.last_mut() {
                Some(d) if span(t).0 <= d.to_s + 2.0 * SMOOTH_S => {
                    d.to_s = span(t).1;
                    if dph.abs() > d.peak_dph.abs() {
                        d.peak_dph = dph;
                    }
                }
                _ => disagreements.push(Disagreement {
                    from_s: span(t).0,
                    to_s: span(t).1,
                    peak_dph: dph,
                }),
            }
        }
    }
    let candidates: Vec<Effect> = Effect::ALL
        .into_iter()
        .filter(|e| e.applies_to(model.gyro) && e.available(inp))
        .collect();
    let skipped: Vec<(Effect, &'static [Column])> = Effect::ALL
        .into_iter()
        .filter(|e| e.applies_to(model.gyro) && !e.available(inp))
        .map(|e| (e, e.needs()))
        .collect();
    let design = Design {
        inp,
        win: &win,
        r: win.mean(&r),
    };
    // Two passes: the residual correlation of the first selection sets the
    // variance inflation of the second.
    let first = select::select(&design, &candidates, 1.0);
    let terms: Vec<select::Term> = first
        .chosen
        .iter()
        .map(|s| s.term)
        .chain(first.nuisance.iter().copied())
        .collect();
    let phi = design.inflation(&terms);
    let selection = select::select(&design, &candidates, phi);
    let found = select::estimates(&design, &selection);
    let mut model_after = model.clone();
    for e in &found {
        let params: BTreeMap<String, f64> =
            e.params.iter().map(|p| (p.0.to_owned(), p.1)).collect();
        model_after.effects.push(ModelEffect {
            effect: e.effect,
            params,
        });
    }
    let sim_after = model_after.evaluate(inp);
    let r_after: Vec<f64> = run
        .rate
        .iter()
        .zip(&sim_after)
        .map(|(y, s)| y - s)
        .collect();
    let allan_after = allan_of(&inp.t, &r_after);
    Discovery {
        gyro: model.gyro,
        found,
        selection,
        skipped,
        gap_before_dph: gap(&win, &r),
        gap_after_dph: gap(&win, &r_after),
        noise_floor_dph: floor,
        disagreements,
        residual_before: r,
        residual_after: r_after,
        windows: win,
        model_after,
        allan_before,
        allan_after,
    }
}

#[derive(serde::Serialize)]
struct FoundJson {
    effect: &'static str,
    parameters: BTreeMap<&'static str, f64>,
    parameter_intervals: BTreeMap<&'static str, [f64; 2]>,
    delta_bic: f64,
    explained_share: f64,
}

pub fn json(d: &Discovery) -> serde_json::Value {
    let found: Vec<FoundJson> = d
        .found
        .iter()
        .map(|e| FoundJson {
            effect: e.effect.name(),
            parameters: e.params.iter().map(|p| (p.0, p.1)).collect(),
            parameter_intervals: e.params.iter().map(|p| (p.0, [p.2, p.3])).collect(),
            delta_bic: e.delta_bic,
            explained_share: e.explained_share,
        })
        .collect();
    let skipped: Vec<serde_json::Value> = d
        .skipped
        .iter()
        .map(|(e, cols)| {
            let names: Vec<&str> = cols.iter().map(|c| c.name()).collect();
            serde_json::json!({"effect": e.name(), "missing": names})
        })
        .collect();
    serde_json::json!({
        "found": found,
        "gap_before_dph": d.gap_before_dph,
        "gap_after_dph": d.gap_after_dph,
        "noise_floor_dph": d.noise_floor_dph,
        "ambiguous": d.selection.ambiguous,
        "skipped": skipped,
        "disagreements": d.disagreements,
        "noise_inflation": d.selection.inflation,
        "windows": d.windows.len(),
        "gyro": d.gyro.name(),
    })
}

pub fn run(a: &DiscoverArgs) -> Result<(), LabError> {
    let t0 = std::time::Instant::now();
    let model = match &a.model {
        Some(p) => Model::read(p, a.gyro)?,
        None => Model::ideal(a.gyro),
    };
    let data = read_run(&a.data)?;
    // The model's own effects must be computable on this run.
    if let Some((e, cols)) = model.missing_inputs(&data.inputs).first() {
        return Err(LabError::input(
            &a.data,
            format!(
                "the model's effect `{}` needs column(s) {} that this run lacks",
                e.name(),
                cols.iter()
                    .map(|c| format!("`{}`", c.name()))
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
        ));
    }
    let d = discover(&model, &data);
    std::fs::create_dir_all(&a.out).map_err(|e| LabError::io(&a.out, e))?;
    let names: Vec<&str> = d.found.iter().map(|e| e.effect.name()).collect();
    d.model_after.write(
        &a.out.join("model.toml"),
        &format!(
            "gyro-lab discover on {}: the model{} with {} added",
            a.data.display(),
            a.model
                .as_ref()
                .map_or(" (ideal)".into(), |p| format!(" {}", p.display())),
            if names.is_empty() {
                "nothing".to_owned()
            } else {
                names.join(", ")
            }
        ),
    )?;
    residual_file::write(
        &a.out.join("residual.csv"),
        &data.inputs.t,
        &d.residual_before,
        &d.residual_after,
    )?;
    let html = a.out.join("report.html");
    report::report(&d, &data, &a.data)
        .write(&html)
        .map_err(|e| LabError::io(&html, e))?;
    if a.json {
        let mut j = json(&d);
        j["elapsed_s"] = t0.elapsed().as_secs_f64().into();
        println!("{j}");
        return Ok(());
    }
    println!(
        "{}: gap (RMS of {} s means of measured - model) {:.4} deg/h; noise floor there {:.4} deg/h",
        a.data.display(),
        WINDOW_S,
        d.gap_before_dph,
        d.noise_floor_dph
    );
    for s in d.disagreements.iter().take(8) {
        println!(
            "  disagrees {:.0} .. {:.0} s (peak {:+.4} deg/h over {} s)",
            s.from_s, s.to_s, s.peak_dph, SMOOTH_S
        );
    }
    if d.disagreements.len() > 8 {
        println!(
            "  ... {} more stretches (in the JSON and the report)",
            d.disagreements.len() - 8
        );
    }
    for (e, cols) in &d.skipped {
        let names: Vec<&str> = cols.iter().map(|c| c.name()).collect();
        println!("skipped {}: the run has no {}", e.name(), names.join(", "));
    }
    if d.found.is_empty() && d.selection.ambiguous.is_empty() {
        println!("nothing is missing: no effect of the library beats the noise");
    }
    for e in &d.found {
        let p: Vec<String> = e
            .params
            .iter()
            .map(|(n, v, lo, hi)| {
                format!(
                    "{n} {} [{} .. {}]",
                    crate::report::sig(*v),
                    crate::report::sig(*lo),
                    crate::report::sig(*hi)
                )
            })
            .collect();
        println!(
            "found {}: {} (delta BIC {:.1}, explains {:.1} % of the residual variance)",
            e.effect.name(),
            p.join(", "),
            e.delta_bic,
            100.0 * e.explained_share
        );
    }
    for g in &d.selection.ambiguous {
        println!(
            "ambiguous: {} (correlation {:.3}): {}",
            g.effects.join(" / "),
            g.correlation.get(1).copied().unwrap_or(1.0),
            g.suggestion
        );
    }
    println!(
        "gap {:.4} -> {:.4} deg/h; written {}, residual.csv, report.html",
        d.gap_before_dph,
        d.gap_after_dph,
        a.out.join("model.toml").display()
    );
    Ok(())
}
