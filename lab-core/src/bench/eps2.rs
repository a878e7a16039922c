//! `gyro-lab bench eps2`: the online eps^2 correction over the vibration
//! envelope of issue 23 (physics.md 1.4, docs/fog.md "The eps^2 drift").
//!
//! One point per instrument (3pi/4 at 12.5 kHz, 7pi/8 at 6.25 kHz), DAC
//! latency (none, the hw board's one closure), oscillation frequency and
//! peak angular acceleration: gyro-sim's `eps2_point` runs the firmware's
//! core around the simulated optics and averages whole periods until the
//! share of the formula's drift left by the correction is known to the
//! standard error asked (a quarter of the 1 % it is judged against by
//! default). Points run on several threads, longest first (the 1 000
//! deg/s^2 points average hours of simulated time).

use gyro_sim::vibration_drift::{
    eps2_instrument, eps2_point, Eps2Point, EPS2_ACCELERATIONS_DPS2, EPS2_DAC_LATENCIES,
    EPS2_FREQUENCIES_HZ, EPS2_INSTRUMENTS,
};
use gyro_sp::fog::config::ConfigError;
use std::sync::Mutex;

/// One point of the envelope.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Eps2Spec {
    pub phi0_rad: f64,
    pub closure_hz: f64,
    /// Closures of DAC latency (0, or 1: the hw board's DMA ping-pong).
    pub dac_latency: u32,
    pub freq_hz: f64,
    /// Peak angular acceleration, deg/s^2.
    pub eps_dps2: f64,
}

impl Eps2Spec {
    /// phi0 in eighths of pi (6 or 7 for the reference instruments).
    pub fn phi0_eighths(&self) -> f64 {
        self.phi0_rad / std::f64::consts::PI * 8.0
    }
}

/// The whole envelope, instrument by instrument, latency, frequency and
/// acceleration ascending (48 points).
pub fn envelope() -> Vec<Eps2Spec> {
    let mut v = Vec::new();
    for (phi0_rad, closure_hz) in EPS2_INSTRUMENTS {
        for dac_latency in EPS2_DAC_LATENCIES {
            for freq_hz in EPS2_FREQUENCIES_HZ {
                for eps_dps2 in EPS2_ACCELERATIONS_DPS2 {
                    v.push(Eps2Spec {
                        phi0_rad,
                        closure_hz,
                        dac_latency,
                        freq_hz,
                        eps_dps2,
                    });
                }
            }
        }
    }
    v
}

/// A measured point: the drift uncorrected, the formula's value
/// (`FogConfig::predicted_vibration_drift`, latency included), the
/// corrected drift (deg/h), the share of the formula's drift left and its
/// standard error, the loop gain and the simulated seconds averaged.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Eps2Row {
    #[serde(flatten)]
    pub spec: Eps2Spec,
    pub uncorrected_dph: f64,
    pub uncorrected_se_dph: f64,
    pub formula_dph: f64,
    pub corrected_dph: f64,
    pub corrected_se_dph: f64,
    pub share_left: f64,
    pub share_left_se: f64,
    pub loop_gain: f64,
    pub seconds: f64,
    /// The standard error reached the target (else the time limit ended it).
    pub converged: bool,
}

impl Eps2Row {
    fn new(spec: Eps2Spec, p: &Eps2Point, se_target: f64) -> Self {
        let d = p.drift;
        Self {
            spec,
            uncorrected_dph: d.raw_dph,
            uncorrected_se_dph: d.raw_se_dph,
            formula_dph: p.formula_dph,
            corrected_dph: d.corrected_dph,
            corrected_se_dph: d.corrected_se_dph,
            share_left: p.share_left(),
            share_left_se: p.share_left_se(),
            loop_gain: d.loop_gain,
            seconds: d.seconds,
            converged: p.share_left_se() <= se_target,
        }
    }
}

/// How far each point is averaged.
#[derive(Clone, Copy, Debug)]
pub struct Eps2Plan {
    /// Standard error of the share left to reach (0.0025: a quarter of 1 %).
    pub se_target: f64,
    /// Simulated seconds per point at most.
    pub max_seconds: f64,
    pub threads: usize,
    /// Seed of the instrument's detector noise.
    pub seed: u64,
}

/// What the progress callback hears: a point finished (its index in the
/// list and its row), or a running point's standard error so far.
#[derive(Clone, Copy, Debug)]
pub enum Eps2Progress {
    Done(usize, Eps2Row),
    Running {
        index: usize,
        share_left_se: f64,
        seconds: f64,
    },
}

