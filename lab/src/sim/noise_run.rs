//! Rate records of known noise terms from the project's own generator
//! (gyro_sim::noise, the IEEE 952 terms): what the noise analysis is
//! checked against.

use crate::noise::terms::COUNT;
use gyro_sim::{NoiseParams, RateNoise};

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

/// `n` samples every `tau0` s of the terms `truth`.
pub fn record(truth: &[f64; COUNT], n: usize, tau0: f64, seed: u64) -> Vec<f64> {
    let mut g = RateNoise::new(noise_params(truth, n as f64 * tau0), tau0, seed);
    (0..n).map(|_| g.sample()).collect()
}
