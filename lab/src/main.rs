//! `gyro-lab`: host tool of the gyro signal processor (see docs in README.md).
//! Every subcommand takes `--json`; bad input exits with status 2 and a one-line
//! error naming the file, line and column. The commands are gyro_lab::cli's.

use clap::Parser;
use gyro_lab::cli::{self, Cli};
use std::process::ExitCode;

fn main() -> ExitCode {
    // Output piped into `head` and closed early: end quietly as other Unix
    // tools do, not with a panic on the broken pipe.
    #[cfg(unix)]
    // SAFETY: restoring the default disposition of one signal at start,
    // before any thread exists.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
    // A day-long record's columns are megabytes each, made and dropped
    // over and over: glibc would map and unmap every one (a page fault per
    // 4 KB each time). Kept in the heap instead, they are reused.
    #[cfg(all(target_os = "linux", target_env = "gnu"))]
    // SAFETY: malloc parameters set once at start, before any thread.
    unsafe {
        libc::mallopt(libc::M_MMAP_THRESHOLD, 256 << 20);
        libc::mallopt(libc::M_TRIM_THRESHOLD, 512 << 20);
    }
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
            eprintln!("gyro-lab: {e}");
            ExitCode::from(e.exit_code())
        }
    }
}
