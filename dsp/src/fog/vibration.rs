//! Online correction of the epsilon-squared (vibration rectification) drift.
//!
//! The loop nulls the mean demodulated residual r, not the true mean
//! residual; their difference follows eps^2 and is the drift. Each closure
//! inverts its own measurement, so the correction holds for any loop gain,
//! latency and vibration frequency: with d the difference of the period's
//! two half residuals, `bias = -(cot(phi0)/n) * d * r * (1 + r^2)` rad, and
//! it adds no drift at rest. Derivation: docs/fog.md, "The eps^2 drift".

#[derive(Clone, Copy, Debug, Default)]
pub struct VibrationCorrection {
    /// Sub-LSB part of the correction carried to the next step (phase LSB,
    /// Q32, in [0, 1)).
    frac: u32,
}

/// Residuals are saturated to this (phase LSB, pi/8 rad), so r^2 in Q32 fits.
const RESIDUAL_LIMIT: i32 = 1 << 28;

/// Q32 of rad^2 per (64 r^2 / 2^32) with r in phase LSB, halved: r_rad^2 =
/// r^2 * (2*pi/2^32)^2, so r_rad^2 * 2^32 = (64 r^2/2^32) * pi^2/16 =
/// smmul(2 * (64 r^2/2^32), pi^2/32 * 2^32).
const R2_SCALE: i32 = 1_324_675_879; // pi^2/32 * 2^32, rounded

/// Fraction bits of the coefficient (see [`crate::fog::FogConfig::vib_coeff`]).
pub const COEFF_FRAC: u32 = 21;

impl VibrationCorrection {
    /// Takes this step's slope d (2^-3 phase LSB: the i32 range is +-0.37 rad,
    /// beyond which the loop is not tracking and the correction means
    /// nothing), its mean residual r (phase LSB) and the coefficient
    /// -(cot(phi0)/n) * 512*pi in Q[`COEFF_FRAC`]; returns the bias to
    /// subtract from the output step, whole phase LSB (the fraction is
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
        // one LSB waits for the next step.
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
