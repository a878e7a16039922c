//! `gyro-lab fit thermal` and `gyro-lab fit scale-factor`: the
//! calibrations on a test-rig run (gyro_lab_core's commands), written as
//! the coefficient files the firmware loads, their reports beside them.

use crate::cli::args::{Json, NoReport, Out, RunRead};
use crate::cli::out_path::{self, FileKind};
use crate::cli::output::write_report;
use clap::Args;
use gyro_lab_core::commands::fit_scale_factor::fit_scale_factor;
use gyro_lab_core::commands::fit_thermal::{fit_thermal, FitOutcome};
use gyro_lab_core::data::source::Source;
use gyro_lab_core::error::LabError;
use std::path::PathBuf;

#[derive(Args, Debug, Clone)]
#[command(mut_arg("out", |a| a.help("A file: the coefficient set (TOML, what the firmware loads); its report is written beside it (.html)")))]
pub struct FitThermalArgs {
    /// Chamber run file (t_s, ref_rate_dps, rate_dps, t_mono_a_c, t_mono_b_c, t_case_c).
    #[arg(long)]
    pub data: PathBuf,
    #[command(flatten)]
    pub read: RunRead,
    #[command(flatten)]
    pub out: Out,
    #[command(flatten)]
    pub no_report: NoReport,
    #[command(flatten)]
    pub json: Json,
}

/// `--out` for a fit: a TOML file of `kind`, its report beside it.
fn check_out(
    command: &str,
    out: &Out,
    kind: &'static str,
    data: &std::path::Path,
    report: bool,
) -> Result<(), LabError> {
    let beside: Vec<_> = match report {
        true => vec![(out_path::report_beside(&out.out), FileKind::Html)],
        false => vec![],
    };
    out_path::file(
        command,
        &out.out,
        FileKind::Toml(kind),
        &beside,
        &[("--data", data)],
        out.force,
    )
}

/// Writes the coefficient file and the report; prints the JSON (with the
/// paths) or the text.
fn emit(o: &FitOutcome, out: &Out, json: bool) -> Result<(), LabError> {
    gyro_lab_core::data::atomic::write(&out.out, &o.coeffs_toml)?;
    let report = o
        .report
        .as_ref()
        .map(|r| (r, out_path::report_beside(&out.out)));
    if let Some((r, p)) = &report {
        write_report(r, p)?;
    }
    let report = report.map(|(_, p)| p.display().to_string());
    if json {
        let mut j = o.json.clone();
        j["out"] = out.out.display().to_string().into();
        j["report"] = report.into();
        println!("{j}");
        return Ok(());
    }
    for l in &o.text {
        println!("{l}");
    }
    println!(
        "written: {} (record CRC {})",
        out.out.display(),
        o.record_crc32
    );
    if let Some(p) = report {
        println!("report: {p}");
    }
    Ok(())
}

pub fn thermal(a: &FitThermalArgs) -> Result<(), LabError> {
    let spec = a.read.spec()?;
    check_out(
        "fit thermal",
        &a.out,
        "rlg_thermal",
        &a.data,
        !a.no_report.no_report,
    )?;
    let o = fit_thermal(Source::File(&a.data), &spec, !a.no_report.no_report)?;
    emit(&o, &a.out, a.json.json)
}

#[derive(Args, Debug, Clone)]
#[command(mut_arg("out", |a| a.help("A file: the coefficient set (TOML, what the firmware loads); its report is written beside it (.html)")))]
pub struct FitScaleFactorArgs {
    /// Run file: continuous-rotation or multi-point (t_s, ref_rate_dps, rate_dps, temp_c).
    #[arg(long)]
    pub data: PathBuf,
    #[command(flatten)]
    pub read: RunRead,
    #[command(flatten)]
    pub out: Out,
    #[command(flatten)]
    pub no_report: NoReport,
    #[command(flatten)]
    pub json: Json,
}

pub fn scale_factor(a: &FitScaleFactorArgs) -> Result<(), LabError> {
    let spec = a.read.spec()?;
    check_out(
        "fit scale-factor",
        &a.out,
        "fog_scale_factor",
        &a.data,
        !a.no_report.no_report,
    )?;
    let o = fit_scale_factor(Source::File(&a.data), &spec, !a.no_report.no_report)?;
    emit(&o, &a.out, a.json.json)
}
