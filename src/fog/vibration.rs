//! Online correction of the epsilon-squared (vibration rectification) drift.
//!
//! Derivation for this loop (physics.md 1.4). Within a step the residual
//! grows by b per half period. A (+phi0, -phi0) pair of half periods around
//! residual d demodulates, exactly, to `sin(d) * g`, `g = cos(b/2) -
//! cot(phi0)*sin(b/2)`: the cosine's even part turns the in-step slope into a
//! gain error of the step. The integrator nulls the mean demodulated residual
//! r, not the mean true residual dbar, so the output carries mean(r - dbar);
//! as b and dbar both follow eps, `-(cot(phi0)/2)*b*dbar` survives the
//! average (physics.md's `-(1/4)*cot(phi0)*K_s*eps^2*dt_m*dt_p` for unit gain).
//!
//! The correction inverts the step's own measurement instead of modelling the
//! loop, so it holds for any loop gain and vibration frequency. With r_a, r_b
//! the demodulated residuals of the step's two halves (r their mean, d = r_b -
//! r_a = b*n/2): dbar = (asin(r_a/g) + asin(r_b/g))/2 and b =
//! (asin(r_b/g) - asin(r_a/g))/(n/2). Expanded to fourth order, keeping what
//! survives averaging over a symmetric vibration:
//! `bias = r - dbar = -(cot(phi0)/n)*d*r*(1 + r^2)` [rad]. The `1 + r^2` is
//! the sine compression of d (r^2/2) and of the mean through 1/g^3 (r^2/2).
//! The mean's own compression, -r^3/6, averages out: the loop nulls the mean
//! of r. In a float model of the loop at 7*pi/8, 6.25 kHz, 50 000 deg/s^2 the
//! second-order term alone leaves 2.8 % of the drift, this 0.25 % (with the
//! cube too, the same), the exact inversion 0.05 %.
//!
//! At rest r and d come from the same samples, but their noise is
//! uncorrelated: E[r*d] = (E[r_b^2] - E[r_a^2])/2 = 0 because both halves see
//! the same statistics; the odd terms vanish for symmetric noise. So the
//! correction adds no drift at rest.

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
