//! Rate records of known noise terms from the project's own generator
//! (gyro_sim::noise, the five IEEE 952 power laws), with the annex's two
//! other terms added here: a sinusoid (each sample its exact mean over the
//! sample period, random phase) and first-order Markov noise (an
//! Ornstein-Uhlenbeck process advanced exactly, its exact mean over each
//! period drawn jointly with its end value, as the generator's flicker
//! components are). What the noise analysis is checked against; the
//! independent generator (independent_noise.rs) checks it again by other
//! algorithms.

use crate::noise::terms::COUNT;
use gyro_sim::{NoiseParams, RateNoise};
use rand_core::SeedableRng;
use rand_distr::{Distribution, StandardNormal, StandardUniform};
use rand_xoshiro::Xoshiro256PlusPlus;

/// Known terms: the power laws (Q arcsec, N deg/sqrt(h), B deg/h, K
/// deg/h/sqrt(h), R deg/h^2; zero where absent), a sinusoid (amplitude
/// deg/h, frequency Hz) and a Markov term (stationary sigma deg/h,
/// correlation time s).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Truth {
    pub laws: [f64; COUNT],
    pub sinusoid: Option<(f64, f64)>,
    pub markov: Option<(f64, f64)>,
}

impl Truth {
    pub const fn laws(laws: [f64; COUNT]) -> Self {
        Self {
            laws,
            sinusoid: None,
            markov: None,
        }
    }
}

/// The generator's parameters for the terms `truth` (Q arcsec, N
/// deg/sqrt(h), B deg/h, K deg/h/sqrt(h), R deg/h^2; rate in deg/s).
pub fn noise_params(truth: &[f64; COUNT], record_s: f64) -> NoiseParams {
    NoiseParams {
        q_deg: truth[0] / 3600.0,
        n_dps_rts: NoiseParams::arw_from_dpsh(truth[1]),
        b_dps: NoiseParams::b_from_dph(truth[2]),
        k_dps_rts: NoiseParams::k_from_dphsh(truth[3]),
        r_dps2: truth[4] / 3600.0 / 3600.0,
        flicker_max_tau_s: 10.0 * record_s,
    }
}

/// `n` samples every `tau0` s of the power laws `truth`.
pub fn record(truth: &[f64; COUNT], n: usize, tau0: f64, seed: u64) -> Vec<f64> {
    let mut g = RateNoise::new(noise_params(truth, n as f64 * tau0), tau0, seed);
    (0..n).map(|_| g.sample()).collect()
}

/// `n` samples every `tau0` s of all the terms of `truth`, deg/s.
pub fn record_with(truth: &Truth, n: usize, tau0: f64, seed: u64) -> Vec<f64> {
    let mut y = record(&truth.laws, n, tau0, seed);
    // The added terms draw from their own stream.
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed ^ 0x9E37_79B9_7F4A_7C15);
    if let Some((amp_dph, f)) = truth.sinusoid {
        let a = amp_dph / 3600.0;
        let u: f64 = StandardUniform.sample(&mut rng);
        let phi = std::f64::consts::TAU * u;
        let w = std::f64::consts::TAU * f;
        for (k, v) in y.iter_mut().enumerate() {
            // Mean of a sin(w t + phi) over [k tau0, (k+1) tau0].
            let (t0, t1) = (k as f64 * tau0, (k + 1) as f64 * tau0);
            *v += a * ((w * t0 + phi).cos() - (w * t1 + phi).cos()) / (w * tau0);
        }
    }
    if let Some((sigma_dph, t)) = truth.markov {
        let var = (sigma_dph / 3600.0).powi(2);
        // Over one period h from x0: end = phi x0 + e1, mean = g x0 + e2,
        // var e1 = v (1 - phi^2), var e2 = v (T/h)^2 (2h/T - 3 + 4 phi -
        // phi^2), cov = v (T/h) (1 - phi)^2.
        let phi = (-tau0 / t).exp();
        let a = t / tau0;
        let v11 = var * (1.0 - phi * phi);
        let v22 = var * a * a * (2.0 / a - 3.0 + 4.0 * phi - phi * phi);
        let v12 = var * a * (1.0 - phi) * (1.0 - phi);
        let l11 = v11.max(0.0).sqrt();
        let l21 = if l11 > 0.0 { v12 / l11 } else { 0.0 };
        let l22 = (v22 - l21 * l21).max(0.0).sqrt();
        let g = a * (1.0 - phi);
        let z0: f64 = StandardNormal.sample(&mut rng);
        let mut x = var.sqrt() * z0;
        for v in y.iter_mut() {
            let (z1, z2): (f64, f64) = (
                StandardNormal.sample(&mut rng),
                StandardNormal.sample(&mut rng),
            );
            *v += g * x + l21 * z1 + l22 * z2;
            x = phi * x + l11 * z1;
        }
    }
    y
}
