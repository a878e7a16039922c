//! A second noise generator, independent of the project's
//! (gyro_sim::noise and noise_run.rs), so the Allan analysis is not only
//! checked on the generator it was built with. Every term by another
//! algorithm:
//!
//! - its own random numbers: splitmix64 and the Box-Muller transform;
//! - white rate noise N: Gaussian samples of sigma N/sqrt(tau0);
//! - flicker (bias instability B, one-sided PSD B^2/(pi f)): spectral
//!   synthesis, Gaussian Fourier coefficients shaped by sqrt(PSD) and an
//!   inverse real FFT over a record 4 times longer than asked (the
//!   spectrum reaches 4 times below the record's lowest frequency), at 4
//!   sub-samples per sample averaged to each sample's mean (the aliasing
//!   of the truncated spectrum stays below 1 % of the variance at tau0);
//! - first-order Markov noise (sigma, T_c): the exact AR(1) recursion of
//!   its point values at 4 sub-samples per sample, averaged;
//! - rate random walk K: a Gaussian random walk at 4 sub-samples per
//!   sample, averaged; a ramp R t;
//! - a sinusoid: the exact mean of A sin(2 pi f t + phi) over each period;
//! - quantization: a true quantizer of the accumulated angle (angle
//!   counts of `quantum` = Q sqrt(12)) read through a stripped dither, as
//!   a ring-laser gyro's body dither is: a known random angle, uniform over
//!   whole quanta and new at every sample, is added before the counter and
//!   taken off its reading. The angle error is then uniform over one
//!   quantum, independent of the signal and from sample to sample
//!   (Schuchman 1964, subtractive dither): white angle noise of variance
//!   quantum^2 / 12 = Q^2, whose Allan variance is IEEE 952's 3 Q^2 /
//!   tau^2 whatever the rate does. Without the dither the error is white
//!   only when the rate moves the angle over many counts per sample; on a
//!   nearly still angle (a sinusoid of 20 deg/h at 0.1 Hz swings 0.018 deg
//!   peak to peak, less than the 0.019 deg quantum of Q = 20 arcsec) the
//!   counter's error follows the signal instead, and the record has no
//!   3 Q^2 / tau^2 part at that Q (its -1 slope read Q = 12 there).

use crate::noise::terms::COUNT;
use num_complex::Complex;
use realfft::RealFftPlanner;

/// Sub-samples per sample for the flicker, Markov and random-walk terms.
const SUB: usize = 4;
/// How much longer than the record the flicker's spectrum reaches.
const EXTEND: usize = 4;

/// The terms: power laws as in noise_run (Q arcsec: the angle quantum is Q
/// sqrt(12); N deg/sqrt(h), B deg/h, K deg/h/sqrt(h), R deg/h^2), a
/// sinusoid (amplitude deg/h, Hz) and a Markov term (sigma deg/h, T_c s).
pub use super::noise_run::Truth;

/// splitmix64 (Steele, Lea and Flood 2014) with Box-Muller normals.
pub struct Rng {
    state: u64,
    spare: Option<f64>,
}

impl Rng {
    pub fn new(seed: u64) -> Self {
        Self {
            state: seed.wrapping_mul(0xD1B5_4A32_D192_ED03) ^ 0x2545_F491_4F6C_DD1D,
            spare: None,
        }
    }
    fn next_u64(&mut self) -> u64 {
        self.state = self.state.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.state;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^ (z >> 31)
    }
    /// Uniform on (0, 1).
    pub fn uniform(&mut self) -> f64 {
        ((self.next_u64() >> 11) as f64 + 0.5) / (1u64 << 53) as f64
    }
    pub fn normal(&mut self) -> f64 {
        if let Some(s) = self.spare.take() {
            return s;
        }
        let (u1, u2) = (self.uniform(), self.uniform());
        let r = (-2.0 * u1.ln()).sqrt();
        let a = std::f64::consts::TAU * u2;
        self.spare = Some(r * a.sin());
        r * a.cos()
    }
}

