//! Online correction of the epsilon-squared (vibration rectification) drift.
//!
//! Derivation for this loop (physics.md 1.4): within a step the residual grows by
//! b = K_s*eps*tau per half period. The cosine's second-order term adds
//! `(cot(phi0)/4)*(d1^2 - d2^2)` to each (+phi0, -phi0) pair, which summed over a
//! step starting on +phi0 gives a demodulated bias `-(cot(phi0)/2)*b*dbar`
//! (dbar = mean residual of the step). The integrator nulls the mean demodulated
//! error, so the output carries that bias. For a one-step integrator of gain g the
//! quasi-static residual is dbar = n*b/g (n half periods per step), so
//! `bias = -(cot(phi0)/2)*(n/g)*b^2` [rad per step]; with g = 1 this is
//! physics.md's `-(1/4)*cot(phi0)*K_s*eps^2*dt_m*dt_p`.
//!
//! Both factors are measured, so the quasi-static step is not needed: b from
//! the step itself (the residual of the second half of the step minus that of
//! the first half, `da = (n/2)*b`), dbar is the demodulated residual the main
//! loop already has. Away from the quasi-static limit (vibration nearer the
//! loop bandwidth, or a loop gain other than one) dbar lags b and the
//! measured product follows; the model `dbar = n*b/g` would not.
//! A product of two noisy estimates from the same samples would be biased by
//! their noise covariance; this step's slope times a residual predicted from
//! the two previous steps (disjoint samples) is unbiased, so the correction
//! adds no drift at rest. The prediction `(4*dbar_(k-1) - dbar_(k-2))/3`
//! removes the one-step lag to second order: the previous residual alone
//! would carry cos(w*dt_p) into the mean, 0.980 at 200 Hz with a 6.25 kHz
//! closure; the prediction carries 1 - (w*dt_p)^4/6.
//! `bias = -(cot(phi0)/n) * da_k * dbar_k(predicted)`.

#[derive(Clone, Copy, Debug, Default)]
pub struct VibrationCorrection {
    /// Mean residuals of the two previous steps, phase LSB, saturated to
    /// +-2^30 (a quarter turn: beyond, the loop is not tracking).
    prev_residual: i32,
    prev_residual2: i32,
    /// Sub-LSB part of the correction carried to the next step (phase LSB,
    /// Q[`FRAC_BITS`], in [0, 1)).
    frac: i64,
}

/// Slopes are saturated to this (2^8 LSB units, about 0.37 rad): beyond that
/// the loop is not tracking and the correction is meaningless.
const SLOPE_LIMIT: i32 = 1 << 20;

/// Fraction bits of the coefficient (see [`crate::fog::FogConfig::vib_coeff`]).
pub const COEFF_FRAC: u32 = 30;

/// Low bits of the product (slope x residual, 2^8 LSB^2 units, below 2^51)
/// dropped (rounded) before the coefficient, so one 32x32 multiply scales it.
/// The step is under 0.1 % of the product at 1 000 deg/s^2 on the reference
/// coil, and unbiased.
const PRODUCT_DROP: u32 = 21;

/// Fraction bits of p * coeff in phase LSB (the coefficient's output is Q16).
const FRAC_BITS: u32 = COEFF_FRAC - PRODUCT_DROP + 16;

impl VibrationCorrection {
    /// Takes this step's slope (2^8 LSB, any value: saturated here), its mean
    /// residual (phase LSB) and the coefficient (Q[`COEFF_FRAC`]); returns the
    /// bias to subtract from the output step, whole phase LSB (the fraction is
    /// carried, no loss).
    #[inline(always)]
    pub fn update(&mut self, slope: i32, residual: i32, coeff: i32) -> i64 {
        // A power-of-two range: one `ssat` on the M4.
        let slope = slope.clamp(-SLOPE_LIMIT, SLOPE_LIMIT - 1);
        // (4*r1 - r2)/3 = r1 + (r1 - r2)/3: |r1 - r2| < 2^31, the third by
        // one `smmul` (2^32/3), so |predicted| < 2^31.
        let (r1, r2) = (self.prev_residual, self.prev_residual2);
        let predicted = r1 + (((r1 - r2) as i64 * 0x5555_5555) >> 32) as i32;
        // slope * predicted / 2^21, rounded: slope << 11 fills an i32, so this
        // is the rounded high word of one product (`smmulr`); |p| <= 2^30.
        let product = ((slope << (32 - PRODUCT_DROP)) as i64) * predicted as i64;
        let p = ((product + (1 << 31)) >> 32) as i32;
        self.prev_residual2 = r1;
        self.prev_residual = residual.clamp(-(1 << 30), (1 << 30) - 1);
        // |p * coeff| <= 2^61, phase LSB in Q[`FRAC_BITS`];
        // the fraction below one LSB waits for the next step.
        let total = self.frac + p as i64 * coeff as i64;
        let whole = total >> FRAC_BITS;
        self.frac = total & ((1 << FRAC_BITS) - 1);
        whole
    }

    /// Forget the history (after a fault: residuals across the gap are not valid).
    pub fn reset(&mut self) {
        self.prev_residual = 0;
        self.prev_residual2 = 0;
    }
}
