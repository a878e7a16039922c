//! Arguments several commands share, declared once and flattened into each
//! command's own (`#[command(flatten)]`). Where a command says more about
//! one in its help, it overrides the help text (`mut_arg`).

use clap::Args;
use gyro_lab_core::data::read_spec::ReadSpec;
use gyro_lab_core::data::units::{RateUnit, TempUnit, TimeUnit};
use gyro_lab_core::error::LabError;
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

/// `--out`: the file or folder a command writes (each command's help
/// says which), and `--force` to replace what is there.
#[derive(Args, Debug, Clone)]
pub struct Out {
    /// The file (or folder) to write.
    #[arg(long)]
    pub out: PathBuf,
    /// Replace existing output files (never an input, never a file of
    /// another kind).
    #[arg(long)]
    pub force: bool,
}

/// `--out` where writing is optional.
#[derive(Args, Debug, Clone)]
pub struct OutOpt {
    /// The folder to write the command's files in (nothing written
    /// without it).
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Replace existing output files (never an input, never a file of
    /// another kind).
    #[arg(long)]
    pub force: bool,
}

/// `--columns ours=theirs,...` as given.
#[derive(Clone, Debug, Default)]
pub struct ColumnMap(pub Vec<(String, String)>);

impl std::str::FromStr for ColumnMap {
    type Err = gyro_lab_core::error::LabError;
    fn from_str(s: &str) -> Result<Self, gyro_lab_core::error::LabError> {
        ReadSpec::parse_rename(s).map(ColumnMap)
    }
}

/// How to read the user's run file: their column names, units and the
/// stretch to take (docs/interfaces.md).
#[derive(Args, Debug, Clone, Default)]
pub struct RunRead {
    /// Map the file's column names onto the run file's, ours=theirs:
    /// `--columns rate_dps=gyro_z,t_s=time,temp_c=temp`.
    #[arg(long, value_name = "OURS=THEIRS,...")]
    pub columns: Option<ColumnMap>,
    /// The unit of the file's rate columns: deg/s (default), rad/s or deg/h.
    #[arg(long, value_name = "UNIT")]
    pub rate_unit: Option<RateUnit>,
    /// The unit of the reference rate column where it differs from the
    /// rate's (a table's log in deg/s beside a gyro's in rad/s).
    #[arg(long, value_name = "UNIT")]
    pub ref_rate_unit: Option<RateUnit>,
    /// The unit of the file's temperature columns: C (default), K or F.
    #[arg(long, value_name = "UNIT")]
    pub temp_unit: Option<TempUnit>,
    /// The unit of the file's time column: s (default), ms or us (clock
    /// timestamps such as `2026-03-01 14:02:07.125` are read as they are).
    #[arg(long, value_name = "UNIT")]
    pub time_unit: Option<TimeUnit>,
    /// Analyse the record from this time on, s (on the file's time scale;
    /// since the first row for clock timestamps).
    #[arg(long, value_name = "S")]
    pub from_s: Option<f64>,
    /// Analyse the record up to this time, s.
    #[arg(long, value_name = "S")]
    pub to_s: Option<f64>,
}

impl RunRead {
    /// The spec the readers take, the stretch checked.
    pub fn spec(&self) -> Result<ReadSpec, LabError> {
        let spec = ReadSpec {
            rename: self.columns.clone().map(|c| c.0).unwrap_or_default(),
            rate_unit: self.rate_unit,
            ref_rate_unit: self.ref_rate_unit,
            temp_unit: self.temp_unit,
            time_unit: self.time_unit,
            from_s: self.from_s,
            to_s: self.to_s,
        };
        spec.check_stretch(["--from-s", "--to-s"])?;
        Ok(spec)
    }
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
