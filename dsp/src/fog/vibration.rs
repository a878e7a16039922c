//! Online correction of the epsilon-squared (vibration rectification) drift.
//!
//! The loop nulls the mean demodulated residual r, not the true mean
//! residual; their difference follows eps^2 and is the drift. Each closure
//! inverts its own measurement, so the correction holds for any loop gain,
//! latency and vibration frequency: with d the difference of the period's
//! two half residuals, `bias = -(cot(phi0)/n) * d * r * (1 + r^2)` rad, and
//! it adds no drift at rest. Derivation: docs/fog.md, "The eps^2 drift".

use super::config::{ConfigError, FogParams};
#[allow(unused_imports)] // f64 maths comes from libm where core lacks it
use num_traits::float::Float;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct VibrationConfig {
    /// -(cot(phi0)/n_half) * 512*pi in Q[`COEFF_FRAC`]: the factor from the
    /// in-closure slope (2^-3 phase LSB) to -(cot(phi0)/n) * slope in rad,
    /// Q32, by one `smmul`. Below 2^31 in magnitude.
    pub coeff: i32,
    pub enabled: bool,
}

impl VibrationConfig {
    /// Refused (with the correction on) when |cot(phi0)|/n_half is 0.637 or
    /// more: the coefficient would not fit.
    pub fn new(p: &FogParams, n_half: usize) -> Result<Self, ConfigError> {
        let coeff = -(1.0 / p.phi0_rad.tan() / n_half as f64)
            * 512.0
            * core::f64::consts::PI
            * (1u64 << COEFF_FRAC) as f64;
        if p.vibration_correction && coeff.abs() >= 2_147_483_647.0 {
            return Err(ConfigError::VibrationCoeff);
        }
        Ok(Self {
            coeff: coeff.round().clamp(i32::MIN as f64, i32::MAX as f64) as i32,
            enabled: p.vibration_correction,
        })
    }
}

#[derive(Clone, Copy, Debug, Default)]
pub struct VibrationCorrection {
    /// Sub-LSB part of the correction carried to the next closure (phase LSB,
    /// Q32, in [0, 1)).
    frac: u32,
}

/// Residuals are saturated to this (phase LSB, pi/8 rad), so r^2 in Q32 fits.
const RESIDUAL_LIMIT: i32 = 1 << 28;

/// Q32 of rad^2 per (64 r^2 / 2^32) with r in phase LSB, halved: r_rad^2 =
/// r^2 * (2*pi/2^32)^2, so r_rad^2 * 2^32 = (64 r^2/2^32) * pi^2/16 =
/// smmul(2 * (64 r^2/2^32), pi^2/32 * 2^32).
const R2_SCALE: i32 = 1_324_675_879; // pi^2/32 * 2^32, rounded

/// Fraction bits of the coefficient (see [`VibrationConfig::coeff`]).
pub const COEFF_FRAC: u32 = 21;

impl VibrationCorrection {
    /// Takes this closure's slope d (2^-3 phase LSB: the i32 range is +-0.37 rad,
    /// beyond which the loop is not tracking and the correction means
    /// nothing), its mean residual r (phase LSB) and the coefficient
    /// -(cot(phi0)/n) * 512*pi in Q[`COEFF_FRAC`]; returns the bias to
    /// subtract from the output phase, whole phase LSB (the fraction is
    /// carried, no loss; |bias| < 2^27).
    #[inline(always)]
    pub fn update(&mut self, slope_q3: i32, residual: i32, coeff: i32) -> i32 {
        // A power-of-two range: one `ssat` on the M4.
        let r = residual.clamp(-RESIDUAL_LIMIT, RESIDUAL_LIMIT - 1);
        // u = -(cot(phi0)/n) * d [rad], Q32: config keeps |coeff| < 2^31, so
        // |u| < 0.24 * 2^32.
        let u = smmul(slope_q3, coeff);
        // q = r^2 [rad^2], Q32: r << 3 fills an i32, t < 2^30, q < 0.16 * 2^32.
        let t = smmul(r << 3, r << 3);
        let q = smmul(t << 1, R2_SCALE);
        // v = u*(1 + q), one `smmla`; |v| < 0.28 * 2^32.
        let v = u + smmul(q, u);
        // bias = r * v, phase LSB in Q32 (|r * v| < 2^59); the fraction below
        // one LSB waits for the next closure.
        let total = self.frac as i64 + r as i64 * v as i64;
        self.frac = total as u32;
        (total >> 32) as i32
    }
}

/// High word of the 64-bit product (`smmul`).
#[inline(always)]
fn smmul(a: i32, b: i32) -> i32 {
    ((a as i64 * b as i64) >> 32) as i32
}
