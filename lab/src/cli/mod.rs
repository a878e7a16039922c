//! The command line: one file per command family. Each owns its
//! arguments, checks its output paths, reads and writes the files, prints
//! the text or the JSON and writes the reports; what a command finds, and
//! its words, are gyro_lab_core's (commands/), which Python calls too.

pub mod allan;
pub mod args;
pub mod bench;
pub mod bench_dither;
pub mod bench_eps2;
pub mod bench_record;
pub mod compensate;
pub mod discover;
pub mod fit;
pub mod lockin;
pub mod out_path;
pub mod output;
pub mod record;
pub mod simulate;

use clap::{Parser, Subcommand};
use gyro_lab_core::error::LabError;

#[derive(Parser)]
#[command(
    name = "gyro-lab",
    version,
    allow_negative_numbers = true,
    about = "Simulation and calibration for the FOG/RLG signal processor"
)]
pub struct Cli {
    #[command(subcommand)]
    pub cmd: Cmd,
}

#[derive(Subcommand)]
pub enum Cmd {
    /// Run the firmware's core against a simulated gyro.
    #[command(subcommand)]
    Simulate(simulate::SimulateCmd),
    /// RLG lock-in rate from a fringe record (exact harmonic relation).
    Lockin(lockin::LockinArgs),
    /// Calibration fits on test-rig runs.
    #[command(subcommand)]
    Fit(FitCmd),
    /// Noise analysis: overlapping Allan deviation, IEEE 952 terms with intervals.
    Allan(allan::AllanArgs),
    /// Compare a model with measured data: name the missing effect, add it, show the gap shrink.
    Discover(discover::DiscoverArgs),
    /// Apply a coefficient file as the firmware does; adds `rate_comp_dps`.
    Compensate(compensate::CompensateArgs),
    /// The board's frames from a serial port (or a raw capture) into run files.
    Record(record::RecordArgs),
    /// Benchmarks of the estimators on simulated records.
    #[command(subcommand)]
    Bench(bench::BenchCmd),
}

#[derive(Subcommand)]
pub enum FitCmd {
    /// RLG thermal bias model (two monoblock sensors, case sensor, gradient, warm-up).
    Thermal(fit::FitThermalArgs),
    /// FOG scale factor over temperature (knees by BIC) from a continuous-rotation or multi-point run.
    ScaleFactor(fit::FitScaleFactorArgs),
}

/// Runs the command given.
pub fn run(cli: &Cli) -> Result<(), LabError> {
    match &cli.cmd {
        Cmd::Simulate(c) => simulate::run(c),
        Cmd::Lockin(a) => lockin::run(a),
        Cmd::Fit(FitCmd::Thermal(a)) => fit::thermal(a),
        Cmd::Fit(FitCmd::ScaleFactor(a)) => fit::scale_factor(a),
        Cmd::Compensate(a) => compensate::run(a),
        Cmd::Allan(a) => allan::run(a),
        Cmd::Discover(a) => discover::run(a),
        Cmd::Record(a) => record::run(a),
        Cmd::Bench(c) => bench::run(c),
    }
}

#[cfg(test)]
mod tests {
    use super::Cli;
    use clap::CommandFactory;

    /// Every option of every command says what it is in `--help`.
    #[test]
    fn every_option_has_help() {
        fn walk(cmd: &clap::Command, path: &str, blank: &mut Vec<String>) {
            for a in cmd.get_arguments() {
                let id = a.get_id().as_str();
                if id == "help" || id == "version" {
                    continue;
                }
                if a.get_help().is_none() && a.get_long_help().is_none() {
                    blank.push(format!("{path} --{id}"));
                }
            }
            for s in cmd.get_subcommands() {
                walk(s, &format!("{path} {}", s.get_name()), blank);
            }
        }
        let mut blank = vec![];
        walk(&Cli::command(), "gyro-lab", &mut blank);
        assert!(blank.is_empty(), "options without help: {blank:#?}");
    }
}
