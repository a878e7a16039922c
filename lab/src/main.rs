//! `gyro-lab`: host tool of the gyro signal processor (see docs in README.md).
//! Every subcommand takes `--json`; bad input exits with status 2 and a one-line
//! error naming the file, line and column.

use gyro_lab::error::LabError;
use gyro_lab::{allan, discover, lockin, scale_factor, simulate, thermal};

use clap::{Parser, Subcommand};
use std::process::ExitCode;

#[derive(Parser)]
#[command(
    name = "gyro-lab",
    version,
    allow_negative_numbers = true,
    about = "Simulation and calibration for the FOG/RLG signal processor"
)]
struct Cli {
    #[command(subcommand)]
    cmd: Cmd,
}

#[derive(Subcommand)]
enum Cmd {
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
    Compensate(thermal::CompensateArgs),
    /// Benchmarks of the estimators on simulated records.
    #[command(subcommand)]
    Bench(BenchCmd),
}

#[derive(Subcommand)]
enum FitCmd {
    /// RLG thermal bias model (two monoblock sensors, case sensor, gradient, warm-up).
    Thermal(thermal::FitThermalArgs),
    /// FOG scale factor over temperature (knees by BIC) from a continuous-rotation or multi-point run.
    ScaleFactor(scale_factor::FitArgs),
}

#[derive(Subcommand)]
enum BenchCmd {
    /// Lock-in: exact harmonic relation next to the published approximate formula.
    Lockin(lockin::LockinBenchArgs),
    /// FOG scale factor: raw, classic multi-point and continuous rotation on one simulated gyro.
    ScaleFactor(scale_factor::bench::BenchArgs),
    /// Allan terms recovered from the project's noise generators, over seeds.
    Allan(allan::bench::AllanBenchArgs),
    /// Allan analysis time on 10^7 samples against the O(N m) definition.
    AllanSpeed(allan::bench::SpeedArgs),
    /// Discovery on randomized runs with hidden effects: the confusion table.
    Discover(discover::bench::DiscoverBenchArgs),
}

fn main() -> ExitCode {
    // Output piped into `head` and closed early: end quietly as other Unix
    // tools do, not with a panic on the broken pipe.
    #[cfg(unix)]
    // SAFETY: restoring the default disposition of one signal at start,
    // before any thread exists.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
    let cli = match Cli::try_parse() {
        Ok(c) => c,
        Err(e) => {
            let code = if e.use_stderr() { 2 } else { 0 };
            let _ = e.print();
            return ExitCode::from(code);
        }
    };
    let result = match cli.cmd {
        Cmd::Simulate(c) => simulate::run(c),
        Cmd::Lockin(a) => lockin::run(&a),
        Cmd::Fit(FitCmd::Thermal(a)) => thermal::fit_run(&a),
        Cmd::Fit(FitCmd::ScaleFactor(a)) => scale_factor::fit_run(&a),
        Cmd::Compensate(a) => thermal::compensate_run(&a),
        Cmd::Allan(a) => allan::run(&a),
        Cmd::Discover(a) => discover::run(&a),
        Cmd::Bench(BenchCmd::Lockin(a)) => lockin::bench_run(&a),
        Cmd::Bench(BenchCmd::ScaleFactor(a)) => scale_factor::bench::run(&a),
        Cmd::Bench(BenchCmd::Allan(a)) => allan::bench::run(&a),
        Cmd::Bench(BenchCmd::AllanSpeed(a)) => allan::bench::speed(&a),
        Cmd::Bench(BenchCmd::Discover(a)) => discover::bench::run(&a),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            let e: LabError = e;
            eprintln!("gyro-lab: {e}");
            ExitCode::from(e.exit_code())
        }
    }
}