/// Flicker rate noise of one-sided PSD `h / f` as sub-sample point values
/// (period `dt`), `len` of them.
fn flicker(h: f64, len: usize, dt: f64, rng: &mut Rng) -> Vec<f64> {
    let nfft = (len * EXTEND).max(8) & !1;
    let mut spec: Vec<Complex<f64>> = vec![Complex::new(0.0, 0.0); nfft / 2 + 1];
    for (k, c) in spec.iter_mut().enumerate().skip(1) {
        let f = k as f64 / (nfft as f64 * dt);
        // E|X_k|^2 = N S(f) / (2 dt); real and imaginary parts each half.
        let s = (nfft as f64 * h / f / (4.0 * dt)).sqrt();
        *c = if k == nfft / 2 {
            Complex::new(s * std::f64::consts::SQRT_2 * rng.normal(), 0.0)
        } else {
            Complex::new(s * rng.normal(), s * rng.normal())
        };
    }
    let mut out = vec![0.0; nfft];
    let ifft = RealFftPlanner::<f64>::new().plan_fft_inverse(nfft);
    if ifft.process(&mut spec, &mut out).is_err() {
        return vec![0.0; len];
    }
    // A random stretch of the longer record.
    let start = ((rng.uniform() * (nfft - len) as f64) as usize).min(nfft - len);
    out[start..start + len]
        .iter()
        .map(|v| v / nfft as f64)
        .collect()
}

/// `n` samples every `tau0` s of the terms of `truth`, deg/s. Quantization
/// (`truth.laws[0]` > 0) quantizes the accumulated angle of everything
/// else.
pub fn record(truth: &Truth, n: usize, tau0: f64, seed: u64) -> Vec<f64> {
    let mut rng = Rng::new(seed);
    let [q_arcsec, n_dpsh, b_dph, k_dphsh, r_dphh] = truth.laws;
    let n_dps = n_dpsh / 60.0;
    let k_dps = k_dphsh / 3600.0 / 60.0;
    let r_dps2 = r_dphh / 3600.0 / 3600.0;
    let dt = tau0 / SUB as f64;
    let mut y: Vec<f64> = (0..n).map(|_| n_dps / tau0.sqrt() * rng.normal()).collect();
    // Sub-sampled terms, averaged per sample.
    let mut sub = vec![0.0; n * SUB];
    if b_dph > 0.0 {
        let b = b_dph / 3600.0;
        let fl = flicker(b * b / std::f64::consts::PI, n * SUB, dt, &mut rng);
        sub.iter_mut().zip(&fl).for_each(|(s, v)| *s += v);
    }
    if let Some((sigma_dph, t)) = truth.markov {
        let sigma = sigma_dph / 3600.0;
        let phi = (-dt / t).exp();
        let e = sigma * (1.0 - phi * phi).sqrt();
        let mut x = sigma * rng.normal();
        for s in sub.iter_mut() {
            *s += x;
            x = phi * x + e * rng.normal();
        }
    }
    if k_dps > 0.0 {
        let step = k_dps * dt.sqrt();
        let mut w = 0.0;
        let half = step * std::f64::consts::FRAC_1_SQRT_2;
        for s in sub.iter_mut() {
            // The walk at the sub-sample's middle, then at its end.
            let mid = w + half * rng.normal();
            *s += mid;
            w = mid + half * rng.normal();
        }
    }
    for (k, v) in y.iter_mut().enumerate() {
        *v += sub[k * SUB..(k + 1) * SUB].iter().sum::<f64>() / SUB as f64;
        *v += r_dps2 * (k as f64 + 0.5) * tau0;
    }
    if let Some((amp_dph, f)) = truth.sinusoid {
        let a = amp_dph / 3600.0;
        let phi = std::f64::consts::TAU * rng.uniform();
        let w = std::f64::consts::TAU * f;
        for (k, v) in y.iter_mut().enumerate() {
            let (t0, t1) = (k as f64 * tau0, (k + 1) as f64 * tau0);
            *v += a * ((w * t0 + phi).cos() - (w * t1 + phi).cos()) / (w * tau0);
        }
    }
    if q_arcsec > 0.0 {
        let quantum = q_arcsec / 3600.0 * 12f64.sqrt();
        // The dither's span, in quanta (any whole number leaves the error
        // uniform over one quantum).
        const DITHER_QUANTA: f64 = 8.0;
        let mut dither = || rng.uniform() * DITHER_QUANTA * quantum;
        // The counter's phase at the start is arbitrary.
        let mut angle = 0.0;
        let d = dither();
        let mut last = ((angle + d) / quantum).floor() * quantum - d;
        for v in y.iter_mut() {
            angle += *v * tau0;
            let d = dither();
            let read = ((angle + d) / quantum).floor() * quantum - d;
            *v = (read - last) / tau0;
            last = read;
        }
    }
    y
}

/// The power laws alone (no sinusoid, no Markov term).
pub fn record_laws(laws: &[f64; COUNT], n: usize, tau0: f64, seed: u64) -> Vec<f64> {
    record(&Truth::laws(*laws), n, tau0, seed)
}
