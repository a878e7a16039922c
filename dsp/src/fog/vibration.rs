//! Online correction of the epsilon-squared (vibration rectification) drift.
//!
//! The closure measures the residual phase as asin(r) of the demodulated
//! residual r ([`super::residual`]); what survives in it is the cosine's
//! even part, which turns the in-closure slope into a gain error of the
//! closure: with d the difference of the closure's two half residuals,
//! `bias = -(cot(phi0)/n) * d * r / (1 - r^2)` rad (exact to first order in
//! the slope: the `1/(1 - r^2)` is the slope's own sine compression, 1/cos x,
//! times tan x against sin x). Each closure inverts its own measurement, so
//! the correction holds for any loop gain, latency and vibration frequency,
//! and it adds no drift at rest. Derivation: docs/fog.md, "The eps^2 drift".

use super::residual::Sine;
use crate::fixed::smmul;
#[allow(unused_imports)] // f64 maths comes from libm where core lacks it
use num_traits::float::Float;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct VibrationConfig {
    /// -(cot(phi0)/n_half) * 512*pi in Q[`COEFF_FRAC`]: the factor from the
    /// in-closure slope (2^-3 phase LSB) to u = -(cot(phi0)/n) * slope in
    /// rad, Q32, by one `smmul`. Below 2^31 in magnitude; 0 when the
    /// correction is off (the update then returns 0 without a branch).
    pub coeff: i32,
    /// The correction is on.
    pub enabled: bool,
}

