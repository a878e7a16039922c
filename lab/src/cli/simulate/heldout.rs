//! `gyro-lab simulate heldout`: the second, independent generator's
//! held-out set (sim/heldout_run.rs) as run files and their truth:
//! `DIR/NN-name.csv` and `DIR/truth.json` (per run: file, category, gyro,
//! the names a right answer holds, the truth in the library's terms, the
//! disturbances outside the library, the noise).

use crate::cli::args::{Json, Out, Seed};
use crate::data::csv_writer::CellFormat::{Exp, Fixed, Shortest};
use crate::data::run_file::{Column, RunWriter};
use crate::error::LabError;
use crate::sim::heldout_run::{held_out, HeldOutRun};
use clap::Args;

#[derive(Args, Debug, Clone)]
pub struct HeldOutArgs {
    #[command(flatten)]
    pub seed: Seed,
    /// Directory for the runs and truth.json.
    #[command(flatten)]
    pub out: Out,
    #[command(flatten)]
    pub json: Json,
}

fn write_run(r: &HeldOutRun, path: &std::path::Path) -> Result<(), LabError> {
    let mut cols = vec![
        (Column::Time, Shortest),
        (Column::RefRate, Fixed(9)),
        (Column::Rate, Exp(12)),
    ];
    if r.temp.is_some() {
        cols.push((Column::Temp, Fixed(3)));
    }
    if r.mono.is_some() {
        cols.extend([(Column::MonoA, Fixed(3)), (Column::MonoB, Fixed(3))]);
    }
    if r.case.is_some() {
        cols.push((Column::Case, Fixed(3)));
    }
    if r.acc.is_some() {
        cols.push((Column::RefAcc, Fixed(4)));
    }
    let mut w = RunWriter::create(
        path,
        &format!(
            "gyro-lab simulate heldout: {} ({}); noise: {}",
            r.name, r.category, r.noise
        ),
        &cols,
    )?;
    let mut row = Vec::with_capacity(cols.len());
    for k in 0..r.t.len() {
        row.clear();
        row.extend([r.t[k], r.w[k], r.rate[k]]);
        if let Some(x) = &r.temp {
            row.push(x[k]);
        }
        if let Some((a, b)) = &r.mono {
            row.extend([a[k], b[k]]);
        }
        if let Some(x) = &r.case {
            row.push(x[k]);
        }
        if let Some(x) = &r.acc {
            row.push(x[k]);
        }
        w.row(&row)?;
    }
    w.finish()
}

pub fn run(a: &HeldOutArgs) -> Result<(), LabError> {
    let dir = &a.out.out;
    std::fs::create_dir_all(dir).map_err(|e| LabError::io(dir, e))?;
    let runs = held_out(a.seed.seed);
    let mut truth = vec![];
    for (i, r) in runs.iter().enumerate() {
        let file = format!("{:02}-{}.csv", i + 1, r.name.replace('+', "_"));
        write_run(r, &dir.join(&file))?;
        truth.push(serde_json::json!({
            "file": file,
            "name": r.name,
            "category": r.category,
            "gyro": r.gyro.name(),
            "expect": r.expect,
            "truth": r.truth,
            "outside": r.outside,
            "noise": r.noise,
        }));
    }
    let path = dir.join("truth.json");
    let text = serde_json::to_string_pretty(&truth).map_err(|e| LabError::io(&path, e))?;
    std::fs::write(&path, text).map_err(|e| LabError::io(&path, e))?;
    let j = serde_json::json!({"runs": runs.len(), "out": dir});
    if a.json.json {
        println!("{j}");
    } else {
        println!("{} runs and truth.json -> {}", runs.len(), dir.display());
    }
    Ok(())
}
