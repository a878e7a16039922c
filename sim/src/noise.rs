//! Gyro rate-noise generators with the IEEE 952 terms (docs/noise.md), each
//! set by the coefficient the Allan deviation shows:
//!
//! | term | parameter | Allan variance |
//! |---|---|---|
//! | angle quantization | `q_deg` (Q, deg) | 3 Q^2 / tau^2 |
//! | angle random walk | `n_dps_rts` (N, deg/s per sqrt(Hz), i.e. deg/sqrt(s)) | N^2 / tau |
//! | bias instability | `b_dps` (B, deg/s) | (2 ln 2 / pi) B^2 (flat) |
//! | rate random walk | `k_dps_rts` (K, deg/s/sqrt(s)) | K^2 tau / 3 |
//! | rate ramp | `r_dps2` (R, deg/s^2) | R^2 tau^2 / 2 |
//!
//! Each sample is the mean rate over one sample period dt (what a gyro's
//! angle increments give), so white noise has sigma N/sqrt(dt). Angle
//! quantization is the white angle error a quantizer leaves when the angle
//! crosses many quanta per sample (or is dithered): uniform, of width
//! S = Q sqrt(12), independent from sample to sample. Flicker noise
//! (two-sided PSD B^2/(2 pi f), IEEE 952) is a sum of Ornstein-Uhlenbeck
//! processes with correlation times spaced by r = 10^(1/3) from dt/1000 to
//! `flicker_max_tau_s`: Lorentzians of equal variance sigma^2 spaced by r
//! sum to sigma^2/(2 f ln r), so sigma^2 = B^2 ln(r)/pi. Each process is
//! advanced exactly and its exact mean over the period drawn jointly with
//! its end value, so the floor is flat down to tau = dt.

#[allow(unused_imports)] // f64 maths comes from libm where core lacks it
use num_traits::float::Float;
use rand_core::SeedableRng;
use rand_distr::{Distribution, StandardNormal};
use rand_xoshiro::Xoshiro256PlusPlus;

/// Most processes of the flicker sum (3 per decade: 16 decades).
pub const MAX_FLICKER: usize = 48;

#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct NoiseParams {
    pub q_deg: f64,
    pub n_dps_rts: f64,
    pub b_dps: f64,
    pub k_dps_rts: f64,
    pub r_dps2: f64,
    /// Longest correlation time of the flicker sum, s (the floor holds to
    /// about this averaging time).
    pub flicker_max_tau_s: f64,
}

/// Unit conversions from the usual datasheet units.
impl NoiseParams {
    /// N from deg/sqrt(h).
    pub fn arw_from_dpsh(n: f64) -> f64 {
        n / 60.0
    }
    /// B from deg/h.
    pub fn b_from_dph(b: f64) -> f64 {
        b / 3600.0
    }
    /// K from deg/h/sqrt(h).
    pub fn k_from_dphsh(k: f64) -> f64 {
        k / 3600.0 / 60.0
    }
}

pub struct RateNoise {
    p: NoiseParams,
    dt: f64,
    rng: Xoshiro256PlusPlus,
    /// Flicker: the processes' states, their step coefficient phi, the
    /// mean's dependence on the start (T/dt (1 - phi)) and the Cholesky
    /// factor of the (end, mean) innovations.
    fl_x: [f64; MAX_FLICKER],
    fl_phi: [f64; MAX_FLICKER],
    fl_g: [f64; MAX_FLICKER],
    fl_l: [[f64; 3]; MAX_FLICKER],
    fl_n: usize,
    /// Last angle-quantization error, deg.
    q_prev: f64,
    rrw: f64,
    t: f64,
}

impl RateNoise {
    /// Noise for samples of period `dt_s`.
    pub fn new(p: NoiseParams, dt_s: f64, seed: u64) -> Self {
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed);
        let mut s = Self {
            p,
            dt: dt_s,
            rng: Xoshiro256PlusPlus::seed_from_u64(0),
            fl_x: [0.0; MAX_FLICKER],
            fl_phi: [0.0; MAX_FLICKER],
            fl_g: [0.0; MAX_FLICKER],
            fl_l: [[0.0; 3]; MAX_FLICKER],
            fl_n: 0,
            q_prev: 0.0,
            rrw: 0.0,
            t: 0.0,
        };
        if p.b_dps > 0.0 {
            let r: f64 = 10f64.powf(1.0 / 3.0);
            let var = p.b_dps * p.b_dps * r.ln() / core::f64::consts::PI;
            let h = dt_s;
            let mut tau = dt_s * 1e-3;
            while s.fl_n < MAX_FLICKER && tau <= p.flicker_max_tau_s.max(dt_s) {
                // OU over one period from x0: end = phi x0 + e1, mean =
                // g x0 + e2, with
                // var e1 = v (1 - phi^2),
                // var e2 = v (T/h)^2 (2h/T - 3 + 4 phi - phi^2),
                // cov = v (T/h) (1 - phi)^2.
                let phi = (-h / tau).exp();
                let a = tau / h;
                let v11 = var * (1.0 - phi * phi);
                let v22 = var * a * a * (2.0 / a - 3.0 + 4.0 * phi - phi * phi);
                let v12 = var * a * (1.0 - phi) * (1.0 - phi);
                let l11 = v11.max(0.0).sqrt();
                let l21 = if l11 > 0.0 { v12 / l11 } else { 0.0 };
                let l22 = (v22 - l21 * l21).max(0.0).sqrt();
                let k = s.fl_n;
                s.fl_phi[k] = phi;
                s.fl_g[k] = a * (1.0 - phi);
                s.fl_l[k] = [l11, l21, l22];
                // Start in the stationary state.
                let z: f64 = StandardNormal.sample(&mut rng);
                s.fl_x[k] = var.sqrt() * z;
                s.fl_n += 1;
                tau *= r;
            }
        }
        s.rng = rng;
        s
    }

    fn normal(&mut self) -> f64 {
        StandardNormal.sample(&mut self.rng)
    }

    /// The next sample's rate noise, deg/s (mean over the sample period).
    pub fn sample(&mut self) -> f64 {
        let p = self.p;
        let dt = self.dt;
        let mut rate = p.n_dps_rts / dt.sqrt() * self.normal();
        for k in 0..self.fl_n {
            let (z1, z2) = (self.normal(), self.normal());
            let [l11, l21, l22] = self.fl_l[k];
            let x0 = self.fl_x[k];
            rate += self.fl_g[k] * x0 + l21 * z1 + l22 * z2;
            self.fl_x[k] = self.fl_phi[k] * x0 + l11 * z1;
        }
        // Rate random walk: the mean over the period of a Wiener process
        // (its start plus a step of K*sqrt(dt) whose mean over the period
        // has a third of its variance beyond the start).
        let w1 = self.normal();
        let w2 = self.normal();
        let step = p.k_dps_rts * dt.sqrt();
        let mean_rrw = self.rrw + step * (0.5 * w1 + w2 / 12f64.sqrt());
        self.rrw += step * w1;
        rate += mean_rrw;
        rate += p.r_dps2 * (self.t + 0.5 * dt);
        self.t += dt;
        if p.q_deg > 0.0 {
            // White angle error of variance Q^2: uniform over S = Q sqrt(12).
            let u: f64 = rand_distr::StandardUniform.sample(&mut self.rng);
            let e = (u - 0.5) * p.q_deg * 12f64.sqrt();
            rate += (e - self.q_prev) / dt;
            self.q_prev = e;
        }
        rate
    }
}
