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

use super::fit::{self, SfInput};
use super::sim::{self, Direction, RigParams, SweepProfile, Test};
use super::{compensate_rows, fit_run_data};
use crate::error::LabError;
use clap::Args;
use indicatif::{ProgressBar, ProgressStyle};

#[derive(Args, Debug, Clone)]
pub struct BenchArgs {
    /// Seeds (gyro noise and sensor noise) to average over.
    #[arg(long, default_value_t = 20)]
    pub seeds: u64,
    #[arg(long)]
    pub json: bool,
}

fn input(run: &sim::Run) -> SfInput {
    fit::prepare(&run.t_s, &run.ref_rate_dps, &run.rate_dps, &run.temp_c)
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

#[derive(Default, serde::Serialize)]
struct Stats {
    n: usize,
    mean: f64,
    sd: f64,
    max: f64,
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

#[derive(serde::Serialize)]
struct BenchJson {
    seeds: u64,
    knee_true_c: f64,
    /// Continuous fit: seeds with exactly one knee found, |knee error|, and
    /// seeds whose 95 % interval covers the truth.
    continuous_one_knee: usize,
    continuous_knee_abs_err_c: Stats,
    continuous_knee_ci_width_c: Stats,
    continuous_ci_covers: usize,
    sensor_lag_s: Stats,
    sensor_lag_ci_covers: usize,
    /// Validation RMS of 60 s means, ppm.
    validation_raw_ppm: Stats,
    validation_multipoint_ppm: Stats,
    validation_continuous_ppm: Stats,
    multipoint_knee_bracketed: usize,
    no_knee_fitted_without_knee: usize,
}

pub fn run(a: &BenchArgs) -> Result<(), LabError> {
    if a.seeds == 0 || a.seeds > 1000 {
        return Err(LabError::Usage(format!("--seeds {}: 1..=1000", a.seeds)));
    }
    let base = RigParams::default();
    let knee_true = base.truth.knees[0].0;
    let bar = if a.json {
        ProgressBar::hidden()
    } else {
        let b = ProgressBar::new(a.seeds);
        b.set_style(
            ProgressStyle::with_template("{bar:40} seed {pos}/{len} {eta}")
                .unwrap_or(ProgressStyle::default_bar()),
        );
        b
    };
    let fail = |what: &str, e: fit::SfFitError| {
        LabError::Bench(format!("bench scale-factor: {what}: {e}"))
    };
    let (mut knee_err, mut knee_w, mut lag) = (vec![], vec![], vec![]);
    let (mut one_knee, mut covers, mut lag_covers, mut bracketed, mut no_knee_ok) = (0, 0, 0, 0, 0);
    let (mut raw, mut mp, mut cont) = (vec![], vec![], vec![]);
    for seed in 1..=a.seeds {
        let rig = |s: u64| RigParams { seed: s, ..base };
        let fit_run = sim::simulate(&continuous_fit_test(), &rig(seed));
        let (cf, _) = fit_run_data(&input(&fit_run)).map_err(|e| fail("continuous fit", e))?;
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
        let mp_run = sim::simulate(&multipoint_test(), &rig(seed + 10_000));
        let (mf, _) = fit_run_data(&input(&mp_run)).map_err(|e| fail("multi-point fit", e))?;
        if mf
            .knees
            .iter()
            .any(|k| k.lo <= knee_true && knee_true <= k.hi)
        {
            bracketed += 1;
        }
        let val = sim::simulate(&validation_test(), &rig(seed + 20_000));
        let ppm = |rate: &[f64]| {
            let err: Vec<f64> = rate
                .iter()
                .zip(&val.ref_rate_dps)
                .map(|(y, w)| y - w)
                .collect();
            fit::window_rms_ppm(&val.t_s, &val.ref_rate_dps, &err, fit::RESIDUAL_WINDOW_S).0
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
        let nk_run = sim::simulate(&continuous_fit_test(), &nk);
        let (nf, _) = fit_run_data(&input(&nk_run)).map_err(|e| fail("no-knee fit", e))?;
        if nf.knees.is_empty() {
            no_knee_ok += 1;
        }
        bar.inc(1);
    }
    bar.finish_and_clear();
    let j = BenchJson {
        seeds: a.seeds,
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
    };
    if !a.json {
        let n = a.seeds;
        println!("FOG scale factor over temperature, {n} seeds; true knee {knee_true} degC, sensor lag {} s", base.tau_sensor_s);
        println!("validation run: steps profile, -100 deg/s only; RMS of the scale-factor error over 60 s means");
        println!(
            "{:<34} {:>22} {:>18}",
            "calibration", "validation ppm", "knee"
        );
        println!(
            "{:<34} {:>10.2} +- {:<8.2} {:>18}",
            "raw (nominal scale factor)", j.validation_raw_ppm.mean, j.validation_raw_ppm.sd, "-"
        );
        println!(
            "{:<34} {:>10.2} +- {:<8.2} {:>18}",
            "classic multi-point (5 plateaus)",
            j.validation_multipoint_ppm.mean,
            j.validation_multipoint_ppm.sd,
            format!("bracketed {bracketed}/{n}")
        );
        println!(
            "{:<34} {:>10.3} +- {:<8.3} {:>18}",
            "continuous rotation",
            j.validation_continuous_ppm.mean,
            j.validation_continuous_ppm.sd,
            format!("found {one_knee}/{n}")
        );
        println!(
            "continuous: knee error {:.3} degC mean, {:.3} max; 95 % interval {:.2} degC wide, covers the truth in {covers}/{n}",
            j.continuous_knee_abs_err_c.mean, j.continuous_knee_abs_err_c.max, j.continuous_knee_ci_width_c.mean
        );
        println!(
            "continuous: sensor lag {:.2} +- {:.2} s (truth {}), interval covers in {lag_covers}/{n}; worst validation {:.3} ppm",
            j.sensor_lag_s.mean, j.sensor_lag_s.sd, base.tau_sensor_s, j.validation_continuous_ppm.max
        );
        println!("no-knee gyro fitted with no knee: {no_knee_ok}/{n}");
    }
    println!(
        "{}",
        serde_json::to_string(&j).map_err(|e| LabError::Io {
            file: None,
            msg: e.to_string()
        })?
    );
    Ok(())
}