impl VibrationConfig {
    /// For depth `phi0_rad`, `n_half` half periods per closure and a depth
    /// dither of mean square `dither_sq` (rad^2). `None` (with the
    /// correction on) when |cot(phi0)|/n_half is 0.637 or more: the
    /// coefficient would reach 2^30, and |u| (below 0.24 for the slope's
    /// range) with it the Q31 range of u/(1 - r^2).
    ///
    /// The dither: a closure at depth phi0 + e has the coefficient
    /// cot(phi0 + e) and its levels are scaled back by 1 - e*cot(phi0)
    /// (closure.rs), so the drift's mean coefficient is cot(phi0) * (1 +
    /// (1 + cot^2(phi0)) * <e^2>): 0.07 % at 7pi/8 with the 16-bit ADC's
    /// 240 codes (<e^2> = w^2/6, triangular).
    pub fn new(enabled: bool, phi0_rad: f64, n_half: usize, dither_sq: f64) -> Option<Self> {
        let cot = 1.0 / phi0_rad.tan();
        let dither = 1.0 + (1.0 + cot * cot) * dither_sq;
        let coeff = -(cot / n_half as f64)
            * dither
            * 512.0
            * core::f64::consts::PI
            * (1u64 << COEFF_FRAC) as f64;
        // NaN (phi0 of 0) is refused too.
        if enabled && (coeff.is_nan() || coeff.abs() >= 2_147_483_647.0) {
            return None;
        }
        Some(Self {
            coeff: if enabled {
                coeff.round().clamp(i32::MIN as f64, i32::MAX as f64) as i32
            } else {
                0
            },
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

/// Fraction bits of the coefficient (see [`VibrationConfig::coeff`]).
pub const COEFF_FRAC: u32 = 21;

impl VibrationCorrection {
    /// Takes this closure's slope d (2^-3 phase LSB: the i32 range is +-0.37 rad,
    /// beyond which the loop is not tracking and the correction means
    /// nothing) and its residual's sine ([`Sine`]: r saturated at +-pi/8,
    /// and its square); returns the bias to subtract from the output phase, whole
    /// phase LSB (the fraction is carried, no loss; |bias| < 2^27), or 0
    /// when the correction is off (coefficient 0: u, v and the carried
    /// fraction stay 0).
    #[inline(always)]
    pub fn update(&mut self, cfg: &VibrationConfig, slope_q3: i32, s: &Sine) -> i32 {
        // u = -(cot(phi0)/n) * d [rad], Q32: config keeps |coeff| < 2^31,
        // and the slope's range makes |u| < 0.24.
        let u = smmul(slope_q3, cfg.coeff);
        // v = u/(1 - q) to q^3 (Horner, Q32, -q in Q32): |v| < 0.24/(1 -
        // 0.154) < 0.29. The dropped q^4 is 0.06 % of v at r = 0.37.
        let nq = s.neg_q();
        let v = u - smmul(nq, u);
        let v = u - smmul(nq, v);
        let v = u - smmul(nq, v);
        // bias = r * v, phase LSB in Q32 (|r * v| < 2^57); the fraction
        // below one LSB waits for the next closure.
        let total = self.frac as i64 + s.r as i64 * v as i64;
        self.frac = total as u32;
        (total >> 32) as i32
    }
}

#[cfg(test)]
mod tests {
    use super::super::residual::RESIDUAL_LIMIT;
    use super::*;
    use crate::phase::RAD_PER_PHASE_LSB;
    use core::f64::consts::PI;

    /// The bias the correction implements, phase LSB: -(cot(phi0)/n) * d *
    /// r * (1 + q + q^2 + q^3), q = r^2, d and r in rad (d given in 2^-3
    /// phase LSB, r saturated at +-pi/4).
    fn formula(phi0: f64, n: usize, slope_q3: i32, residual: i32) -> f64 {
        let d = slope_q3 as f64 / 8.0 * RAD_PER_PHASE_LSB;
        let r = residual.clamp(-RESIDUAL_LIMIT, RESIDUAL_LIMIT - 1) as f64 * RAD_PER_PHASE_LSB;
        let q = r * r;
        -(1.0 / phi0.tan() / n as f64) * d * r * (1.0 + q * (1.0 + q * (1.0 + q)))
            / RAD_PER_PHASE_LSB
    }

    fn update(c: &mut VibrationCorrection, cfg: &VibrationConfig, slope: i32, r: i32) -> i32 {
        c.update(cfg, slope, &Sine::new(r))
    }

    /// The series stands for 1/(1 - r^2) to 0.06 % up to r = 0.39 rad (the
    /// residual's limit; the eps^2 envelope reaches 0.37).
    #[test]
    fn series_is_the_slope_compression() {
        let q: f64 = 0.39 * 0.39;
        let series = 1.0 + q * (1.0 + q * (1.0 + q));
        assert!((series * (1.0 - q) - 1.0).abs() < 6e-4);
    }

    /// Over both reference instruments and slopes and residuals across
    /// their ranges, the sum of the biases (the carried fraction makes it
    /// exact over many closures) equals the formula's: to 2e-7 of its size
    /// (the coefficient's and r^2's rounding), 16|r|/2^32 per closure for
    /// the floored products that r multiplies, and the fraction still
    /// carried.
    #[test]
    fn correction_follows_its_formula() {
        for (phi0, n) in [(0.75 * PI, 16), (0.875 * PI, 32), (0.6 * PI, 4)] {
            let cfg = VibrationConfig::new(true, phi0, n, 0.0).unwrap();
            for (slope_q3, residual) in [
                (1 << 20, 1 << 20),
                (-(1 << 24), 3 << 22),
                (i32::MAX, RESIDUAL_LIMIT - 1),
                (i32::MIN, -RESIDUAL_LIMIT),
                (i32::MAX, i32::MIN),
                (12_345_678, -87_654_321),
                (-5, 7),
            ] {
                let mut c = VibrationCorrection::default();
                let closures = 1000;
                let got: i64 = (0..closures)
                    .map(|_| update(&mut c, &cfg, slope_q3, residual) as i64)
                    .sum();
                let want = formula(phi0, n, slope_q3, residual) * closures as f64;
                let r = residual.clamp(-RESIDUAL_LIMIT, RESIDUAL_LIMIT) as f64;
                let floors = 16.0 * r.abs() / 4_294_967_296.0;
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
        let cfg = VibrationConfig::new(true, 0.75 * PI, 16, 0.0).unwrap();
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
            assert_eq!(
                update(&mut a, &cfg, slope, beyond),
                update(&mut b, &cfg, slope, at)
            );
        }
        // The largest bias, at both ends, stays below 2^27 LSB.
        for (slope, r) in [
            (i32::MAX, RESIDUAL_LIMIT - 1),
            (i32::MIN, -RESIDUAL_LIMIT),
            (i32::MIN, RESIDUAL_LIMIT - 1),
        ] {
            let mut c = VibrationCorrection::default();
            assert!(update(&mut c, &cfg, slope, r).unsigned_abs() < 1 << 27);
        }
    }

    /// At rest (no slope) it adds nothing; off, it returns nothing.
    #[test]
    fn no_bias_at_rest_or_when_off() {
        let on = VibrationConfig::new(true, 0.75 * PI, 16, 0.0).unwrap();
        let off = VibrationConfig::new(false, 0.75 * PI, 16, 0.0).unwrap();
        let mut c = VibrationCorrection::default();
        for r in [-RESIDUAL_LIMIT, -1, 0, 1, 1 << 27] {
            assert_eq!(update(&mut c, &on, 0, r), 0);
            assert_eq!(update(&mut c, &off, 1 << 24, r), 0);
        }
    }

    /// The coefficient's range: refused where |cot(phi0)|/n reaches 0.637
    /// (phi0 within 0.37 rad of 0 or pi at 4 half periods), accepted when off.
    #[test]
    fn coefficient_range() {
        assert!(VibrationConfig::new(true, 0.36, 4, 0.0).is_none());
        assert!(VibrationConfig::new(true, PI - 0.36, 4, 0.0).is_none());
        assert!(VibrationConfig::new(true, 0.38, 4, 0.0).is_some());
        assert!(VibrationConfig::new(false, 0.36, 4, 0.0).is_some());
    }
}
