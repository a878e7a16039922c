//! `simulate run`: a gyro model on a test profile with the project's noise
//! (sim/model_run.rs): a run with known effects, as the run file's
//! columns.

use crate::commands::model_file::ModelFile;
use crate::data::run_file::Column;
use crate::error::LabError;
use crate::sim::model_run::{generate, TestProfile, TrialNoise, TrialRun};

/// The profiles by the names the CLI and Python give them.
pub const PROFILES: [(&str, TestProfile); 7] = [
    ("table", TestProfile::Table),
    ("constant-rate", TestProfile::ConstantRate),
    ("chamber", TestProfile::Chamber),
    ("lockin", TestProfile::Lockin),
    ("vibration", TestProfile::Vibration),
    ("constant-vibration", TestProfile::ConstantVibration),
    ("fog-chamber", TestProfile::FogChamber),
];

/// A profile by its name (`fog-chamber`, or `fog_chamber`).
pub fn profile(name: &str) -> Result<TestProfile, LabError> {
    let n = name.replace('_', "-");
    PROFILES
        .iter()
        .find(|p| p.0 == n)
        .map(|p| p.1)
        .ok_or_else(|| {
            let names: Vec<&str> = PROFILES.iter().map(|p| p.0).collect();
            LabError::Usage(format!("profile `{name}`: not one of {}", names.join(", ")))
        })
}

/// What `simulate run` is asked: the model, the profile, the timing
/// (the profile's where not given), the noise (a navigation-grade gyro
/// of the profile's kind where not given) and the seed.
pub struct SimulateRequest<'a> {
    pub model: &'a ModelFile,
    pub profile: TestProfile,
    pub dt_s: Option<f64>,
    pub duration_s: Option<f64>,
    pub arw_dpsh: Option<f64>,
    pub bias_instability_dph: Option<f64>,
    pub rate_random_walk_dphsh: Option<f64>,
    pub seed: u64,
}

/// The run simulated, and the noise it was made with.
pub fn simulate_run(req: &SimulateRequest) -> Result<(TrialRun, TrialNoise), LabError> {
    let (dt0, dur0) = req.profile.default_timing();
    let dt = req.dt_s.unwrap_or(dt0);
    let dur = req.duration_s.unwrap_or(dur0);
    if !(dt.is_finite() && dt > 0.0 && dur.is_finite() && dur >= 10.0 * dt && dur / dt <= 2e7) {
        return Err(LabError::Usage(format!(
            "row period {dt} s, duration {dur} s: out of range (at least 10 rows, at most 2e7)"
        )));
    }
    let nom = TrialNoise::nominal(req.profile.gyro());
    let noise = TrialNoise {
        arw_dpsh: req.arw_dpsh.unwrap_or(nom.arw_dpsh).max(0.0),
        bias_instability_dph: req
            .bias_instability_dph
            .unwrap_or(nom.bias_instability_dph)
            .max(0.0),
        rate_random_walk_dphsh: req
            .rate_random_walk_dphsh
            .unwrap_or(nom.rate_random_walk_dphsh)
            .max(0.0),
    };
    let run = generate(
        &req.model.model,
        req.profile,
        noise,
        req.seed,
        Some((dt, dur)),
    );
    // A term must be computable on the profile's inputs: refused at its
    // place (its rows would be NaN).
    req.model.check_terms(&run.inputs)?;
    Ok((run, noise))
}

/// The run's columns as a run file has them: the required ones, then
/// those the profile has.
pub fn columns(run: &TrialRun) -> Vec<(Column, &[f64])> {
    let inp = &run.inputs;
    let mut cols: Vec<(Column, &[f64])> = vec![
        (Column::Time, &inp.t),
        (Column::RefRate, &inp.w),
        (Column::Rate, &run.rate),
    ];
    if let Some(t) = &inp.temp {
        cols.push((Column::Temp, t));
    }
    if let Some((a, b)) = &run.mono {
        cols.extend([(Column::MonoA, &a[..]), (Column::MonoB, &b[..])]);
    }
    if let Some(c) = &run.case {
        cols.push((Column::Case, c));
    }
    if run.acc_column {
        cols.push((Column::RefAcc, &inp.acc));
    }
    cols
}
