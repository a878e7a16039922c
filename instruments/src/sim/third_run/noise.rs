//! The third generator's rate noise (physics.md 3), each term synthesised
//! its own way:
//!
//! - white rate noise of angle random walk N: a row's mean has standard
//!   deviation (N/60)/sqrt(dt) deg/s;
//! - flicker (bias instability B) by Kasdin's fractional integration
//!   (alpha = 1): white innovations of standard deviation B filtered by
//!   h_0 = 1, h_k = h_(k-1) (k - 1/2)/k, through a zero-padded FFT; its
//!   one-sided PSD is B^2/(pi f), the Allan floor (2 ln 2/pi) B^2;
//! - rate random walk K: increments of (K/216000) sqrt(dt) deg/s;
//! - first-order Markov noise (sigma, T_c) as its exact AR(1);
//! - quantisation, by the caller (an RLG's angle counts, a MEMS word).

use super::rng::Rng;
use realfft::RealFftPlanner;

/// The noise of a run, in the units gyro engineers quote.
#[derive(Clone, Copy, Debug, Default)]
pub struct NoiseSpec {
    /// Angle random walk, deg/sqrt(h).
    pub arw_dpsh: f64,
    /// Bias instability, deg/h.
    pub flicker_dph: f64,
    /// Rate random walk, deg/h/sqrt(h).
    pub rrw_dphsh: f64,
    /// First-order Markov: sigma, deg/h; correlation time, s.
    pub markov_dph: f64,
    pub markov_s: f64,
}

impl NoiseSpec {
    pub fn describe(&self) -> String {
        format!(
            "white {} deg/sqrt(h), flicker (Kasdin) {} deg/h, random walk {} deg/h/sqrt(h), Markov {} deg/h over {} s",
            self.arw_dpsh, self.flicker_dph, self.rrw_dphsh, self.markov_dph, self.markov_s
        )
    }
}

/// Kasdin's flicker: `n` samples of 1/f noise whose innovations have
/// standard deviation `b` (its bias instability, in the output's unit).
pub fn kasdin_flicker(n: usize, b: f64, rng: &mut Rng) -> Vec<f64> {
    if n == 0 || b == 0.0 {
        return vec![0.0; n];
    }
    let m = (2 * n).next_power_of_two();
    let mut h = vec![0.0; m];
    let mut w = vec![0.0; m];
    h[0] = 1.0;
    for k in 1..n {
        h[k] = h[k - 1] * (k as f64 - 0.5) / k as f64;
    }
    for v in w.iter_mut().take(n) {
        *v = b * rng.normal();
    }
    let mut planner = RealFftPlanner::<f64>::new();
    let fwd = planner.plan_fft_forward(m);
    let inv = planner.plan_fft_inverse(m);
    let mut hs = fwd.make_output_vec();
    let mut ws = fwd.make_output_vec();
    if fwd.process(&mut h, &mut hs).is_err() || fwd.process(&mut w, &mut ws).is_err() {
        return vec![0.0; n];
    }
    for (a, b) in ws.iter_mut().zip(&hs) {
        *a *= b;
    }
    let mut out = inv.make_output_vec();
    if inv.process(&mut ws, &mut out).is_err() {
        return vec![0.0; n];
    }
    out.truncate(n);
    out.iter().map(|v| v / m as f64).collect()
}

/// The noise of `n` rows `dt` s apart, deg/s (row means).
pub fn rate_noise(spec: &NoiseSpec, n: usize, dt: f64, rng: &mut Rng) -> Vec<f64> {
    let white = spec.arw_dpsh / 60.0 / dt.sqrt();
    let fl = kasdin_flicker(n, spec.flicker_dph / 3600.0, rng);
    let rw_step = spec.rrw_dphsh / 216_000.0 * dt.sqrt();
    let (phi, mk_sd) = if spec.markov_dph > 0.0 {
        let p = (-dt / spec.markov_s.max(1e-9)).exp();
        (p, spec.markov_dph / 3600.0)
    } else {
        (0.0, 0.0)
    };
    let mut walk = 0.0;
    let mut mk = mk_sd * rng.normal();
    (0..n)
        .map(|k| {
            walk += rw_step * rng.normal();
            mk = phi * mk + mk_sd * (1.0 - phi * phi).sqrt() * rng.normal();
            white * rng.normal() + fl[k] + walk + mk
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn kasdin_flicker_has_the_allan_floor_of_its_bias_instability() {
        // Allan variance of 1/f noise: (2 ln 2/pi) B^2, flat; checked at
        // averaging times of 64 and 256 samples over 40 records.
        let b = 1.0;
        let mut rng = Rng::new(11);
        let (mut a64, mut a256) = (0.0, 0.0);
        let reps = 40;
        for _ in 0..reps {
            let x = kasdin_flicker(1 << 14, b, &mut rng);
            let avar = |m: usize| {
                let means: Vec<f64> = x
                    .chunks_exact(m)
                    .map(|c| c.iter().sum::<f64>() / m as f64)
                    .collect();
                means.windows(2).map(|p| (p[1] - p[0]).powi(2)).sum::<f64>()
                    / (2.0 * (means.len() - 1) as f64)
            };
            a64 += avar(64) / reps as f64;
            a256 += avar(256) / reps as f64;
        }
        let want = 2.0 * std::f64::consts::LN_2 / std::f64::consts::PI * b * b;
        assert!((a64 / want - 1.0).abs() < 0.12, "{a64} vs {want}");
        assert!((a256 / want - 1.0).abs() < 0.2, "{a256} vs {want}");
    }
}
