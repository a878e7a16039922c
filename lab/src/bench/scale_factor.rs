//! `gyro-lab bench scale-factor`: the three calibrations side by side on the
//! same simulated gyro, over seeds, against the truth.
//!
//! Per seed: a continuous-rotation fit run (cycle -40..+60 degC and back,
//! +-50 deg/s reversed every 5 min), a classic multi-point run (plateaus
//! -40, -15, 10, 35, 60 degC: the knee at 48 degC falls between the last
//! two) and a validation run of another profile, rate and direction (steps,
//! -100 deg/s only). Both tables compensate the validation run through the
//! firmware's fixed-point code; the figure is the RMS of the scale-factor
//! error over 60 s means. A no-knee gyro's fit run checks that no knee is
//! invented.

use crate::calibration::scale_factor::compensation::compensate_rows;
use crate::calibration::scale_factor::fit::fit;
use crate::calibration::scale_factor::input::{prepare, SfInput};
use crate::calibration::scale_factor::residual::{window_rms_ppm, RESIDUAL_WINDOW_S};
use crate::calibration::scale_factor::result::SfFitError;
use crate::sim::scale_factor_rig::{simulate, Direction, RigParams, Run, SweepProfile, Test};

/// The bench's runs that are fitted.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BenchRun {
    Continuous,
    MultiPoint,
    NoKnee,
}

/// A fit that failed on the bench's own simulated run.
#[derive(Debug)]
pub struct BenchFitError {
    pub run: BenchRun,
    pub error: SfFitError,
}

impl std::fmt::Display for BenchFitError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let run = match self.run {
            BenchRun::Continuous => "continuous fit",
            BenchRun::MultiPoint => "multi-point fit",
            BenchRun::NoKnee => "no-knee fit",
        };
        write!(f, "{run}: {}", self.error)
    }
}

fn input(run: &Run) -> SfInput {
    prepare(&run.t_s, &run.ref_rate_dps, &run.rate_dps, &run.temp_c)
}

pub fn continuous_fit_test() -> Test {
    Test::Continuous {
        profile: SweepProfile::Cycle,
        rate_dps: 50.0,
        direction: Direction::Both,
        reverse_every_s: 300.0,
    }
}

pub fn validation_test() -> Test {
    Test::Continuous {
        profile: SweepProfile::Steps,
        rate_dps: 100.0,
        direction: Direction::Negative,
        reverse_every_s: 300.0,
    }
}

pub fn multipoint_test() -> Test {
    Test::MultiPoint {
        plateaus_c: vec![-40.0, -15.0, 10.0, 35.0, 60.0],
        rates_dps: vec![10.0, 20.0, 50.0, 100.0, 200.0],
        soak_s: 3600.0,
        dwell_s: 60.0,
    }
}

/// Count, mean, standard deviation and largest of a figure over seeds.
#[derive(Default, serde::Serialize)]
pub struct Stats {
    pub n: usize,
    pub mean: f64,
    pub sd: f64,
    pub max: f64,
}

fn stats(v: &[f64]) -> Stats {
    let n = v.len();
    if n == 0 {
        return Stats::default();
    }
    let mean = v.iter().sum::<f64>() / n as f64;
    let sd = (v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n.max(2) - 1) as f64).sqrt();
    Stats {
        n,
        mean,
        sd,
        max: v.iter().fold(f64::NEG_INFINITY, |a, x| a.max(*x)),
    }
}

/// The bench's figures (its JSON, in this order).
#[derive(serde::Serialize)]
pub struct ScaleFactorBench {
    pub seeds: u64,
    pub knee_true_c: f64,
    /// Continuous fit: seeds with exactly one knee found, |knee error|, and
    /// seeds whose 95 % interval covers the truth.
    pub continuous_one_knee: usize,
    pub continuous_knee_abs_err_c: Stats,
    pub continuous_knee_ci_width_c: Stats,
    pub continuous_ci_covers: usize,
    pub sensor_lag_s: Stats,
    pub sensor_lag_ci_covers: usize,
    /// Validation RMS of 60 s means, ppm.
    pub validation_raw_ppm: Stats,
    pub validation_multipoint_ppm: Stats,
    pub validation_continuous_ppm: Stats,
    pub multipoint_knee_bracketed: usize,
    pub no_knee_fitted_without_knee: usize,
}

