//! The outside generator's rate noise, each term made its own way:
//!
//! - white rate noise of angle random walk N (deg/sqrt(h)): a row of dt s
//!   is a mean whose standard deviation is (N/60)/sqrt(dt) deg/s, so a 1 s
//!   mean has 60 N deg/h;
//! - flicker of bias instability B as a sum of relaxation processes
//!   (first-order Markov, exact AR(1) steps) with time constants spaced a
//!   factor r = 10^(1/3) apart from 2 s to ten times the record. Each
//!   has variance s^2 and one-sided PSD 4 s^2 tau/(1 + (2 pi f tau)^2);
//!   summed over log-spaced tau that is s^2/(f ln r) inside the band, and
//!   flicker noise h/f has the flat Allan variance 2 ln2 h, which is
//!   (2 ln2/pi) B^2 (the floor 0.664 B) for s^2 = B^2 ln r/pi. (The other
//!   generators use Kasdin's fractional filter through an FFT and other
//!   filters: this one has no FFT.)
//! - rate random walk K (deg/h/sqrt(h)): Gaussian increments of
//!   K/216000 sqrt(dt) deg/s per row;
//! - first-order Markov noise (sigma, T_c) as its exact AR(1);
//! - an RLG's angle counts of q arcsec, read through its dither and
//!   stripped: each readout's error is uniform over a count and independent
//!   of the last, so a 1 s mean carries q/sqrt(6) deg/h of quantisation
//!   noise (the difference of two independent uniform errors of q:
//!   variance 2 q^2/12).

use super::rng::Rng;

/// Relaxation processes per decade of the flicker synthesis.
const PER_DECADE: f64 = 3.0;

/// The noise of a gyro, in the units gyro engineers quote.
#[derive(Clone, Copy, Debug, Default, serde::Serialize)]
pub struct NoiseSpec {
    /// Angle random walk, deg/sqrt(h).
    pub arw_dpsh: f64,
    /// Bias instability (flicker), deg/h.
    pub flicker_dph: f64,
    /// Rate random walk, deg/h/sqrt(h).
    pub rrw_dphsh: f64,
    /// First-order Markov noise: sigma, deg/h, and correlation time, s.
    pub markov_dph: f64,
    pub markov_s: f64,
    /// RLG angle count, arcsec (0: the output is not quantised).
    pub count_arcsec: f64,
}

impl NoiseSpec {
    /// The white floor of 1 s means, deg/h: angle random walk and, for an
    /// RLG, its counts (both white at 1 s).
    pub fn floor_1s_dph(&self) -> f64 {
        let w = 60.0 * self.arw_dpsh;
        let q = self.count_arcsec / 6f64.sqrt();
        (w * w + q * q).sqrt()
    }

    pub fn describe(&self) -> String {
        format!(
            "white {:.4} deg/sqrt(h), flicker (relaxation sum) {:.4} deg/h, rate random walk {:.4} deg/h/sqrt(h), Markov {:.4} deg/h over {:.0} s, counts {:.2} arcsec",
            self.arw_dpsh, self.flicker_dph, self.rrw_dphsh, self.markov_dph, self.markov_s, self.count_arcsec
        )
    }
}

/// Flicker noise of bias instability `b` (the output carries its unit)
/// over `n` rows `dt` s apart, as a sum of relaxation processes.
pub fn relaxation_flicker(n: usize, dt: f64, b: f64, rng: &mut Rng) -> Vec<f64> {
    let mut out = vec![0.0; n];
    if n == 0 || b == 0.0 {
        return out;
    }
    let r = 10f64.powf(1.0 / PER_DECADE);
    let s = b * (r.ln() / std::f64::consts::PI).sqrt();
    let tau_max = 10.0 * n as f64 * dt;
    let mut tau = 2.0 * dt.max(1.0);
    while tau < tau_max {
        let phi = (-dt / tau).exp();
        let kick = s * (1.0 - phi * phi).sqrt();
        // Stationary from the first row.
        let mut x = s * rng.gauss();
        for o in out.iter_mut() {
            *o += x;
            x = phi * x + kick * rng.gauss();
        }
        tau *= r;
    }
    out
}

