//! `gyro-lab simulate run`: a gyro model on a test profile with the
//! project's noise (sim/model_run.rs), written as a run file: a run with
//! known effects.

use crate::cli::args::{Json, Out, Seed};
use clap::{Args, ValueEnum};
use gyro_lab_core::commands::model_file::read_model_file;
use gyro_lab_core::commands::simulate_run::{columns, simulate_run, SimulateRequest};
use gyro_lab_core::data::csv_writer::CellFormat::{Exp, Fixed, Shortest};
use gyro_lab_core::data::run_file::{Column, RunWriter};
use gyro_lab_core::error::LabError;
use gyro_lab_core::sim::model_run::{TestProfile, TrialRun};
use std::path::PathBuf;

/// Test profiles, as the command line names them.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum TestProfileArg {
    /// Rate table: 0, +-10, +-50, +-100, +-200 deg/s in a shuffled order,
    /// 60 s each, while the chamber sweeps -20 -> +60 -> -20 degC (the coil
    /// 600 s behind the air); 1 s rows, 2 h.
    Table,
    /// The same table at one constant rate (+50 deg/s) and constant
    /// temperature: a scale-factor error and a bias look alike there.
    ConstantRate,
    /// RLG at rest in a thermal chamber (gyro_sp's chamber: case and two
    /// monoblock sensors with their lags and self-heating), the cycle
    /// -40 -> +50 degC; 1 s rows, 6 h.
    Chamber,
    /// RLG rate steps near lock-in: +-0.03 .. +-3 deg/s log-spaced, 20 s
    /// each; 10 Hz rows, 30 min.
    Lockin,
    /// FOG at rest under 20 Hz sinusoidal vibration switched between
    /// amplitudes (0, 2 000, 5 000, 10 000 deg/s^2 peak), 30 s each, with
    /// `ref_acc_dps2`; 200 Hz rows, 10 min.
    Vibration,
    /// FOG under one constant vibration level: rectification looks like a
    /// bias.
    ConstantVibration,
    /// FOG at rest in a chamber: 20 -> +50 -> -10 -> 20 degC at 1 degC/min
    /// with 30 min soaks (coil 600 s behind the air); 1 s rows, 3.7 h.
    FogChamber,
}

impl From<TestProfileArg> for TestProfile {
    fn from(p: TestProfileArg) -> Self {
        match p {
            TestProfileArg::Table => TestProfile::Table,
            TestProfileArg::ConstantRate => TestProfile::ConstantRate,
            TestProfileArg::Chamber => TestProfile::Chamber,
            TestProfileArg::Lockin => TestProfile::Lockin,
            TestProfileArg::Vibration => TestProfile::Vibration,
            TestProfileArg::ConstantVibration => TestProfile::ConstantVibration,
            TestProfileArg::FogChamber => TestProfile::FogChamber,
        }
    }
}

/// Writes a run file: the required columns, then those the profile has.
pub fn write(run: &TrialRun, path: &std::path::Path, comment: &str) -> Result<(), LabError> {
    let cols = columns(run);
    let format = |c: Column| match c {
        Column::Time => Shortest,
        Column::RefRate => Fixed(9),
        Column::Rate => Exp(12),
        Column::RefAcc => Fixed(6),
        _ => Fixed(4),
    };
    let spec: Vec<(Column, _)> = cols.iter().map(|(c, _)| (*c, format(*c))).collect();
    let mut w = RunWriter::create(path, comment, &spec)?;
    let mut row = Vec::with_capacity(cols.len());
    for k in 0..run.inputs.len() {
        row.clear();
        row.extend(cols.iter().map(|(_, v)| v[k]));
        w.row(&row)?;
    }
    w.finish()
}

#[derive(Args, Debug, Clone)]
#[command(mut_arg("out", |a| a.help("A file: the run file to write (CSV)")))]
pub struct SimulateRunArgs {
    /// The truth: a model file (its gyro kind must match the profile's).
    #[arg(long)]
    pub model: PathBuf,
    /// The test profile the model is run on (each sets the gyro kind, the row period and
    /// the length).
    #[arg(long, value_enum)]
    pub profile: TestProfileArg,
    /// Row period, s (default: the profile's).
    #[arg(long)]
    pub dt_s: Option<f64>,
    /// Record length, s (default: the profile's).
    #[arg(long)]
    pub duration_s: Option<f64>,
    /// Angle random walk, deg/sqrt(h) (default: a navigation-grade gyro of
    /// the profile's kind).
    #[arg(long)]
    pub arw_dpsh: Option<f64>,
    /// Bias instability, deg/h (default: a navigation-grade gyro of the profile's kind).
    #[arg(long)]
    pub bias_instability_dph: Option<f64>,
    /// Rate random walk, deg/h/sqrt(h) (default none).
    #[arg(long)]
    pub rate_random_walk_dphsh: Option<f64>,
    #[command(flatten)]
    pub seed: Seed,
    #[command(flatten)]
    pub out: Out,
    #[command(flatten)]
    pub json: Json,
}

pub fn run(a: &SimulateRunArgs) -> Result<(), LabError> {
    let profile = TestProfile::from(a.profile);
    let file = read_model_file(&a.model, profile.gyro())?;
    let (run, noise) = simulate_run(&SimulateRequest {
        model: &file,
        profile,
        dt_s: a.dt_s,
        duration_s: a.duration_s,
        arw_dpsh: a.arw_dpsh,
        bias_instability_dph: a.bias_instability_dph,
        rate_random_walk_dphsh: a.rate_random_walk_dphsh,
        seed: a.seed.seed,
    })
    .map_err(|e| match e {
        LabError::Usage(_) => {
            let (dt0, dur0) = profile.default_timing();
            LabError::Usage(format!(
                "--dt-s {} --duration-s {}: out of range",
                a.dt_s.unwrap_or(dt0),
                a.duration_s.unwrap_or(dur0)
            ))
        }
        e => e,
    })?;
    write(
        &run,
        &a.out.out,
        &format!(
            "gyro-lab simulate run: profile {:?}, model {}, seed {}, ARW {} deg/sqrt(h), bias instability {} deg/h, rate random walk {} deg/h/sqrt(h)",
            a.profile,
            a.model.display(),
            a.seed.seed,
            noise.arw_dpsh,
            noise.bias_instability_dph,
            noise.rate_random_walk_dphsh
        ),
    )?;
    let j = serde_json::json!({"rows": run.inputs.len(), "out": a.out.out});
    if a.json.json {
        println!("{j}");
    } else {
        println!("{} rows -> {}", run.inputs.len(), a.out.out.display());
    }
    Ok(())
}
