//! The dithered RLG through the firmware's stripping (sim/dither_run.rs)
//! against the physics (sim/dither_theory.rs), the table of issue 33:
//! - the output's angle random walk (Allan analysis) against the prediction
//!   and Killpatrick's formula, on random draws across the acceptance
//!   ranges (lock-in 0.02..0.2 deg/s, dither 100..300 deg/s at 300..500 Hz,
//!   2000..5000 counts per degree, 2..10 % noise), at rest or inside the
//!   static lock-in band, each with its own seed;
//! - the mean rate error against the input rate through and around the
//!   static lock-in band and the dynamic lock-in zones at multiples of
//!   `f_d/K` (K in fringes per degree), without the amplitude noise, with
//!   a little and with enough.

use crate::sim::dither_run::{DitherRun, DitherRunError, DitherSummary};
use gyro_sim::rlg_dither::{Accuracy, DitherParams};
use rand_core::SeedableRng;
use rand_distr::{Distribution, StandardUniform};
use rand_xoshiro::Xoshiro256PlusPlus;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Mutex;

/// One ARW point's settings and what it measured.
#[derive(Clone, Debug, serde::Serialize)]
pub struct ArwRow {
    pub lock_in_dps: f64,
    pub dither_dps: f64,
    pub dither_hz: f64,
    pub counts_per_deg: f64,
    pub noise_frac: f64,
    pub rate_dps: f64,
    pub seed: u64,
    pub arw_dpsh: Option<f64>,
    pub arw_lo_dpsh: Option<f64>,
    pub arw_hi_dpsh: Option<f64>,
    pub arw_predicted_dpsh: f64,
    pub arw_killpatrick_dpsh: f64,
    /// Measured over predicted.
    pub ratio: Option<f64>,
    /// The prediction inside the measurement's 95 % interval.
    pub covered: bool,
    pub dither_residual_counts_rms: f64,
    pub mean_rate_error_dph: f64,
    pub mean_rate_error_stderr_dph: f64,
    pub crossing_phase_rms_rad: f64,
    pub zone_kappa: f64,
    pub allan_fit_consistent: bool,
}

/// One input rate's mean error.
#[derive(Clone, Debug, serde::Serialize)]
pub struct RateRow {
    pub noise_frac: f64,
    pub rate_dps: f64,
    /// The rate over the zone spacing `f_d/K` (K in fringes per degree).
    pub rate_in_zones: f64,
    pub mean_rate_error_dph: f64,
    pub mean_rate_error_stderr_dph: f64,
    pub predicted_rate_error_dph: f64,
    pub dynamic_zone: i64,
    pub residual_lock_in_dph: f64,
    pub zone_kappa: f64,
}

/// The random draws across the acceptance ranges: `n` points from `seed`,
/// half at rest, half at a rate inside the static lock-in band.
pub fn arw_plan(n: usize, seed: u64, duration_s: f64) -> Vec<DitherRun> {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
    let mut u = move || -> f64 { StandardUniform.sample(&mut rng) };
    (0..n)
        .map(|i| {
            let lock_in = 0.02 * 10f64.powf(u());
            let rate = if i % 2 == 0 {
                0.0
            } else {
                lock_in * (u() * 1.8 - 0.9)
            };
            DitherRun {
                gyro: DitherParams {
                    counts_per_deg: (2000.0 + 3000.0 * u()).round(),
                    lock_in_dps: lock_in,
                    dither_dps: 100.0 + 200.0 * u(),
                    dither_hz: 300.0 + 200.0 * u(),
                    noise_frac: 0.02 + 0.08 * u(),
                    fd_drift_frac: 0.01,
                    fd_drift_period_s: duration_s,
                    accuracy: Accuracy::HOST,
                    seed: seed.wrapping_mul(1000).wrapping_add(i as u64 + 1),
                    ..DitherParams::default()
                },
                rate_dps: rate,
                duration_s,
                settle_s: 2.0,
                photodiodes: true,
            }
        })
        .collect()
}

/// The rate sweep's gyro: 500 fringes per degree at 500 Hz puts the zones
/// at whole deg/s, lock-in 0.2 deg/s, dither 100 deg/s (the crossings'
/// kicks 0.05 rad: the zones are wide).
pub fn rate_gyro(noise: f64, seed: u64) -> DitherParams {
    DitherParams {
        counts_per_deg: 2000.0,
        lock_in_dps: 0.2,
        dither_dps: 100.0,
        dither_hz: 500.0,
        noise_frac: noise,
        fd_drift_frac: 0.0,
        accuracy: Accuracy::HOST,
        seed,
        ..DitherParams::default()
    }
}

