//! `gyro-lab simulate`: the simulators' records as files, one command per
//! simulator.

pub mod chamber;
pub mod dither;
pub mod fog;
pub mod lockin;
pub mod run;
pub mod scale_factor;

use crate::cli::out_path::{self, FileKind};
use clap::Subcommand;
use gyro_lab_core::error::LabError;
use std::path::Path;

#[derive(Subcommand)]
pub enum SimulateCmd {
    /// Closed-loop fiber-optic gyro.
    Fog(fog::FogArgs),
    /// RLG fringe signal near lock-in (writes a fringe file).
    Lockin(lockin::LockinSimArgs),
    /// RLG in a thermal chamber (writes a run file).
    Chamber(chamber::ChamberArgs),
    /// Mechanically dithered RLG, counted and dither-stripped by the firmware's RLG core.
    Dither(dither::DitherArgs),
    /// FOG scale-factor calibration run over temperature (continuous rotation or multi-point; writes a run file).
    ScaleFactor(scale_factor::SimulateArgs),
    /// A gyro model (model.toml) on a test profile with the project's noise: a run with known effects.
    Run(run::SimulateRunArgs),
}

/// The run file a simulation writes: refused where it names the model
/// read, exists without `--force`, or is not a CSV's name.
fn check_out(
    command: &str,
    out: Option<&Path>,
    force: bool,
    inputs: &[(&str, &Path)],
) -> Result<(), LabError> {
    match out {
        Some(o) => out_path::file(command, o, FileKind::Csv, &[], inputs, force),
        None => Ok(()),
    }
}

pub fn run(cmd: &SimulateCmd) -> Result<(), LabError> {
    match cmd {
        SimulateCmd::Fog(a) => check_out("simulate fog", a.out.out.as_deref(), a.out.force, &[])?,
        SimulateCmd::Lockin(a) => check_out("simulate lockin", Some(&a.out.out), a.out.force, &[])?,
        SimulateCmd::Chamber(a) => {
            check_out("simulate chamber", Some(&a.out.out), a.out.force, &[])?
        }
        SimulateCmd::Dither(a) => {
            check_out("simulate dither", a.out.out.as_deref(), a.out.force, &[])?
        }
        SimulateCmd::ScaleFactor(a) => {
            check_out("simulate scale-factor", Some(&a.out.out), a.out.force, &[])?
        }
        SimulateCmd::Run(a) => check_out(
            "simulate run",
            Some(&a.out.out),
            a.out.force,
            &[("--model", &a.model)],
        )?,
    }
    match cmd {
        SimulateCmd::Fog(a) => fog::run(a),
        SimulateCmd::Lockin(a) => lockin::run(a),
        SimulateCmd::Chamber(a) => chamber::run(a),
        SimulateCmd::Dither(a) => dither::run(a),
        SimulateCmd::ScaleFactor(a) => scale_factor::run(a),
        SimulateCmd::Run(a) => run::run(a),
    }
}
