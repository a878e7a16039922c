//! Arguments several commands share, declared once and flattened into each
//! command's own (`#[command(flatten)]`). Where a command says more about
//! one in its help, it overrides the help text (`mut_arg`).

use clap::Args;
use std::path::PathBuf;

/// `--json`: the last line of stdout is one JSON object.
#[derive(Args, Debug, Clone, Copy)]
pub struct Json {
    /// Print the result as one JSON object, the last line of stdout.
    #[arg(long)]
    pub json: bool,
}

/// `--seed`: the seed of a simulation's noise.
#[derive(Args, Debug, Clone, Copy)]
pub struct Seed {
    /// Seed of the simulation's noise: the same seed gives the same run.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
}

/// `--out`: the file or directory a command writes.
#[derive(Args, Debug, Clone)]
pub struct Out {
    /// The file (or directory) to write.
    #[arg(long)]
    pub out: PathBuf,
}

/// `--out` where writing is optional.
#[derive(Args, Debug, Clone)]
pub struct OutOpt {
    /// The directory to write the command's files in (nothing written
    /// without it).
    #[arg(long)]
    pub out: Option<PathBuf>,
}

/// `--no-report`: skip the report a command writes beside its output
/// (for scripted loops; the JSON and the other files are unchanged).
#[derive(Args, Debug, Clone, Copy)]
pub struct NoReport {
    /// Skip the HTML report written beside the output (the JSON and the
    /// other files are unchanged).
    #[arg(long)]
    pub no_report: bool,
}
