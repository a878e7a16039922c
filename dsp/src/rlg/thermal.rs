//! Thermal bias compensation (docs/rlg.md), fixed point:
//! `B_TC = bias0 + K1*dT + K2*grad(dT) + K3*dT^2 + K4*T_K + K5*F(tau)`.
//!
//! Formats:
//! - temperatures: i32, Q8 degC (1/256 degC; TMP117's LSB is 1/128 degC);
//! - dT = T_a - T_b: Q8 degC; grad(dT): Q32 degC/s (state precision: a Q16
//!   state's truncation biased the term by 0.03 deg/h) from a filtered
//!   differentiator `s/(1 + tau_g*s)` (tau_g = 20 s) run at the sensor rate,
//!   its input clamped to +-8 degC/s;
//! - F(tau) = 1 - exp(-t/tau_warm): Q30, advanced recursively
//!   (`F += a*(1 - F)`, a = 1 - exp(-dt/tau_warm)), no exp on the target;
//! - coefficients: Q24 deg/h per unit (Q16 cost 3e-4 deg/h on K4*T_K at
//!   40 degC); every term and B_TC: Q16 deg/h in i64. |coeff| <= 1e3 (2^34 in
//!   Q24), |dT| clamped to 32 degC and temperatures within -55..150 degC keep
//!   every product below 2^61.
//!
//! Sensor faults ([`crate::sensor`]): a failed, implausible or stuck read
//! marks that sensor bad; the compensation then holds that sensor's last
//! good value (and the gradient decays to 0), and the flag stays up while it
//! lasts.

use super::coeffs::ThermalCoeffs;
use crate::derivative::{Derivative, DerivativeConfig};
use crate::sensor::SensorHold;
pub use crate::sensor::STUCK_READS;
#[allow(unused_imports)] // f64 maths comes from libm where core lacks it
use num_traits::float::Float;

/// Gradient filter time constant, s.
pub const GRAD_TAU_S: f64 = 20.0;

/// One set of sensor reads, Q8 degC; `None`: the read failed.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Temperatures {
    pub mono_a_q8: Option<i32>,
    pub mono_b_q8: Option<i32>,
    pub case_q8: Option<i32>,
}

bitflags::bitflags! {
    /// Fault bits of the RLG thermal channel (frame byte 60).
    #[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
    pub struct RlgFlags: u8 {
        /// Monoblock sensor A bad: its last good value held.
        const SENSOR_A = 1 << 0;
        /// Monoblock sensor B bad: its last good value held.
        const SENSOR_B = 1 << 1;
        /// Case sensor bad: its last good value held.
        const SENSOR_CASE = 1 << 2;
        /// The stored coefficients were refused: running on `ThermalCoeffs::SAFE`.
        const COEFFS_DEFAULT = 1 << 3;
        /// Dithered gyro: no pickoff latch after the frame's instant, the
        /// raw counter (dither included) stood in; or crossings were missed.
        const NO_PICKOFF = 1 << 4;
        /// Dithered gyro: a pickoff edge refused as implausible, or the
        /// photodiodes too weak to place a latch within its count.
        const LATCH_REFUSED = 1 << 5;
    }
}

/// Immutable fixed-point form of the coefficients for one sensor update period.
#[derive(Clone, Copy, Debug)]
pub struct ThermalConfig {
    bias0_q24: i64,
    k1_q24: i64,
    k2_q24: i64,
    k3_q24: i64,
    k4_q24: i64,
    k5_q24: i64,
    /// The dT gradient's differentiator.
    grad: DerivativeConfig,
    /// Warm-up step 1 - exp(-dt/tau_warm), Q30.
    warm_a_q30: i64,
    pub coeffs_default: bool,
}

impl ThermalConfig {
    /// `dt_s`: sensor update period. Refused coefficients fall back to SAFE.
    pub fn new(c: &ThermalCoeffs, dt_s: f64) -> Self {
        let (c, coeffs_default) = match c.check() {
            Ok(()) => (*c, false),
            Err(_) => (ThermalCoeffs::SAFE, true),
        };
        // Sensor period 1 ms .. 1 s (the gradient filter's headroom assumes it).
        let dt = if dt_s.is_finite() && dt_s > 1e-3 {
            dt_s.min(1.0)
        } else {
            1.0
        };
        let q24 = |x: f64| (x * 16_777_216.0).round() as i64;
        let q30 = |x: f64| (x * (1u64 << 30) as f64).round() as i64;
        Self {
            bias0_q24: q24(c.bias0_dph),
            k1_q24: q24(c.k1_dph_per_c),
            k2_q24: q24(c.k2_dph_per_c_per_s),
            k3_q24: q24(c.k3_dph_per_c2),
            k4_q24: q24(c.k4_dph_per_c),
            k5_q24: q24(c.k5_dph),
            grad: DerivativeConfig::new(dt, GRAD_TAU_S),
            warm_a_q30: q30(1.0 - (-dt / c.tau_warm_s).exp()),
            coeffs_default,
        }
    }
}

