//! `gyro-lab`: host tool of the gyro signal processor (see docs in README.md).
//! Every subcommand takes `--json`; bad input exits with status 2 and a one-line
//! error naming the file, line and column.

mod error;
mod simulate;

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
}

fn main() -> ExitCode {
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
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("gyro-lab: {e}");
            ExitCode::from(e.exit_code())
        }
    }
}
