//! `gyro-instruments simulate outside`: the outside generator's cases
//! (sim/outside_run/) as files: per case two runs of the same gyro,
//! `DIR/NN-kind-R-A.csv` and `-B.csv`, the hidden term per row beside each
//! (`-A.hidden.csv`: `t_s`, `hidden_dph`), and `DIR/truth.json` (per case:
//! category, gyro, the names a right answer holds and may hold, the hidden
//! term's parameters and description, per run the noise's 1 s floor and
//! its realised figures).

use crate::sim::outside_run::{outside_set, OutsideCase, OutsideRun};
use clap::Args;
use gyro_lab::cli::args::{Json, Out, Seed};
use gyro_lab_core::data::csv_writer::CellFormat::{Exp, Fixed, Shortest};
use gyro_lab_core::data::csv_writer::CsvWriter;
use gyro_lab_core::data::run_file::{Column, RunWriter};
use gyro_lab_core::error::LabError;
use std::path::Path;

/// The side file's column of the hidden term, deg/h.
pub const HIDDEN_COLUMN: &str = "hidden_dph";

#[derive(Args, Debug, Clone)]
pub struct OutsideArgs {
    #[command(flatten)]
    pub seed: Seed,
    /// Directory for the runs, their hidden terms and truth.json.
    #[command(flatten)]
    pub out: Out,
    /// Cases per kind (21 kinds: 10 physical terms, 4 events, 4 nulls, 3
    /// library effects), each two runs.
    #[arg(long, default_value_t = 2)]
    pub per_kind: usize,
    #[command(flatten)]
    pub json: Json,
}

fn write_run(c: &OutsideCase, r: &OutsideRun, which: &str, path: &Path) -> Result<(), LabError> {
    let mut cols = vec![
        (Column::Time, Shortest),
        (Column::RefRate, Fixed(9)),
        (Column::Rate, Exp(12)),
    ];
    if r.temp.is_some() {
        cols.push((Column::Temp, Fixed(4)));
    }
    if r.mono.is_some() {
        cols.extend([(Column::MonoA, Fixed(4)), (Column::MonoB, Fixed(4))]);
    }
    if r.case.is_some() {
        cols.push((Column::Case, Fixed(4)));
    }
    if r.acc.is_some() {
        cols.push((Column::RefAcc, Fixed(4)));
    }
    let mut w = RunWriter::create(
        path,
        &format!(
            "gyro-instruments simulate outside: {} run {which} ({}); {}; noise: {}",
            c.name,
            c.category.name(),
            r.profile,
            c.noise.describe()
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

fn write_hidden(c: &OutsideCase, r: &OutsideRun, path: &Path) -> Result<(), LabError> {
    let mut w = CsvWriter::create(
        path,
        &format!(
            "gyro-instruments simulate outside: {}: the hidden term's contribution per row (deg/h)",
            c.name
        ),
        &[(Column::Time.name(), Shortest), (HIDDEN_COLUMN, Exp(10))],
    )?;
    for (t, h) in r.t.iter().zip(&r.hidden_dph) {
        w.row(&[*t, *h])?;
    }
    w.finish()
}

fn run_json(r: &OutsideRun, file: &str, hidden: &str) -> serde_json::Value {
    let dt = r.t.get(1).zip(r.t.first()).map_or(0.0, |(b, a)| b - a);
    serde_json::json!({
        "file": file,
        "hidden": hidden,
        "rows": r.t.len(),
        "dt_s": dt,
        "bias_dph": r.bias_dph,
        "floor_dph": r.floor_dph,
        "white_1s_dph": r.white_1s_dph,
        "noise_1s_dph": r.noise_1s_dph,
        "hidden_1s_dph": r.hidden_1s_dph,
        "multiple_of_floor": r.hidden_1s_dph / r.floor_dph,
        "profile": r.profile,
    })
}

pub fn run(a: &OutsideArgs) -> Result<(), LabError> {
    if a.per_kind == 0 || a.per_kind > 100 {
        return Err(LabError::Usage(format!(
            "--per-kind {}: 1..100",
            a.per_kind
        )));
    }
    let dir = &a.out.out;
    std::fs::create_dir_all(dir).map_err(|e| LabError::io(dir, e))?;
    let cases = outside_set(a.seed.seed, a.per_kind);
    let mut truth = vec![];
    for (i, c) in cases.iter().enumerate() {
        let stem = format!("{:02}-{}", i + 1, c.name);
        let mut runs = serde_json::Map::new();
        for (which, r) in [("A", &c.a), ("B", &c.b)] {
            let file = format!("{stem}-{which}.csv");
            let hidden = format!("{stem}-{which}.hidden.csv");
            write_run(c, r, which, &dir.join(&file))?;
            write_hidden(c, r, &dir.join(&hidden))?;
            runs.insert(which.to_lowercase(), run_json(r, &file, &hidden));
        }
        let mut j = serde_json::json!({
            "name": c.name,
            "kind": c.kind,
            "category": c.category.name(),
            "gyro": c.gyro.name(),
            "expect": c.expect,
            "allow": c.allow,
            "hidden": c.hidden.describe(),
            "parameters": c.parameters,
            "multiple_of_floor": c.multiple,
            "noise": c.noise,
        });
        for (k, v) in runs {
            j[k] = v;
        }
        truth.push(j);
    }
    let path = dir.join("truth.json");
    let text = serde_json::to_string_pretty(&truth).map_err(|e| LabError::io(&path, e))?;
    std::fs::write(&path, text).map_err(|e| LabError::io(&path, e))?;
    if a.json.json {
        println!(
            "{}",
            serde_json::json!({"cases": cases.len(), "runs": 2 * cases.len(), "out": dir})
        );
    } else {
        println!(
            "{} cases ({} runs, their hidden terms) and truth.json -> {}",
            cases.len(),
            2 * cases.len(),
            dir.display()
        );
    }
    Ok(())
}
