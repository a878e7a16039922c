//! `gyro-lab discover`: reads the model and the run, hands them to the
//! discovery (model/discovery/), and writes what it found: the model with
//! the effects added, residual.csv, the report and the JSON.

pub mod report;

use crate::cli::args::{Json, Out};
use crate::cli::model_file::{read_model, write_model};
use crate::cli::output::write_report;
use crate::data::residual_file;
use crate::data::run_file::{Column, RunFile};
use crate::error::LabError;
use crate::model::discovery::{discover, Discovery, Run, SMOOTH_S, WINDOW_S};
use crate::model::effects::Effect;
use crate::model::gyro_kind::GyroKind;
use crate::model::gyro_model::Model;
use crate::model::inputs::Inputs;
use crate::report::text::sig;
use clap::{Args, ValueEnum};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// The gyro kinds, as the command line names them.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum GyroArg {
    Fog,
    Rlg,
}

impl From<GyroArg> for GyroKind {
    fn from(g: GyroArg) -> Self {
        match g {
            GyroArg::Fog => GyroKind::Fog,
            GyroArg::Rlg => GyroKind::Rlg,
        }
    }
}

#[derive(Args, Debug, Clone)]
pub struct DiscoverArgs {
    #[arg(long, value_enum)]
    pub gyro: GyroArg,
    /// The model (model.toml); the ideal gyro without it.
    #[arg(long)]
    pub model: Option<PathBuf>,
    /// Run file (t_s, ref_rate_dps, rate_dps; temp_c, t_mono_a_c,
    /// t_mono_b_c, t_case_c, ref_acc_dps2 where the effects need them).
    #[arg(long)]
    pub data: PathBuf,
    #[command(flatten)]
    pub out: Out,
    #[command(flatten)]
    pub json: Json,
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

#[derive(serde::Serialize)]
struct FoundJson {
    effect: Effect,
    parameters: BTreeMap<&'static str, f64>,
    parameter_intervals: BTreeMap<&'static str, [f64; 2]>,
    delta_bic: f64,
    explained_share: f64,
}

/// The JSON of a discovery (docs/interfaces.md keys and more).
pub fn json(d: &Discovery) -> serde_json::Value {
    let found: Vec<FoundJson> = d
        .found
        .iter()
        .map(|e| FoundJson {
            effect: e.effect,
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
    let gyro = GyroKind::from(a.gyro);
    let model = match &a.model {
        Some(p) => read_model(p, gyro)?,
        None => Model::ideal(gyro),
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
    write_files(a, &d, &data)?;
    if a.json.json {
        let mut j = json(&d);
        j["elapsed_s"] = t0.elapsed().as_secs_f64().into();
        println!("{j}");
        return Ok(());
    }
    print_text(a, &d);
    Ok(())
}

/// model.toml (the model with the effects found), residual.csv and the
/// report, in `--out`.
fn write_files(a: &DiscoverArgs, d: &Discovery, data: &Run) -> Result<(), LabError> {
    let out = &a.out.out;
    std::fs::create_dir_all(out).map_err(|e| LabError::io(out, e))?;
    let names: Vec<&str> = d.found.iter().map(|e| e.effect.name()).collect();
    write_model(
        &out.join("model.toml"),
        &d.model_after,
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
        &out.join("residual.csv"),
        &data.inputs.t,
        &d.residual_before,
        &d.residual_after,
    )?;
    write_report(&report::report(d, data, &a.data), &out.join("report.html"))?;
    Ok(())
}

fn print_text(a: &DiscoverArgs, d: &Discovery) {
    let out = &a.out.out;
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
            .map(|(n, v, lo, hi)| format!("{n} {} [{} .. {}]", sig(*v), sig(*lo), sig(*hi)))
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
            Effect::names(&g.effects, " / "),
            g.correlation.get(1).copied().unwrap_or(1.0),
            g.suggestion
        );
    }
    println!(
        "gap {:.4} -> {:.4} deg/h; written {}, residual.csv, report.html",
        d.gap_before_dph,
        d.gap_after_dph,
        out.join("model.toml").display()
    );
}
