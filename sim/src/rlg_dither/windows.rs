//! The crossing windows: where in a half cycle the lock-in equation is
//! integrated finely (the module's notes).

use super::motion::{g, Half};
use super::trig::sin_small;
use core::f64::consts::PI;
use num_traits::float::Float;

#[derive(Clone, Copy, Debug, Default)]
pub(super) struct Windows {
    pub(super) valid: bool,
    pub(super) rate: f64,
    pub(super) n: usize,
    pub(super) iv: [(f64, f64); 2],
}

impl Windows {
    /// Whether fraction s is in a fine interval, and where the current
    /// interval (fine or not) ends.
    pub(super) fn at(&self, s: f64) -> (bool, f64) {
        let mut next = 1.0;
        for &(a, b) in &self.iv[..self.n] {
            // An interval that ends at the turnaround holds to it (s may
            // pass 1 by rounding there).
            if s >= a && (s < b || b >= 1.0) {
                return (true, b);
            }
            if a > s {
                next = next.min(a);
            }
        }
        (false, next)
    }
}

/// The fine intervals of a half cycle at input rate `rate`: where
/// `|rate + sign g(s)| < w`.
pub(super) fn find_windows<F: Float>(
    hc: &Half,
    rate: f64,
    w: f64,
    lock_in: bool,
    fast: bool,
) -> Windows {
    let mut out = Windows {
        valid: true,
        rate,
        n: 0,
        iv: [(0.0, 0.0); 2],
    };
    if !lock_in {
        return out;
    }
    // g(s) = r -/+ w bounds the window; r is where Omega_I = 0.
    let r = -hc.sign * rate;
    let (lo, hi) = (r - w, r + w);
    let (abar, d) = (hc.abar(), hc.d());
    let c_peak = if d.abs() > 1e-15 * abar.abs() {
        (abar - (abar * abar + 8.0 * d * d).sqrt()) / (4.0 * d)
    } else {
        0.0
    };
    let s_peak = c_peak.clamp(-1.0, 1.0).acos() / PI;
    let g_max = g(hc, s_peak);
    let solve = |level: f64, a: f64, b: f64| {
        if fast {
            solve_fast::<F>(hc, level, a, b)
        } else {
            solve(hc, level, a, b)
        }
    };
    if hi <= 0.0 || lo >= g_max {
        return out;
    }
    // {g < hi} = [0, a_hi) u (b_hi, 1] (or all); {g > lo} = (a_lo, b_lo) (or all).
    let (a_hi, b_hi) = if hi >= g_max {
        (s_peak, s_peak)
    } else {
        (solve(hi, 0.0, s_peak), solve(hi, s_peak, 1.0))
    };
    let (a_lo, b_lo) = if lo <= 0.0 {
        (0.0, 1.0)
    } else {
        (solve(lo, 0.0, s_peak), solve(lo, s_peak, 1.0))
    };
    if a_hi > a_lo {
        out.iv[out.n] = (a_lo, a_hi);
        out.n += 1;
    }
    if b_lo > b_hi && out.n < 2 {
        if out.n == 1 && out.iv[0].1 >= b_hi {
            // One interval across the peak.
            out.iv[0].1 = b_lo;
        } else {
            out.iv[out.n] = (b_hi, b_lo);
            out.n += 1;
        }
    }
    out
}

/// s in [a, b] with g(s) = level, g monotone there (bisection).
pub(super) fn solve(hc: &Half, level: f64, a: f64, b: f64) -> f64 {
    let rising = g(hc, b) > g(hc, a);
    let (mut lo, mut hi) = (a, b);
    for _ in 0..48 {
        let m = 0.5 * (lo + hi);
        if (g(hc, m) < level) == rising {
            lo = m;
        } else {
            hi = m;
        }
    }
    0.5 * (lo + hi)
}

/// The same in the inner loops' float with [`sin_small`] (`Accuracy::
/// fast_trig`): 30 halvings reach f32's resolution (the edges then to
/// 1e-7 of a half cycle, a tenth of a nanosecond; where a window begins
/// matters only to where the transform holds, far inside its bounds).
pub(super) fn solve_fast<F: Float>(hc: &Half, level: f64, a: f64, b: f64) -> f64 {
    let c = |x: f64| F::from(x).unwrap_or(F::zero());
    let (k, abar, d, pi, half_pi) = (c(PI / hc.h), c(hc.abar()), c(hc.d()), c(PI), c(0.5 * PI));
    let g = |s: F| {
        let x = pi * s;
        k * sin_small(x) * (abar - d * sin_small(x + half_pi))
    };
    let level = c(level);
    let (mut lo, mut hi) = (c(a), c(b));
    let rising = g(hi) > g(lo);
    let half = c(0.5);
    for _ in 0..30 {
        let m = half * (lo + hi);
        if (g(m) < level) == rising {
            lo = m;
        } else {
            hi = m;
        }
    }
    (half * (lo + hi)).to_f64().unwrap_or(0.5 * (a + b))
}