/// The noise of `n` rows `dt` s apart before the counts, deg/s: the sum,
/// and its white part alone (to measure the realised floor).
pub fn rate_noise(spec: &NoiseSpec, n: usize, dt: f64, rng: &mut Rng) -> (Vec<f64>, Vec<f64>) {
    let white_sd = spec.arw_dpsh / 60.0 / dt.sqrt();
    let white: Vec<f64> = (0..n).map(|_| white_sd * rng.gauss()).collect();
    let flicker = relaxation_flicker(n, dt, spec.flicker_dph / 3600.0, rng);
    let walk_sd = spec.rrw_dphsh / 216_000.0 * dt.sqrt();
    let (phi, mk_sd) = if spec.markov_dph > 0.0 {
        (
            (-dt / spec.markov_s.max(1e-9)).exp(),
            spec.markov_dph / 3600.0,
        )
    } else {
        (0.0, 0.0)
    };
    let mut walk = 0.0;
    let mut mk = mk_sd * rng.gauss();
    let sum = (0..n)
        .map(|k| {
            let v = white[k] + flicker[k] + walk + mk;
            walk += walk_sd * rng.gauss();
            mk = phi * mk + mk_sd * (1.0 - phi * phi).sqrt() * rng.gauss();
            v
        })
        .collect();
    (sum, white)
}

/// An RLG's counted output, deg/s: the rate integrated over each row and
/// counted in whole counts of `q_arcsec` through the dither. The dither
/// angle at each readout is random over many counts (its amplitude noise
/// randomises it) and stripping subtracts it after counting, so each
/// readout's counting error is uniform over one count and independent of
/// the last; the row's rate is the difference of two readouts.
pub fn count(rate: &[f64], dt: f64, q_arcsec: f64, rng: &mut Rng) -> Vec<f64> {
    if q_arcsec <= 0.0 {
        return rate.to_vec();
    }
    let q = q_arcsec / 3600.0;
    let mut angle = 0.0;
    let read = |angle: f64, rng: &mut Rng| {
        let dither = 64.0 * q * rng.unit();
        ((angle + dither) / q).floor() * q - dither
    };
    let mut last = read(angle, rng);
    rate.iter()
        .map(|r| {
            angle += r * dt;
            let now = read(angle, rng);
            let out = (now - last) / dt;
            last = now;
            out
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn adev(x: &[f64], m: usize) -> f64 {
        let means: Vec<f64> = x
            .chunks_exact(m)
            .map(|c| c.iter().sum::<f64>() / m as f64)
            .collect();
        (means.windows(2).map(|p| (p[1] - p[0]).powi(2)).sum::<f64>()
            / (2.0 * (means.len() - 1) as f64))
            .sqrt()
    }

    #[test]
    fn relaxation_flicker_has_the_floor_of_its_bias_instability() {
        // The Allan deviation of flicker is 0.664 B, flat, between the
        // band's ends (2 s .. 10 records): read at 16 and 128 s over 30
        // records of 2^14 s.
        let b = 1.0;
        let mut rng = Rng::new(17, 4);
        let (mut v16, mut v128) = (0.0, 0.0);
        let reps = 30;
        for _ in 0..reps {
            let x = relaxation_flicker(1 << 14, 1.0, b, &mut rng);
            v16 += adev(&x, 16).powi(2) / reps as f64;
            v128 += adev(&x, 128).powi(2) / reps as f64;
        }
        let want = (2.0 * std::f64::consts::LN_2 / std::f64::consts::PI).sqrt() * b;
        assert!(
            (v16.sqrt() / want - 1.0).abs() < 0.12,
            "{} vs {want}",
            v16.sqrt()
        );
        assert!(
            (v128.sqrt() / want - 1.0).abs() < 0.15,
            "{} vs {want}",
            v128.sqrt()
        );
    }

    #[test]
    fn white_and_counts_give_the_stated_1s_floor() {
        let spec = NoiseSpec {
            arw_dpsh: 0.003,
            count_arcsec: 0.8,
            ..Default::default()
        };
        let mut rng = Rng::new(2, 9);
        let n = 40_000;
        let (x, _) = rate_noise(&spec, n, 1.0, &mut rng);
        let w = 0.01; // a constant input rate, deg/s
        let y: Vec<f64> = x.iter().map(|v| v + w).collect();
        let c = count(&y, 1.0, spec.count_arcsec, &mut rng);
        let rms = (c.iter().map(|v| (v - w).powi(2)).sum::<f64>() / n as f64).sqrt() * 3600.0;
        let want = spec.floor_1s_dph();
        assert!((rms / want - 1.0).abs() < 0.03, "{rms} vs {want}");
    }
}