impl ThermalConfig {
    /// From a stored record (coeffs.rs): a corrupt, wrong-version or
    /// out-of-range record gives the SAFE set with `coeffs_default` up.
    pub fn from_record(record: &[u8], dt_s: f64) -> Self {
        match ThermalCoeffs::from_record(record) {
            Ok(c) => Self::new(&c, dt_s),
            Err(_) => Self {
                coeffs_default: true,
                ..Self::new(&ThermalCoeffs::SAFE, dt_s)
            },
        }
    }
}

/// Mutable state of the compensation.
#[derive(Clone, Copy, Debug, Default)]
pub struct ThermalComp {
    a: SensorHold,
    b: SensorHold,
    case: SensorHold,
    grad: Derivative,
    warm_q30: i64,
    bias_q16: i64,
    flags: RlgFlags,
}

impl ThermalComp {
    /// One sensor update: returns B_TC (constant bias included), Q16 deg/h.
    pub fn update(&mut self, cfg: &ThermalConfig, t: &Temperatures) -> i64 {
        let (ta, bad_a) = self.a.take(t.mono_a_q8);
        let (tb, bad_b) = self.b.take(t.mono_b_q8);
        let (tk, bad_k) = self.case.take(t.case_q8);
        let mut flags = RlgFlags::empty();
        flags.set(RlgFlags::SENSOR_A, bad_a);
        flags.set(RlgFlags::SENSOR_B, bad_b);
        flags.set(RlgFlags::SENSOR_CASE, bad_k);
        flags.set(RlgFlags::COEFFS_DEFAULT, cfg.coeffs_default);
        self.flags = flags;

        let dt = ((ta - tb) as i64).clamp(-32 * 256, 32 * 256); // Q8

        // Held values carry no rate: the gradient decays while either
        // monoblock sensor is bad.
        let grad_q32 = self.grad.update(&cfg.grad, dt as i32, !(bad_a || bad_b));
        // |1 - F| <= 2^30, a < 2^26: below 2^56. Rounded shift.
        const HALF: i64 = 1 << 29;
        self.warm_q30 += (((1i64 << 30) - self.warm_q30) * cfg.warm_a_q30 + HALF) >> 30;

        let b = (cfg.bias0_q24 >> 8)
            + ((cfg.k1_q24 * dt) >> 16)
            + ((cfg.k2_q24 * (grad_q32 >> 12)) >> 28)
            + ((cfg.k3_q24 * (dt * dt)) >> 24)
            + ((cfg.k4_q24 * tk as i64) >> 16)
            + ((cfg.k5_q24 * (self.warm_q30 >> 6)) >> 32);
        self.bias_q16 = b;
        b
    }

    /// Operating time already elapsed at start (a restart, or a record that
    /// does not begin at power-on): presets F(tau) = 1 - exp(-t/tau_warm).
    pub fn preset_operating_time(&mut self, c: &ThermalCoeffs, t_s: f64) {
        let tau = if c.check().is_ok() {
            c.tau_warm_s
        } else {
            ThermalCoeffs::SAFE.tau_warm_s
        };
        let f = 1.0 - (-t_s.max(0.0) / tau).exp();
        self.warm_q30 = (f * (1u64 << 30) as f64).round() as i64;
    }

    /// Sensor values in use (last good), Q8 degC: mono A, mono B, case.
    pub fn in_use_q8(&self) -> [i32; 3] {
        [self.a.value_q8(), self.b.value_q8(), self.case.value_q8()]
    }

    /// Last B_TC, Q16 deg/h.
    pub fn bias_q16(&self) -> i64 {
        self.bias_q16
    }
    /// Fault bits (the sensor and coefficient ones).
    pub fn flags(&self) -> RlgFlags {
        self.flags
    }
    /// Filtered d(dT)/dt, Q32 degC/s.
    pub fn gradient_q32(&self) -> i64 {
        self.grad.value_q32()
    }
}