/// Input rates: through and around the static band (+-0.2 deg/s) and the
/// m = 0, 1, 2 zones (0, 1, 2 deg/s), finely across each zone.
pub fn rate_plan(noises: &[f64], duration_s: f64, seed: u64) -> Vec<DitherRun> {
    let mut rates: Vec<f64> = vec![-0.3, -0.2, -0.1, -0.05, 0.05, 0.1, 0.15, 0.2, 0.3, 0.5];
    for zone in [0.0, 1.0, 2.0] {
        for k in -8..=8 {
            rates.push(zone + k as f64 * 0.0025);
        }
        rates.push(zone + 0.04);
        rates.push(zone - 0.04);
    }
    rates.retain(|r| *r >= -0.3);
    rates.sort_by(f64::total_cmp);
    rates.dedup_by(|a, b| (*a - *b).abs() < 1e-9);
    let mut out = vec![];
    for (j, &noise) in noises.iter().enumerate() {
        for (i, &rate) in rates.iter().enumerate() {
            out.push(DitherRun {
                gyro: rate_gyro(noise, seed.wrapping_add((j * 1000 + i) as u64)),
                rate_dps: rate,
                duration_s,
                settle_s: 2.0,
                photodiodes: true,
            });
        }
    }
    out
}

pub fn arw_row(r: &DitherRun, s: &DitherSummary) -> ArwRow {
    let g = &r.gyro;
    ArwRow {
        lock_in_dps: g.lock_in_dps,
        dither_dps: g.dither_dps,
        dither_hz: g.dither_hz,
        counts_per_deg: g.counts_per_deg,
        noise_frac: g.noise_frac,
        rate_dps: r.rate_dps,
        seed: g.seed,
        arw_dpsh: s.arw_dpsh,
        arw_lo_dpsh: s.arw_lo_dpsh,
        arw_hi_dpsh: s.arw_hi_dpsh,
        arw_predicted_dpsh: s.arw_predicted_dpsh,
        arw_killpatrick_dpsh: s.arw_killpatrick_dpsh,
        ratio: s.arw_dpsh.map(|v| v / s.arw_predicted_dpsh),
        covered: matches!((s.arw_lo_dpsh, s.arw_hi_dpsh), (Some(lo), Some(hi))
            if lo <= s.arw_predicted_dpsh && s.arw_predicted_dpsh <= hi),
        dither_residual_counts_rms: s.dither_residual_counts_rms,
        mean_rate_error_dph: s.mean_rate_error_dph,
        mean_rate_error_stderr_dph: s.mean_rate_error_stderr_dph,
        crossing_phase_rms_rad: s.crossing_phase_rms_rad,
        zone_kappa: s.zone_kappa,
        allan_fit_consistent: s.allan_fit_consistent,
    }
}

pub fn rate_row(r: &DitherRun, s: &DitherSummary) -> RateRow {
    let g = &r.gyro;
    RateRow {
        noise_frac: g.noise_frac,
        rate_dps: r.rate_dps,
        rate_in_zones: r.rate_dps * g.fringes_per_deg() / g.dither_hz,
        mean_rate_error_dph: s.mean_rate_error_dph,
        mean_rate_error_stderr_dph: s.mean_rate_error_stderr_dph,
        predicted_rate_error_dph: s.predicted_rate_error_dph,
        dynamic_zone: s.dynamic_zone,
        residual_lock_in_dph: s.residual_lock_in_dph,
        zone_kappa: s.zone_kappa,
    }
}

/// Runs `jobs` on `threads` threads (the longest-running share the
/// machine), in their order in the result; `done(i, summary)` hears of
/// each as it ends.
pub fn run_all(
    jobs: &[DitherRun],
    threads: usize,
    done: &(dyn Fn(usize, &DitherSummary) + Sync),
) -> Result<Vec<DitherSummary>, DitherRunError> {
    let next = AtomicUsize::new(0);
    let out: Mutex<Vec<Option<Result<DitherSummary, DitherRunError>>>> =
        Mutex::new((0..jobs.len()).map(|_| None).collect());
    std::thread::scope(|s| {
        for _ in 0..threads.max(1) {
            s.spawn(|| loop {
                let i = next.fetch_add(1, Ordering::Relaxed);
                let Some(job) = jobs.get(i) else { break };
                let r = job.run::<DitherRunError>(None, |_| {});
                if let Ok(s) = &r {
                    done(i, s);
                }
                if let Ok(mut o) = out.lock() {
                    o[i] = Some(r);
                }
            });
        }
    });
    let out = out
        .into_inner()
        .map_err(|_| DitherRunError::Analysis("a bench thread panicked".into()))?;
    out.into_iter()
        .map(|r| r.unwrap_or_else(|| Err(DitherRunError::Analysis("a point did not run".into()))))
        .collect()
}
