//! Filtered differentiator of a temperature, `s/(1 + tau*s)`, run at the
//! sensor rate in fixed point: input Q8 degC, output Q32 degC/s (a Q16
//! state's truncation biased the RLG gradient term by 0.03 deg/h).
//!
//! Each update takes the slope over the last sensor period (clamped to
//! +-8 degC/s: anything faster is a bad read, not heat) and moves the output
//! towards it by `dt/(tau + dt)`. An invalid input (a sensor flagged bad)
//! feeds slope 0, so the output decays instead of jumping on held values.

#[allow(unused_imports)] // f64 maths comes from libm where core lacks it
use num_traits::float::Float;

/// Slope clamp, Q32 degC/s.
const SLOPE_LIMIT_Q32: i64 = 8 << 32;

/// Immutable weights for one sensor period and time constant.
#[derive(Clone, Copy, Debug)]
pub struct DerivativeConfig {
    /// 1/dt in Q16 per s.
    inv_dt_q16: i64,
    /// dt/(tau + dt), Q30.
    a_q30: i64,
}

impl DerivativeConfig {
    /// `dt_s`: sensor period (1 ms .. 100 s; non-finite or non-positive
    /// periods count as 1 s). `tau_s`: filter time constant, at least
    /// 15 periods (the update's headroom needs dt/(tau + dt) < 2^-4).
    pub fn new(dt_s: f64, tau_s: f64) -> Self {
        let dt = if dt_s.is_finite() && dt_s > 1e-3 {
            dt_s.min(100.0)
        } else {
            1.0
        };
        let tau = if tau_s.is_finite() { tau_s } else { 0.0 }.max(15.0 * dt);
        Self {
            inv_dt_q16: (65_536.0 / dt).round() as i64,
            a_q30: (dt / (tau + dt) * (1u64 << 30) as f64).round() as i64,
        }
    }
}

#[derive(Clone, Copy, Debug, Default)]
pub struct Derivative {
    prev_q8: Option<i32>,
    out_q32: i64,
}

impl Derivative {
    /// One sensor update with input `x_q8` (|x| < 2^16); returns the filtered
    /// derivative, Q32 degC/s.
    #[inline(always)]
    pub fn update(&mut self, cfg: &DerivativeConfig, x_q8: i32, valid: bool) -> i64 {
        // |x - p| < 2^17, 1/dt < 2^26 (Q16, dt >= 1 ms): the slope < 2^51.
        let slope_q32 = match self.prev_q8 {
            Some(p) if valid => ((x_q8 as i64 - p as i64) * cfg.inv_dt_q16) << 8,
            _ => 0,
        }
        .clamp(-SLOPE_LIMIT_Q32, SLOPE_LIMIT_Q32);
        self.prev_q8 = Some(x_q8);
        // The output is a running mean of clamped slopes: |slope - out| <=
        // 2^36, a < 2^26: the product below 2^62. Rounded shift.
        const HALF: i64 = 1 << 29;
        self.out_q32 += ((slope_q32 - self.out_q32) * cfg.a_q30 + HALF) >> 30;
        self.out_q32
    }

    /// The last output, Q32 degC/s.
    pub fn value_q32(&self) -> i64 {
        self.out_q32
    }
}