/// Runs `points` (in the order of the list in the result), `progress`
/// hearing of each from every thread.
pub fn run(
    points: &[Eps2Spec],
    plan: Eps2Plan,
    progress: &(dyn Fn(Eps2Progress) + Sync),
) -> Result<Vec<Eps2Row>, ConfigError> {
    // Longest first: the smallest accelerations need the most averaging.
    let mut order: Vec<usize> = (0..points.len()).collect();
    order.sort_by(|&a, &b| {
        let (pa, pb) = (points[a], points[b]);
        pb.eps_dps2.total_cmp(&pa.eps_dps2).then(b.cmp(&a))
    });
    let queue = Mutex::new(order);
    let rows: Mutex<Vec<(usize, Eps2Row)>> = Mutex::new(Vec::new());
    let failed: Mutex<Option<ConfigError>> = Mutex::new(None);
    std::thread::scope(|s| {
        for _ in 0..plan.threads.max(1) {
            s.spawn(|| loop {
                let next = queue.lock().map(|mut q| q.pop()).unwrap_or(None);
                let Some(i) = next else { break };
                let spec = points[i];
                let mut blocks = 0u64;
                let r = eps2_point(
                    eps2_instrument(spec.phi0_rad, spec.closure_hz, spec.dac_latency),
                    plan.seed,
                    spec.eps_dps2,
                    spec.freq_hz,
                    plan.se_target,
                    plan.max_seconds,
                    |p| {
                        blocks += 1;
                        if blocks.is_multiple_of(16) {
                            progress(Eps2Progress::Running {
                                index: i,
                                share_left_se: p.share_left_se(),
                                seconds: p.drift.seconds,
                            });
                        }
                    },
                );
                match r {
                    Ok(p) => {
                        let row = Eps2Row::new(spec, &p, plan.se_target);
                        progress(Eps2Progress::Done(i, row));
                        if let Ok(mut v) = rows.lock() {
                            v.push((i, row));
                        }
                    }
                    Err(e) => {
                        if let Ok(mut f) = failed.lock() {
                            *f = Some(e);
                        }
                        if let Ok(mut q) = queue.lock() {
                            q.clear();
                        }
                    }
                }
            });
        }
    });
    if let Some(e) = failed.into_inner().ok().flatten() {
        return Err(e);
    }
    let mut rows = rows.into_inner().unwrap_or_default();
    rows.sort_by_key(|r| r.0);
    Ok(rows.into_iter().map(|r| r.1).collect())
}

/// The table's verdict: the worst share left (absolute) and where, the
/// worst loop-gain error, the points not converged.
#[derive(Clone, Copy, Debug, serde::Serialize)]
pub struct Eps2Summary {
    pub points: usize,
    pub worst_share_left: f64,
    pub worst_share_left_se: f64,
    pub worst_gain_error: f64,
    pub points_over_1pct: usize,
    pub not_converged: usize,
}

pub fn summarize(rows: &[Eps2Row]) -> Eps2Summary {
    let worst = rows
        .iter()
        .max_by(|a, b| a.share_left.abs().total_cmp(&b.share_left.abs()));
    Eps2Summary {
        points: rows.len(),
        worst_share_left: worst.map_or(0.0, |r| r.share_left),
        worst_share_left_se: worst.map_or(0.0, |r| r.share_left_se),
        worst_gain_error: rows
            .iter()
            .map(|r| (r.loop_gain - 1.0).abs())
            .fold(0.0, f64::max),
        points_over_1pct: rows.iter().filter(|r| r.share_left.abs() > 0.01).count(),
        not_converged: rows.iter().filter(|r| !r.converged).count(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The envelope has every combination once: 2 instruments x 2 latencies
    /// x 3 frequencies x 4 accelerations.
    #[test]
    fn envelope_covers_every_point_once() {
        let e = envelope();
        assert_eq!(e.len(), 48);
        for (i, a) in e.iter().enumerate() {
            assert!(e[i + 1..].iter().all(|b| b != a));
        }
        assert!(e
            .iter()
            .any(|p| p.dac_latency == 1 && p.eps_dps2 == 50_000.0));
    }

    /// A short run of one fast point (the standard error target loose) comes
    /// back in order, with the formula's sign and the correction at work.
    #[test]
    fn one_point_runs() {
        let spec = Eps2Spec {
            phi0_rad: 0.75 * std::f64::consts::PI,
            closure_hz: 12_500.0,
            dac_latency: 0,
            freq_hz: 60.0,
            eps_dps2: 50_000.0,
        };
        let plan = Eps2Plan {
            se_target: 1.0,
            max_seconds: 2.0,
            threads: 1,
            seed: gyro_sim::vibration_drift::EPS2_NOISE_SEED,
        };
        let rows = run(&[spec], plan, &|_| {}).unwrap();
        assert_eq!(rows.len(), 1);
        let r = rows[0];
        assert!(r.formula_dph > 0.0);
        assert!(
            (r.uncorrected_dph / r.formula_dph - 1.0).abs() < 0.1,
            "{r:?}"
        );
        assert!(r.share_left.abs() < 0.05, "{r:?}");
    }
}
