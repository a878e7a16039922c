//! Online correction of the epsilon-squared (vibration rectification) drift.
//!
//! The loop nulls the mean demodulated residual r, not the true mean
//! residual; their difference follows eps^2 and is the drift. Each closure
//! inverts its own measurement, so the correction holds for any loop gain,
//! latency and vibration frequency: with d the difference of the period's
//! two half residuals, `bias = -(cot(phi0)/n) * d * r * (1 + r^2)` rad, and
//! it adds no drift at rest. Derivation: docs/fog.md, "The eps^2 drift".

use crate::fixed::smmul;
#[allow(unused_imports)] // f64 maths comes from libm where core lacks it
use num_traits::float::Float;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct VibrationConfig {
    /// -(cot(phi0)/n_half) * 512*pi in Q[`COEFF_FRAC`]: the factor from the
    /// in-closure slope (2^-3 phase LSB) to -(cot(phi0)/n) * slope in rad,
    /// Q32, by one `smmul`. Below 2^31 in magnitude.
    pub coeff: i32,
    /// Off: the update returns no bias.
    pub enabled: bool,
}

impl VibrationConfig {
    /// For depth `phi0_rad` and `n_half` half periods per closure. `None`
    /// (with the correction on) when |cot(phi0)|/n_half is 0.637 or more:
    /// the coefficient would not fit.
    pub fn new(enabled: bool, phi0_rad: f64, n_half: usize) -> Option<Self> {
        let coeff = -(1.0 / phi0_rad.tan() / n_half as f64)
            * 512.0
            * core::f64::consts::PI
            * (1u64 << COEFF_FRAC) as f64;
        // NaN (phi0 of 0) is refused too.
        if enabled && (coeff.is_nan() || coeff.abs() >= 2_147_483_647.0) {
            return None;
        }
        Some(Self {
            coeff: coeff.round().clamp(i32::MIN as f64, i32::MAX as f64) as i32,
            enabled,
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
pub const RESIDUAL_LIMIT: i32 = 1 << 28;

/// Q32 of rad^2 per (64 r^2 / 2^32) with r in phase LSB, halved: r_rad^2 =
/// r^2 * (2*pi/2^32)^2, so r_rad^2 * 2^32 = (64 r^2/2^32) * pi^2/16 =
/// umull(2 * (64 r^2/2^32), pi^2/32 * 2^32) >> 32.
const R2_SCALE: u32 = 1_324_675_879; // pi^2/32 * 2^32, rounded

/// Fraction bits of the coefficient (see [`VibrationConfig::coeff`]).
pub const COEFF_FRAC: u32 = 21;

impl VibrationCorrection {
    /// Takes this closure's slope d (2^-3 phase LSB: the i32 range is +-0.37 rad,
    /// beyond which the loop is not tracking and the correction means
    /// nothing) and its mean residual r (phase LSB, saturated at
    /// [`RESIDUAL_LIMIT`]); returns the bias to subtract from the output
    /// phase, whole phase LSB (the fraction is carried, no loss; |bias| <
    /// 2^27), or 0 when the correction is off.
    #[inline(always)]
    pub fn update(&mut self, cfg: &VibrationConfig, slope_q3: i32, residual: i32) -> i32 {
        if !cfg.enabled {
            return 0;
        }
        // A power-of-two range: one `ssat` on the M4.
        let r = residual.clamp(-RESIDUAL_LIMIT, RESIDUAL_LIMIT - 1);
        // u = -(cot(phi0)/n) * d [rad], Q32: config keeps |coeff| < 2^31, so
        // |u| < 0.24 * 2^32.
        let u = smmul(slope_q3, cfg.coeff);
        // q = r^2 [rad^2], Q32: r << 3 fills an i32, so t <= 2^30 (equal at
        // r = -2^28, where 2t is 2^31: unsigned, one `umull`); q < 0.16 * 2^32.
        let t = smmul(r << 3, r << 3);
        let q = ((((t as u32) << 1) as u64 * R2_SCALE as u64) >> 32) as i32;
        // v = u*(1 + q), one `smmla`; |v| < 0.28 * 2^32.
        let v = u + smmul(q, u);
        // bias = r * v, phase LSB in Q32 (|r * v| < 2^59); the fraction below
        // one LSB waits for the next closure.
        let total = self.frac as i64 + r as i64 * v as i64;
        self.frac = total as u32;
        (total >> 32) as i32
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::phase::RAD_PER_PHASE_LSB;
    use core::f64::consts::PI;

    /// The bias the formula gives, phase LSB: -(cot(phi0)/n) * d * r * (1 +
    /// r^2) with d and r in rad (d given in 2^-3 phase LSB).
    fn formula(phi0: f64, n: usize, slope_q3: i32, residual: i32) -> f64 {
        let d = slope_q3 as f64 / 8.0 * RAD_PER_PHASE_LSB;
        let r = residual as f64 * RAD_PER_PHASE_LSB;
        -(1.0 / phi0.tan() / n as f64) * d * r * (1.0 + r * r) / RAD_PER_PHASE_LSB
    }

    /// Over both reference instruments and slopes and residuals across
    /// their ranges, the sum of the biases (the carried fraction makes it
    /// exact over many closures) equals the formula's: to 2e-7 of its size
    /// (the coefficient's and r^2's rounding), |r|/2^32 per closure for each
    /// of the two floored Q32 products that r multiplies, and the fraction
    /// still carried.
    #[test]
    fn correction_follows_its_formula() {
        for (phi0, n) in [(0.75 * PI, 16), (0.875 * PI, 32), (0.6 * PI, 4)] {
            let cfg = VibrationConfig::new(true, phi0, n).unwrap();
            for (slope_q3, residual) in [
                (1 << 20, 1 << 20),
                (-(1 << 24), 3 << 22),
                (i32::MAX, RESIDUAL_LIMIT - 1),
                (i32::MIN, -RESIDUAL_LIMIT),
                (12_345_678, -87_654_321),
                (-5, 7),
            ] {
                let mut c = VibrationCorrection::default();
                let closures = 1000;
                let got: i64 = (0..closures)
                    .map(|_| c.update(&cfg, slope_q3, residual) as i64)
                    .sum();
                let want = formula(phi0, n, slope_q3, residual) * closures as f64;
                let floors = 2.0 * residual.unsigned_abs().min(1 << 28) as f64 / 4_294_967_296.0;
                let tol = 2e-7 * want.abs() + floors * closures as f64 + 2.0;
                assert!(
                    (got as f64 - want).abs() <= tol,
                    "phi0 {phi0} n {n} d {slope_q3} r {residual}: {got} vs {want}"
                );
            }
        }
    }

    /// The residual saturates at the clamp: beyond it the bias is the
    /// clamp's, never a wrapped value.
    #[test]
    fn residual_saturates_at_the_clamp() {
        let cfg = VibrationConfig::new(true, 0.75 * PI, 16).unwrap();
        let slope = 1 << 22;
        for (beyond, at) in [
            (i32::MAX, RESIDUAL_LIMIT - 1),
            (RESIDUAL_LIMIT, RESIDUAL_LIMIT - 1),
            (i32::MIN, -RESIDUAL_LIMIT),
            (-RESIDUAL_LIMIT - 1, -RESIDUAL_LIMIT),
        ] {
            let (mut a, mut b) = (
                VibrationCorrection::default(),
                VibrationCorrection::default(),
            );
            assert_eq!(a.update(&cfg, slope, beyond), b.update(&cfg, slope, at));
        }
        // The largest bias, at both ends, stays below 2^27 LSB.
        let mut c = VibrationCorrection::default();
        assert!(c.update(&cfg, i32::MAX, RESIDUAL_LIMIT - 1).unsigned_abs() < 1 << 27);
    }

    /// At rest (no slope) it adds nothing; off, it returns nothing.
    #[test]
    fn no_bias_at_rest_or_when_off() {
        let on = VibrationConfig::new(true, 0.75 * PI, 16).unwrap();
        let off = VibrationConfig::new(false, 0.75 * PI, 16).unwrap();
        let mut c = VibrationCorrection::default();
        for r in [-RESIDUAL_LIMIT, -1, 0, 1, 1 << 27] {
            assert_eq!(c.update(&on, 0, r), 0);
            assert_eq!(c.update(&off, 1 << 24, r), 0);
        }
    }

    /// The coefficient's range: refused where |cot(phi0)|/n reaches 0.637
    /// (phi0 within 0.37 rad of 0 or pi at 4 half periods), accepted when off.
    #[test]
    fn coefficient_range() {
        assert!(VibrationConfig::new(true, 0.36, 4).is_none());
        assert!(VibrationConfig::new(true, PI - 0.36, 4).is_none());
        assert!(VibrationConfig::new(true, 0.38, 4).is_some());
        assert!(VibrationConfig::new(false, 0.36, 4).is_some());
    }
}
