//! `gyro-instruments simulate heldout`: an independent generator's held-out set
//! (`--generator second`, sim/heldout_run/, the default; `--generator
//! third`, sim/third_run/) as run files and their truth:
//! `DIR/NN-name.csv` and `DIR/truth.json` (per run: file, category, gyro,
//! the names a right answer holds, the truth in the library's terms, the
//! disturbances outside the library, the noise; from the third, the
//! grade, and for MEMS runs `validate`, a second day of the same gyro
//! written beside it).

use crate::sim::heldout_run::{held_out, HeldOutRun};
use crate::sim::third_run::third_set;
use clap::{Args, ValueEnum};
use gyro_lab::cli::args::{Json, Out, Seed};
use gyro_lab_core::data::csv_writer::CellFormat::{Exp, Fixed, Shortest};
use gyro_lab_core::data::run_file::{Column, RunWriter};
use gyro_lab_core::error::LabError;

/// Which independent generator.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum Generator {
    /// The second generator (issue 22).
    Second,
    /// The third, written apart from both (issue 31).
    Third,
}

#[derive(Args, Debug, Clone)]
pub struct HeldOutArgs {
    /// Which independent generator writes the set: `second` (issue 22's
    /// 53 runs) or `third` (issue 31's, written apart from both).
    #[arg(long, value_enum, default_value = "second")]
    pub generator: Generator,
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
            "gyro-instruments simulate heldout: {} ({}); noise: {}",
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
    let runs: Vec<(HeldOutRun, Option<&str>, Option<HeldOutRun>)> = match a.generator {
        Generator::Second => held_out(a.seed.seed)
            .into_iter()
            .map(|r| (r, None, None))
            .collect(),
        Generator::Third => third_set(a.seed.seed)
            .into_iter()
            .map(|r| (r.run, Some(r.grade), r.day2))
            .collect(),
    };
    let mut truth = vec![];
    for (i, (r, grade, day2)) in runs.iter().enumerate() {
        let file = format!("{:02}-{}.csv", i + 1, r.name.replace('+', "_"));
        write_run(r, &dir.join(&file))?;
        let mut j = serde_json::json!({
            "file": file,
            "name": r.name,
            "category": r.category,
            "gyro": r.gyro.name(),
            "expect": r.expect,
            "truth": r.truth,
            "outside": r.outside,
            "noise": r.noise,
        });
        if let Some(g) = grade {
            j["grade"] = (*g).into();
        }
        if let Some(d2) = day2 {
            let f2 = format!("{:02}-{}.csv", i + 1, d2.name.replace('+', "_"));
            write_run(d2, &dir.join(&f2))?;
            j["validate"] = f2.into();
            j["validate_truth"] = serde_json::to_value(&d2.truth).unwrap_or_default();
        }
        truth.push(j);
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
