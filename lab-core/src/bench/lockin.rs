//! `gyro-lab bench lockin`: the exact harmonic relation against the published
//! approximate formula over Omega_I/Omega_L = 2..100, on simulated records in
//! the reference conditions (K = 2000 /deg, Omega_I = 1 deg/s, beta = 0):
//! 1 % noise for 3 s at 20 kHz, and 8-bit records of 2 500 points.

use crate::calibration::lockin::lock_in;
use crate::sim::fringe::FringeParams;
use serde::Serialize;

pub const RATIOS: [f64; 8] = [2.0, 3.0, 5.0, 10.0, 20.0, 30.0, 50.0, 100.0];

#[derive(Clone, Copy, Debug)]
pub enum Record {
    /// 1 % noise, 3 s at 20 kHz.
    Noise1Pct,
    /// 8-bit ADC over +-1.1 amplitudes, 2 500 points at 20 kHz, 0.1 % noise
    /// ahead of it (the quantization noise, 0.25 %, dominates).
    EightBit,
}

impl Record {
    pub fn params(self, ratio: f64, seed: u64) -> FringeParams {
        let base = FringeParams {
            input_rate_dps: 1.0,
            lock_in_dps: 1.0 / ratio,
            // An arbitrary start phase per seed: the estimator must not need it.
            psi0_rad: seed as f64 * 2.399,
            seed,
            ..Default::default()
        };
        match self {
            Record::Noise1Pct => FringeParams {
                noise_rel: 0.01,
                ..base
            },
            Record::EightBit => FringeParams {
                samples: 2500,
                noise_rel: 0.001,
                bits: Some(8),
                ..base
            },
        }
    }
}

#[derive(Clone, Debug, Serialize)]
pub struct Row {
    pub ratio: f64,
    pub lock_in_dps: f64,
    /// Exact relation with the fitted rho and beat (input rate not used):
    /// RMS and largest relative error over the seeds, %.
    pub exact_rms_pct: f64,
    pub exact_max_pct: f64,
    /// The fit's own one-sigma uncertainty, % (mean over seeds).
    pub exact_std_pct: f64,
    /// The same from both channels of the quadrature pair (the RLG readout
    /// has two photodiodes, docs/rlg.md): independent noise, so the
    /// bound falls by sqrt(2).
    pub pair_rms_pct: f64,
    pub pair_max_pct: f64,
    pub pair_std_pct: f64,
    /// Published approximate formula with the true input rate and the
    /// spectrum's A2/A1: mean and largest relative error, %.
    pub approx_mean_pct: f64,
    pub approx_max_pct: f64,
}

/// The two record kinds of the bench: JSON key, kind, title.
pub const RECORDS: [(&str, Record, &str); 2] = [
    (
        "noise_1pct_3s",
        Record::Noise1Pct,
        "1 % noise, 3 s at 20 kHz",
    ),
    (
        "adc_8bit_2500",
        Record::EightBit,
        "8-bit ADC, 2 500 points at 20 kHz",
    ),
];

/// One row per ratio of [`RATIOS`], over `seeds` records each.
pub fn table(rec: Record, seeds: u64) -> Vec<Row> {
    RATIOS
        .iter()
        .map(|&ratio| {
            let (mut errs, mut pair_errs) = (Vec::new(), Vec::new());
            let (mut std_sum, mut approx_sum, mut approx_max) = (0.0, 0.0, 0.0f64);
            let mut pair_std_sum = 0.0;
            let mut truth = 0.0;
            for seed in 1..=seeds {
                let p = rec.params(ratio, seed);
                truth = p.lock_in_dps;
                let f = p.simulate();
                match lock_in(&f.t, &f.s, None, p.pulses_per_deg, None) {
                    Ok(r) => {
                        errs.push((r.lock_in_dps / truth - 1.0) * 100.0);
                        std_sum += r.lock_in_std_dps / truth * 100.0;
                        let approx =
                            p.input_rate_dps / (1.0 + (1.0 / (2.0 * r.a2_over_a1)).powi(2)).sqrt();
                        let e = (approx / truth - 1.0) * 100.0;
                        approx_sum += e;
                        approx_max = approx_max.max(e.abs());
                    }
                    Err(_) => errs.push(f64::INFINITY),
                }
                match lock_in(&f.t, &f.s, Some(&f.q), p.pulses_per_deg, None) {
                    Ok(r) => {
                        pair_errs.push((r.lock_in_dps / truth - 1.0) * 100.0);
                        pair_std_sum += r.lock_in_std_dps / truth * 100.0;
                    }
                    Err(_) => pair_errs.push(f64::INFINITY),
                }
            }
            let n = seeds as f64;
            let rms = |e: &[f64]| (e.iter().map(|e| e * e).sum::<f64>() / n).sqrt();
            let max = |e: &[f64]| e.iter().fold(0.0f64, |m, e| m.max(e.abs()));
            Row {
                ratio,
                lock_in_dps: truth,
                exact_rms_pct: rms(&errs),
                exact_max_pct: max(&errs),
                exact_std_pct: std_sum / n,
                pair_rms_pct: rms(&pair_errs),
                pair_max_pct: max(&pair_errs),
                pair_std_pct: pair_std_sum / n,
                approx_mean_pct: approx_sum / n,
                approx_max_pct: approx_max,
            }
        })
        .collect()
}
