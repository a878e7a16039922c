//! The second generator's noise: its own random numbers (Box-Muller
//! normals on xoshiro256**), white noise, flicker by spectral synthesis,
//! rate random walk, first-order Markov noise, angle quantization and
//! spikes.

use rand_core::{RngCore, SeedableRng};
use rand_xoshiro::Xoshiro256StarStar;
use realfft::RealFftPlanner;

/// The generator's random numbers (Box-Muller normals).
pub struct Rng(pub Xoshiro256StarStar);

impl Rng {
    pub fn new(seed: u64) -> Self {
        Self(Xoshiro256StarStar::seed_from_u64(
            seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) ^ 0x51_7CC1,
        ))
    }
    pub fn u(&mut self) -> f64 {
        ((self.0.next_u64() >> 11) as f64 + 0.5) / (1u64 << 53) as f64
    }
    pub fn range(&mut self, a: f64, b: f64) -> f64 {
        a + (b - a) * self.u()
    }
    pub fn pm(&mut self, a: f64, b: f64) -> f64 {
        let v = self.range(a, b);
        if self.u() < 0.5 {
            -v
        } else {
            v
        }
    }
    pub fn normal(&mut self) -> f64 {
        let (a, b) = (self.u(), self.u());
        (-2.0 * a.ln()).sqrt() * (std::f64::consts::TAU * b).cos()
    }
}

/// The noise of a run.
#[derive(Clone, Copy, Debug)]
pub struct Noise {
    /// White rate, deg/sqrt(h).
    pub arw_dpsh: f64,
    /// Flicker by spectral synthesis, deg/h (Allan floor 0.664 B).
    pub flicker_dph: f64,
    /// Rate random walk, deg/h/sqrt(h).
    pub rrw_dphsh: f64,
    /// First-order Markov: sigma deg/h, correlation time s.
    pub markov: (f64, f64),
    /// Angle quantization, arcsec.
    pub quant_arcsec: f64,
    /// Spikes: how many, and their size, deg/h.
    pub spikes: (usize, f64),
}

impl Noise {
    pub fn describe(&self) -> String {
        format!(
            "white {} deg/sqrt(h), flicker {} deg/h, random walk {} deg/h/sqrt(h), Markov {} deg/h over {} s, quantization {} arcsec, {} spike(s)",
            self.arw_dpsh, self.flicker_dph, self.rrw_dphsh, self.markov.0, self.markov.1, self.quant_arcsec, self.spikes.0
        )
    }
}

/// Flicker noise of two-sided PSD B^2/(2 pi f) (deg/s, B in deg/s) by
/// spectral synthesis: Gaussian Fourier coefficients of variance
/// N S(f)/dt, the lowest frequency the record's.
pub fn flicker(rng: &mut Rng2, n: usize, dt: f64, b: f64) -> Vec<f64> {
    if b <= 0.0 || n < 4 {
        return vec![0.0; n];
    }
    let m = 2 * n;
    let mut planner = RealFftPlanner::<f64>::new();
    let inv = planner.plan_fft_inverse(m);
    let mut spec = inv.make_input_vec();
    let df = 1.0 / (m as f64 * dt);
    for (j, c) in spec.iter_mut().enumerate() {
        if j == 0 || j == m / 2 {
            continue;
        }
        let f = j as f64 * df;
        let s = b * b / (2.0 * std::f64::consts::PI * f);
        let sd = (m as f64 * s / dt / 2.0).sqrt();
        *c = num_complex::Complex::new(sd * rng.normal(), sd * rng.normal());
    }
    let mut out = inv.make_output_vec();
    if inv.process(&mut spec, &mut out).is_err() {
        return vec![0.0; n];
    }
    out.truncate(n);
    out.iter().map(|v| v / m as f64).collect()
}

/// The generator's random numbers, for the noise helpers.
pub struct Rng2(Rng);

impl Rng2 {
    pub fn new(seed: u64) -> Self {
        Self(Rng::new(seed))
    }
    pub fn normal(&mut self) -> f64 {
        self.0.normal()
    }
}

/// The noise series, deg/s, for rows `t` (every `dt`).
pub fn noise_series(nz: &Noise, n: usize, dt: f64, seed: u64) -> Vec<f64> {
    let mut r2 = Rng2::new(seed ^ 0xF11C);
    let fl = flicker(&mut r2, n, dt, nz.flicker_dph / 3600.0);
    let rng = &mut r2.0;
    let (mut rw, mut mk, mut angle, mut q_prev) = (0.0, 0.0, 0.0, 0.0);
    let (ms, mt) = (nz.markov.0 / 3600.0, nz.markov.1.max(1e-9));
    let phi = (-dt / mt).exp();
    let q = nz.quant_arcsec / 3600.0;
    let mut out = Vec::with_capacity(n);
    for k in 0..n {
        let white = nz.arw_dpsh / 60.0 / dt.sqrt() * rng.normal();
        let step = nz.rrw_dphsh / 3600.0 / 60.0 * dt.sqrt() * rng.normal();
        let rw_mean = rw + 0.5 * step;
        rw += step;
        mk = phi * mk + ms * (1.0 - phi * phi).sqrt() * rng.normal();
        let mut v = white + rw_mean + mk + fl[k];
        if q > 0.0 {
            angle += v * dt;
            let qa = (angle / q).round() * q;
            v = (qa - q_prev) / dt;
            q_prev = qa;
        }
        out.push(v);
    }
    for _ in 0..nz.spikes.0 {
        let k = (rng.u() * n as f64) as usize % n.max(1);
        out[k] += nz.spikes.1 / 3600.0 / dt.max(1.0);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use gyro_lab_core::noise::adev::oavar;

    #[test]
    fn synthesized_flicker_has_the_flat_allan_floor() {
        // Allan variance of flicker: (2 ln 2/pi) B^2 at every tau well
        // inside the record; the mean over several records within 15 %.
        let (n, dt, b) = (1 << 16, 1.0, 1e-3);
        let ms = [4usize, 16, 64, 256, 1024];
        let mut acc = [0.0; 5];
        for s in 0..8 {
            let mut r = Rng2::new(s);
            let x = flicker(&mut r, n, dt, b);
            for (a, v) in acc.iter_mut().zip(oavar(&x, &ms)) {
                *a += v / 8.0;
            }
        }
        let want = 2.0 * std::f64::consts::LN_2 / std::f64::consts::PI * b * b;
        for (m, a) in ms.iter().zip(acc) {
            assert!((a / want - 1.0).abs() < 0.15, "m {m}: {a} vs {want}");
        }
    }
}
