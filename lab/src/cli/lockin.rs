//! `gyro-lab lockin`: the RLG lock-in rate of a fringe record
//! (gyro_lab_core's commands::lockin); the report in `--out`.

use crate::cli::args::{Json, OutOpt, RunRead};
use crate::cli::out_path::{self, FileKind};
use crate::cli::output::write_report;
use clap::Args;
use gyro_lab_core::commands::lockin::lockin;
use gyro_lab_core::data::source::Source;
use gyro_lab_core::error::LabError;
use std::path::PathBuf;

#[derive(Args, Debug, Clone)]
#[command(mut_arg("out", |a| a.help("A folder: report.html is written in it")))]
pub struct LockinArgs {
    /// Fringe file: `t_s`, `signal`, optional `signal_q`.
    #[arg(long)]
    pub data: PathBuf,
    #[command(flatten)]
    pub read: RunRead,
    /// Scale factor K, pulses (fringes) per degree.
    #[arg(long)]
    pub pulses_per_deg: f64,
    /// Input rate, deg/s (estimated from the record when not given).
    #[arg(long, allow_negative_numbers = true)]
    pub input_rate_dps: Option<f64>,
    #[command(flatten)]
    pub out: OutOpt,
    #[command(flatten)]
    pub json: Json,
}

pub fn run(a: &LockinArgs) -> Result<(), LabError> {
    if !(a.pulses_per_deg.is_finite() && a.pulses_per_deg > 0.0) {
        return Err(LabError::Usage(format!(
            "--pulses-per-deg {}: must be positive",
            a.pulses_per_deg
        )));
    }
    if let Some(w) = a.input_rate_dps {
        if !w.is_finite() || w == 0.0 {
            return Err(LabError::Usage(format!(
                "--input-rate-dps {w}: must be finite and non-zero"
            )));
        }
    }
    let spec = a.read.spec()?;
    if let Some(dir) = &a.out.out {
        out_path::folder(
            "lockin",
            dir,
            &[("report.html", FileKind::Html)],
            &[("--data", &a.data)],
            a.out.force,
        )?;
    }
    let o = lockin(
        Source::File(&a.data),
        &spec,
        a.pulses_per_deg,
        a.input_rate_dps,
        a.out.out.is_some(),
    )?;
    let report = match (&a.out.out, &o.report) {
        (Some(dir), Some(r)) => {
            out_path::make(dir)?;
            let path = dir.join("report.html");
            write_report(r, &path)?;
            Some(path.display().to_string())
        }
        _ => None,
    };
    if a.json.json {
        let mut j = o.json.clone();
        j["report"] = report.into();
        println!("{j}");
        return Ok(());
    }
    for l in &o.text {
        println!("{l}");
    }
    if let Some(p) = report {
        println!("report: {p}");
    }
    Ok(())
}
