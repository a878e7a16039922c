//! `gyro-lab compensate`: a coefficient file (by its `kind`) applied to a
//! run as the firmware applies it, or a model from `discover`; the run
//! written back with `rate_comp_dps`, the report beside it. What it does is
//! gyro_lab_core's commands::compensate.

use crate::cli::args::{Json, NoReport, Out, RunRead};
use crate::cli::out_path::{self, FileKind};
use crate::cli::output::write_report;
use clap::Args;
use gyro_lab_core::commands::compensate::{compensate_run, read_coeffs, Request};
use gyro_lab_core::data::source::Source;
use gyro_lab_core::error::LabError;
use std::path::PathBuf;

#[derive(Args, Debug, Clone)]
#[command(mut_arg("out", |a| a.help("A file: the run written back with the compensated rate added (CSV); its report is written beside it (.html)")))]
pub struct CompensateArgs {
    /// Coefficient file: `rlg_thermal` or `fog_scale_factor` (from `gyro-lab
    /// fit`), or a `gyro_model` (from `gyro-lab discover`).
    #[arg(long)]
    pub coeffs: PathBuf,
    /// Run file to compensate (t_s, rate_dps, and the temperature columns the
    /// coefficients need).
    #[arg(long)]
    pub data: PathBuf,
    #[command(flatten)]
    pub read: RunRead,
    #[command(flatten)]
    pub out: Out,
    /// Also fit the classic cubic on this file and report it (comparison only).
    #[arg(long)]
    pub cubic_from: Option<PathBuf>,
    #[command(flatten)]
    pub no_report: NoReport,
    #[command(flatten)]
    pub json: Json,
}

pub fn run(a: &CompensateArgs) -> Result<(), LabError> {
    let spec = a.read.spec()?;
    let beside: Vec<_> = match a.no_report.no_report {
        false => vec![(out_path::report_beside(&a.out.out), FileKind::Html)],
        true => vec![],
    };
    let mut inputs = vec![
        ("--data", a.data.as_path()),
        ("--coeffs", a.coeffs.as_path()),
    ];
    if let Some(c) = &a.cubic_from {
        inputs.push(("--cubic-from", c.as_path()));
    }
    out_path::file(
        "compensate",
        &a.out.out,
        FileKind::Csv,
        &beside,
        &inputs,
        a.out.force,
    )?;
    let text = std::fs::read_to_string(&a.coeffs)
        .map_err(|e| LabError::input(&a.coeffs, format!("cannot read: {e}")))?;
    let coeffs_name = a.coeffs.display().to_string();
    let coeffs = read_coeffs(&text, &coeffs_name)?;
    let o = compensate_run(&Request {
        coeffs: &coeffs,
        coeffs_name: &coeffs_name,
        source: Source::File(&a.data),
        spec: &spec,
        cubic_from: a.cubic_from.as_deref().map(Source::File),
        report: !a.no_report.no_report,
    })?;
    gyro_lab_core::data::atomic::write(&a.out.out, o.run_text())?;
    let report = o
        .report
        .as_ref()
        .map(|r| (r, out_path::report_beside(&a.out.out)));
    if let Some((r, p)) = &report {
        write_report(r, p)?;
    }
    let report_path = report.map(|(_, p)| p.display().to_string());
    if a.json.json {
        let mut j = o.json.clone();
        j["out"] = a.out.out.display().to_string().into();
        j["report"] = report_path.into();
        println!("{j}");
        return Ok(());
    }
    for l in &o.text {
        println!("{l}");
    }
    println!("written: {}", a.out.out.display());
    if let Some(p) = report_path {
        println!("report: {p}");
    }
    Ok(())
}