/// Runs the bench over seeds 1..=`seeds`; `progress` after each seed.
pub fn run(seeds: u64, mut progress: impl FnMut()) -> Result<ScaleFactorBench, BenchFitError> {
    let base = RigParams::default();
    let knee_true = base.truth.knees[0].0;
    let fail = |run: BenchRun, error: SfFitError| BenchFitError { run, error };
    let (mut knee_err, mut knee_w, mut lag) = (vec![], vec![], vec![]);
    let (mut one_knee, mut covers, mut lag_covers, mut bracketed, mut no_knee_ok) = (0, 0, 0, 0, 0);
    let (mut raw, mut mp, mut cont) = (vec![], vec![], vec![]);
    for seed in 1..=seeds {
        let rig = |s: u64| RigParams { seed: s, ..base };
        let fit_run = simulate(&continuous_fit_test(), &rig(seed));
        let (cf, _) = fit(&input(&fit_run)).map_err(|e| fail(BenchRun::Continuous, e))?;
        if cf.knees.len() == 1 {
            one_knee += 1;
            let k = cf.knees[0];
            knee_err.push((k.value - knee_true).abs());
            knee_w.push(k.hi - k.lo);
            if k.lo <= knee_true && knee_true <= k.hi {
                covers += 1;
            }
        }
        if let Some(l) = cf.sensor_lag_s {
            lag.push(l.value);
            if l.lo <= base.tau_sensor_s && base.tau_sensor_s <= l.hi {
                lag_covers += 1;
            }
        }
        let mp_run = simulate(&multipoint_test(), &rig(seed + 10_000));
        let (mf, _) = fit(&input(&mp_run)).map_err(|e| fail(BenchRun::MultiPoint, e))?;
        if mf
            .knees
            .iter()
            .any(|k| k.lo <= knee_true && knee_true <= k.hi)
        {
            bracketed += 1;
        }
        let val = simulate(&validation_test(), &rig(seed + 20_000));
        let ppm = |rate: &[f64]| {
            let err: Vec<f64> = rate
                .iter()
                .zip(&val.ref_rate_dps)
                .map(|(y, w)| y - w)
                .collect();
            window_rms_ppm(&val.t_s, &val.ref_rate_dps, &err, RESIDUAL_WINDOW_S).0
        };
        raw.push(ppm(&val.rate_dps));
        for (table, out) in [(&mf.table, &mut mp), (&cf.table, &mut cont)] {
            let (c, _) = compensate_rows(table, &val.t_s, &val.rate_dps, &val.temp_c);
            out.push(ppm(&c));
        }
        let nk = RigParams {
            truth: base.truth.without_knees(),
            ..rig(seed + 30_000)
        };
        let nk_run = simulate(&continuous_fit_test(), &nk);
        let (nf, _) = fit(&input(&nk_run)).map_err(|e| fail(BenchRun::NoKnee, e))?;
        if nf.knees.is_empty() {
            no_knee_ok += 1;
        }
        progress();
    }
    Ok(ScaleFactorBench {
        seeds,
        knee_true_c: knee_true,
        continuous_one_knee: one_knee,
        continuous_knee_abs_err_c: stats(&knee_err),
        continuous_knee_ci_width_c: stats(&knee_w),
        continuous_ci_covers: covers,
        sensor_lag_s: stats(&lag),
        sensor_lag_ci_covers: lag_covers,
        validation_raw_ppm: stats(&raw),
        validation_multipoint_ppm: stats(&mp),
        validation_continuous_ppm: stats(&cont),
        multipoint_knee_bracketed: bracketed,
        no_knee_fitted_without_knee: no_knee_ok,
    })
}
