//! `gyro-instruments`: the project's generators and held-out benches (see
//! the README's benchmark section). Errors exit 2 with gyro-lab's message.

use clap::Parser;
use gyro_instruments::cli::{self, Cli};
use std::process::ExitCode;

fn main() -> ExitCode {
    let args = match Cli::try_parse() {
        Ok(c) => c,
        Err(e) => {
            let code = if e.use_stderr() { 2 } else { 0 };
            let _ = e.print();
            return ExitCode::from(code);
        }
    };
    match cli::run(&args) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("gyro-instruments: {e}");
            ExitCode::from(e.exit_code())
        }
    }
}
