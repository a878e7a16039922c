//! Arguments several commands share, declared once and flattened into each
//! command's own (`#[command(flatten)]`). Where a command says more about
//! one in its help, it overrides the help text (`mut_arg`).

use clap::Args;
use std::path::PathBuf;

/// `--json`: the last line of stdout is one JSON object.
#[derive(Args, Debug, Clone, Copy)]
pub struct Json {
    #[arg(long)]
    pub json: bool,
}

/// `--seed`: the seed of a simulation's noise.
#[derive(Args, Debug, Clone, Copy)]
pub struct Seed {
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
}

/// `--out`: the file or directory a command writes.
#[derive(Args, Debug, Clone)]
pub struct Out {
    #[arg(long)]
    pub out: PathBuf,
}

/// `--out` where writing is optional.
#[derive(Args, Debug, Clone)]
pub struct OutOpt {
    #[arg(long)]
    pub out: Option<PathBuf>,
}
