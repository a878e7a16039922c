//! The check of the dithered gyro's integration: the plain equation by
//! brute force.

use super::motion::{DitherMotion, Half};
use super::DitherParams;
use super::Latch;
use core::f64::consts::PI;
// f64's methods on the no_std target (the host also has them inherent).
#[allow(unused_imports)]
use num_traits::float::Float;
use rand_core::SeedableRng;
use rand_distr::{Distribution, StandardUniform};
use rand_xoshiro::Xoshiro256PlusPlus;

/// The plain lock-in equation `dF/dt = K_fr (Omega + theta_d') - K_fr
/// Omega_L sin(2 pi F + beta)` by fixed-step RK4 (`steps_per_rad` per
/// radian of fringe phase at the largest rate), the same dither drawn from
/// the same seed: the check of [`DitheredRlg`] on short records.
pub struct BruteForce {
    p: DitherParams,
    motion: DitherMotion,
    cur: Half,
    t: f64,
    f: f64,
    h: f64,
}

impl BruteForce {
    pub fn new(p: DitherParams, max_rate_dps: f64, steps_per_rad: f64) -> Self {
        let motion = DitherMotion::new(&p);
        let mut pd_rng = Xoshiro256PlusPlus::seed_from_u64(p.seed ^ 0x5EED_F00D_CAFE);
        let f0: f64 = StandardUniform.sample(&mut pd_rng);
        let cur = motion.current();
        let w = 2.0 * PI * p.fringes_per_deg() * max_rate_dps;
        Self {
            p,
            motion,
            cur,
            t: 0.0,
            f: f0 + p.fringes_per_deg() * cur.theta_at(0.0),
            h: 1.0 / (w * steps_per_rad),
        }
    }

    /// Advances to `t_end` at input rate `rate_dps`; `on_latch` gets the
    /// zero crossings (counts and truth only).
    pub fn advance(&mut self, t_end: f64, rate_dps: f64, mut on_latch: impl FnMut(&Latch)) -> f64 {
        let k = self.p.fringes_per_deg();
        let kappa = k * self.p.lock_in_dps;
        let beta = self.p.beta_rad;
        while self.t < t_end {
            let latch_t = self.cur.zero_crossing() + self.p.pickoff_delay_s;
            let stop = self.cur.end().min(t_end).min(if latch_t > self.t {
                latch_t
            } else {
                f64::INFINITY
            });
            // Whole steps to `stop`, the last one shortened.
            let n = ((stop - self.t) / self.h).ceil().max(1.0) as u64;
            let dt = (stop - self.t) / n as f64;
            let hc = self.cur;
            let rhs = |t: f64, f: f64| {
                let s = ((t - hc.t0) / hc.h).clamp(0.0, 1.0);
                k * (rate_dps + hc.rate(s)) - kappa * (2.0 * PI * f + beta).sin()
            };
            for _ in 0..n {
                let t = self.t;
                let k1 = rhs(t, self.f);
                let k2 = rhs(t + 0.5 * dt, self.f + 0.5 * dt * k1);
                let k3 = rhs(t + 0.5 * dt, self.f + 0.5 * dt * k2);
                let k4 = rhs(t + dt, self.f + dt * k3);
                self.f += dt / 6.0 * (k1 + 2.0 * (k2 + k3) + k4);
                self.t += dt;
            }
            self.t = stop;
            if stop == latch_t {
                let counts = (4.0 * self.f).floor() as i64;
                let truth = 4.0 * (self.f - k * hc.theta_at(self.t));
                on_latch(&Latch {
                    t_s: self.t,
                    counter: counts as u16,
                    counts,
                    rising: hc.sign > 0.0,
                    photodiodes: [0, 0],
                    truth_counts: truth,
                });
            }
            if self.t >= self.cur.end() {
                self.cur = self.motion.next_half();
            }
        }
        self.f
    }
}
