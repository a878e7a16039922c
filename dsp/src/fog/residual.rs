//! The demodulated residual is a sine: a closure with mean residual phase x
//! demodulates to `r = sin(x)` (times factors of the in-closure slope,
//! docs/fog.md, "The residual's sine"). Near the dark fringe under strong
//! vibration with DAC latency x reaches 0.38 rad, where `sin` is 2.4 %
//! short: the loop's gain for the mean residual would depend on its
//! amplitude. The closure therefore measures the phase `asin(r)`, and the
//! blocks that need the sine's square (the eps^2 correction, the AGC's DC
//! moment) take it from here, computed once.
//!
//! The square is kept as `h = -r^2/6`: LLVM proves a square non-negative
//! and then widens every signed product with it into `umull` plus a sign
//! fix-up (three instructions instead of one `smmul`); a negated square's
//! sign it cannot know, and the sixth is what the arcsine needs first.

use crate::fixed::smmul;

/// The residual is saturated to +-pi/8 rad (sine domain) for the
/// linearisation and the square, so that r^2 (at most 0.154) and its
/// multiples fit Q32: every product is one `smmul`/`smmla`/`smmls`. The
/// eps^2 envelope (issue 23) reaches 0.37 at 7pi/8 with one closure of DAC
/// latency at 50 000 deg/s^2; beyond the limit the loop is still closed
/// (the residual itself is not saturated here), only the arcsine's and the
/// correction's r stop growing.
pub const RESIDUAL_LIMIT: i32 = 1 << 28;

/// -pi^2/96 * 2^32, rounded: with a = 8r (r in phase LSB), t =
/// `smmul(a, a)` is `64 r^2 / 2^32` (at most 2^30), and `-q/6 = -r_rad^2 *
/// 2^32 / 6 = t * (-pi^2/96)` in Q32.
const NEG_R2_SIXTH: i32 = -441_558_626;

/// A closure's residual in the sine domain, saturated, its square, and the
/// step from it to its arcsine.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Sine {
    /// The demodulated residual r, phase LSB, saturated to +-[`RESIDUAL_LIMIT`].
    pub r: i32,
    /// h = -r^2/6 in rad^2, Q32 (above -0.026 * 2^32): 6h is -r^2, 3h is
    /// -r^2/2.
    pub h: i32,
    /// -(asin(r) - r), phase LSB, rounded: `-r*(q/6)*(1 + q/2)` (q = r^2).
    /// The series' `1 + q/2` stands for `1 + 9q/20 + 15q^2/56 + ...`: within
    /// 1.2e-5 rad of asin up to the limit (3e-5 of the residual).
    pub n_lift: i32,
}

impl Sine {
    /// From the demodulated residual (phase LSB). `8r` fills an i32 (at r
    /// = -2^28 it is i32::MIN, whose square's high word is 2^30).
    #[inline(always)]
    pub fn new(residual: i32) -> Self {
        let r = residual.clamp(-RESIDUAL_LIMIT, RESIDUAL_LIMIT - 1);
        let a = r << 3;
        let t = smmul(a, a);
        let h = smmul(t, NEG_R2_SIXTH);
        // e = h * (1 + q/2) = h - h * (3h), Q32 (|e| < 0.027).
        let e = h - smmul(h, h + (h << 1));
        // r * e, rounded to the nearest LSB (a floored one would bias the
        // output by half an LSB: the loop nulls the mean of what it is
        // given).
        let n_lift = ((r as i64 * e as i64 + (1 << 31)) >> 32) as i32;
        Self { r, h, n_lift }
    }

    /// -r^2 in Q32.
    #[inline(always)]
    pub fn neg_q(&self) -> i32 {
        (self.h + (self.h << 1)) << 1
    }

    /// The residual phase `asin(r)`, phase LSB: the demodulated residual
    /// plus the lift, saturated to the i32 range.
    #[inline(always)]
    pub fn phase(&self, residual: i32) -> i32 {
        residual.saturating_sub(self.n_lift)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::phase::RAD_PER_PHASE_LSB;

    /// -6h is r^2 in Q32 to twelve LSB (six of granularity) over the
    /// range, the clamp's edges included.
    #[test]
    fn square_follows_r() {
        for r in [
            0,
            1,
            -1,
            1 << 20,
            -(1 << 24),
            123_456_789,
            -RESIDUAL_LIMIT,
            RESIDUAL_LIMIT - 1,
        ] {
            let s = Sine::new(r);
            let want = (r as f64 * RAD_PER_PHASE_LSB).powi(2) * 2f64.powi(32);
            assert!(
                (-s.neg_q() as f64 - want).abs() <= 12.0,
                "{r}: {} vs {want}",
                -s.neg_q()
            );
        }
        // Saturated beyond the limit, never wrapped.
        assert_eq!(Sine::new(i32::MAX), Sine::new(RESIDUAL_LIMIT - 1));
        assert_eq!(Sine::new(i32::MIN), Sine::new(-RESIDUAL_LIMIT));
    }

    /// The phase is r + r^3/6 + r^5/12 to two LSB, and asin(r) to that
    /// series' remainder (at most 1.2e-5 rad, near r = 0.35); beyond the
    /// limit the lift
    /// is the limit's, and at the i32 range it saturates.
    #[test]
    fn phase_is_the_arcsine() {
        for k in -39..=39 {
            let x = k as f64 * 0.01;
            let r = (x / RAD_PER_PHASE_LSB).round() as i32;
            let got = Sine::new(r).phase(r) as f64 * RAD_PER_PHASE_LSB;
            let rr = r as f64 * RAD_PER_PHASE_LSB;
            let series = rr + rr.powi(3) / 6.0 + rr.powi(5) / 12.0;
            assert!(
                (got - series).abs() <= 2.0 * RAD_PER_PHASE_LSB,
                "{x}: {got} vs {series}"
            );
            assert!(
                (got - rr.asin()).abs() <= 1.3e-5,
                "{x}: {got} vs {}",
                rr.asin()
            );
        }
        let beyond = Sine::new(RESIDUAL_LIMIT + 5);
        assert_eq!(beyond.n_lift, Sine::new(RESIDUAL_LIMIT - 1).n_lift);
        assert_eq!(Sine::new(i32::MAX).phase(i32::MAX), i32::MAX);
        assert_eq!(Sine::new(i32::MIN).phase(i32::MIN), i32::MIN);
    }

    /// Rounded, not floored: over residuals symmetric about zero the
    /// linearisation adds nothing on average.
    #[test]
    fn phase_adds_no_mean_at_small_residuals() {
        let sum: i64 = (-100_000..100_000)
            .map(|r| (Sine::new(r).phase(r) - r) as i64)
            .sum();
        assert_eq!(sum, 0);
    }
}
