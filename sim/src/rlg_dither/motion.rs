//! The dither's motion: half cycles from turnaround to turnaround, their
//! amplitudes drawn at each turnaround (the module's notes).

use super::DitherParams;
use core::f64::consts::PI;
// f64's methods on the no_std target (the host also has them inherent).
#[allow(unused_imports)]
use num_traits::float::Float;
use rand_core::SeedableRng;
use rand_distr::{Distribution, StandardNormal};
use rand_xoshiro::Xoshiro256PlusPlus;

/// One half cycle of the dither, turnaround to turnaround.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Half {
    /// Start (a turnaround), s, and length, s.
    pub t0: f64,
    pub h: f64,
    /// Amplitudes at the start and end turnarounds, deg.
    pub a0: f64,
    pub a1: f64,
    /// Sign of the dither rate on this half cycle.
    pub sign: f64,
}

impl Half {
    pub fn end(&self) -> f64 {
        self.t0 + self.h
    }
    pub(super) fn abar(&self) -> f64 {
        0.5 * (self.a0 + self.a1)
    }
    pub(super) fn d(&self) -> f64 {
        self.a1 - self.a0
    }
    /// Dither angle at fraction s, deg.
    pub fn theta(&self, s: f64) -> f64 {
        let c = (PI * s).cos();
        -self.sign * (self.abar() * c - 0.5 * self.d() * c * c)
    }
    /// Dither rate at fraction s, deg/s (the magnitude `g(s)` times sign).
    pub fn rate(&self, s: f64) -> f64 {
        self.sign * g(self, s)
    }
    /// Dither angular acceleration at fraction s, deg/s^2.
    pub fn accel(&self, s: f64) -> f64 {
        let (sn, cs) = (PI * s).sin_cos();
        let k = PI / self.h;
        self.sign * k * k * (cs * (self.abar() - self.d() * cs) + self.d() * sn * sn)
    }
    /// Dither angle at time t (within or at the ends of the half), deg.
    pub fn theta_at(&self, t: f64) -> f64 {
        self.theta_x(t - self.t0)
    }
    /// Dither angle at time x since the half's start, deg.
    pub fn theta_x(&self, x: f64) -> f64 {
        self.theta((x / self.h).clamp(0.0, 1.0))
    }
    /// Pickoff zero crossing (the angle's), s.
    pub fn zero_crossing(&self) -> f64 {
        self.t0 + 0.5 * self.h
    }
}

/// |dither rate| on a half cycle at fraction s, deg/s.
pub(super) fn g(hc: &Half, s: f64) -> f64 {
    let (sn, cs) = (PI * s).sin_cos();
    PI / hc.h * sn * (hc.abar() - hc.d() * cs)
}

/// The dither's half cycles, drawn one after another (the fast simulator
/// and the brute force draw the same ones from the same seed).
#[derive(Clone, Debug)]
pub struct DitherMotion {
    amp: f64,
    p: DitherParams,
    rng: Xoshiro256PlusPlus,
    cur: Half,
}

impl DitherMotion {
    pub fn new(p: &DitherParams) -> Self {
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(p.seed);
        let amp = p.amplitude_deg();
        let a0 = draw_amplitude(&mut rng, amp, p.noise_frac);
        let a1 = draw_amplitude(&mut rng, amp, p.noise_frac);
        // The record starts a quarter of a period before the first
        // turnaround's half cycle ends: at a random phase would do as well.
        let h = half_length(p, 0.0);
        Self {
            amp,
            p: *p,
            rng,
            cur: Half {
                t0: -0.25 * h,
                h,
                a0,
                a1,
                sign: 1.0,
            },
        }
    }
    pub fn current(&self) -> Half {
        self.cur
    }
    /// The half cycle after the current one becomes current.
    pub fn next_half(&mut self) -> Half {
        let t0 = self.cur.end();
        self.cur = Half {
            t0,
            h: half_length(&self.p, t0),
            a0: self.cur.a1,
            a1: draw_amplitude(&mut self.rng, self.amp, self.p.noise_frac),
            sign: -self.cur.sign,
        };
        self.cur
    }
}

pub(super) fn draw_amplitude(rng: &mut Xoshiro256PlusPlus, amp: f64, noise: f64) -> f64 {
    let z: f64 = StandardNormal.sample(rng);
    amp * (1.0 + noise * z.clamp(-4.0, 4.0))
}

pub(super) fn half_length(p: &DitherParams, t: f64) -> f64 {
    let f = p.dither_hz
        * (1.0 + p.fd_drift_frac * (2.0 * PI * t / p.fd_drift_period_s.max(1e-3)).sin());
    0.5 / f
}
