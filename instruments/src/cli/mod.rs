//! `gyro-instruments`: the instruments' command line.

pub mod bench_heldout;
pub mod bench_outside;
pub mod heldout;
pub mod outside;

use clap::{Parser, Subcommand};
use gyro_lab_core::error::LabError;

#[derive(Parser)]
#[command(
    name = "gyro-instruments",
    version,
    about = "The project's verification instruments for gyro-lab: independent generators and the held-out benches"
)]
pub struct Cli {
    #[command(subcommand)]
    pub cmd: Cmd,
}

#[derive(Subcommand)]
pub enum Cmd {
    /// Write an independent generator's records.
    #[command(subcommand)]
    Simulate(SimulateCmd),
    /// Score discovery on them.
    #[command(subcommand)]
    Bench(BenchCmd),
}

#[derive(Subcommand)]
pub enum SimulateCmd {
    /// The second (or third), independent generator's held-out set for discovery (runs and truth.json).
    Heldout(heldout::HeldOutArgs),
    /// The outside generator's cases for discovery beyond the library: two runs of one gyro per case, their hidden terms and truth.json.
    Outside(outside::OutsideArgs),
}

#[derive(Subcommand)]
pub enum BenchCmd {
    /// Discovery on the held-out set (`simulate heldout`): right, false names, coverage.
    DiscoverHeldout(bench_heldout::HeldOutBenchArgs),
    /// Discovery beyond the library on the outside generator's cases (`simulate outside`): terms explained, run B predicted, nulls clean, library names kept.
    DiscoverOutside(bench_outside::OutsideBenchArgs),
}

/// Runs the command given.
pub fn run(cli: &Cli) -> Result<(), LabError> {
    match &cli.cmd {
        Cmd::Simulate(SimulateCmd::Heldout(a)) => heldout::run(a),
        Cmd::Simulate(SimulateCmd::Outside(a)) => outside::run(a),
        Cmd::Bench(BenchCmd::DiscoverHeldout(a)) => bench_heldout::discover_heldout(a),
        Cmd::Bench(BenchCmd::DiscoverOutside(a)) => bench_outside::run_bench(a),
    }
}
