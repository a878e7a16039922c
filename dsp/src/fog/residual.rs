//! The demodulated residual is a sine: a closure with mean residual phase x
//! demodulates to `r = sin(x)` (times factors of the in-closure slope,
//! docs/fog.md, "The residual's sine"). Near the dark fringe under strong
//! vibration with DAC latency x reaches 0.4 rad, where `sin` is 2.6 % short:
//! the loop's gain for the mean residual would depend on its amplitude.
//! The closure therefore measures the phase `asin(r)`, and the blocks that
//! need the sine's square (the eps^2 correction, the AGC's DC moment) take it
//! from here, computed once.
//!
//! The square is kept negated, `nq = -r^2`: LLVM proves a square
//! non-negative and then widens every signed product with it into `umull`
//! plus a sign fix-up (three instructions instead of one `smmul`); a
//! negated square's sign it cannot know.

use crate::fixed::smmul;

/// The residual is saturated to +-pi/4 rad (sine domain) for the
/// linearisation and the square: beyond it the loop is not tracking, and
/// `r^2` in Q31 stays below 0.62.
pub const RESIDUAL_LIMIT: i32 = 1 << 29;

/// -pi^2/48 * 2^32, rounded: with a = 4r (r in phase LSB), t =
/// `smmul(a, a)` is `16 r^2 / 2^32` (at most 2^30), and `-q/6 = -r_rad^2 *
/// 2^31 / 6 = t * (-pi^2/48)` in Q31. q itself is six times that.
const NEG_SIXTH_R2: i32 = -883_117_253;

/// A closure's residual in the sine domain, saturated, its negated square,
/// and the step from it to its arcsine.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Sine {
    /// The demodulated residual r, phase LSB, saturated to +-[`RESIDUAL_LIMIT`].
    pub r: i32,
    /// -r^2 in rad^2, Q31 (above -0.62 * 2^31).
    pub nq: i32,
    /// -(asin(r) - r), phase LSB, rounded: `-r*(q/6)*(1 + q/2)` (q = r^2).
    /// The series' `1 + q/2` stands for `1 + 9q/20 + 15q^2/56 + ...`: within
    /// 4e-6 rad of asin at r = 0.4 (the largest of the eps^2 envelope),
    /// 1.5e-4 at 0.5.
    pub n_lift: i32,
}

impl Sine {
    /// From the demodulated residual (phase LSB). `4r` fills an i32 (at r
    /// = -2^29 it is i32::MIN, whose square's high word is 2^30; q at most
    /// 1.24 * 2^30).
    #[inline(always)]
    pub fn new(residual: i32) -> Self {
        let r = residual.clamp(-RESIDUAL_LIMIT, RESIDUAL_LIMIT - 1);
        let a = r << 2;
        let t = smmul(a, a);
        // -q/6 and -q, Q31 (q's granularity six LSB).
        let h = smmul(t, NEG_SIXTH_R2);
        let nq = (h + (h << 1)) << 1;
        // -q/6 * (1 + q/2), Q31: smmul of two Q31 is Q30, i.e. half the
        // product in Q31 (|e| < 0.11).
        let e = h - smmul(h, nq);
        // r * e: 2r * e_Q31 / 2^32, rounded to the nearest LSB (a floored
        // one would bias the output by half an LSB: the loop nulls the mean
        // of what it is given).
        let n_lift = (((r << 1) as i64 * e as i64 + (1 << 31)) >> 32) as i32;
        Self { r, nq, n_lift }
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

    /// -nq is r^2 in Q31 to eight LSB (six of granularity) over the range, the clamp's edges included.
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
            let want = (r as f64 * RAD_PER_PHASE_LSB).powi(2) * 2f64.powi(31);
            assert!((-s.nq as f64 - want).abs() <= 8.0, "{r}: {} vs {want}", -s.nq);
        }
        // Saturated beyond the limit, never wrapped.
        assert_eq!(Sine::new(i32::MAX), Sine::new(RESIDUAL_LIMIT - 1));
        assert_eq!(Sine::new(i32::MIN), Sine::new(-RESIDUAL_LIMIT));
    }

    /// The phase is asin(r) to the series' remainder (r^5 * (3/40 - 1/12)
    /// and beyond, 1.5e-4 at 0.5 rad) and one LSB; saturated at the i32
    /// range.
    #[test]
    fn phase_is_the_arcsine() {
        for k in -50..=50 {
            let x = k as f64 * 0.01;
            let r = (x / RAD_PER_PHASE_LSB).round() as i32;
            let got = Sine::new(r).phase(r) as f64 * RAD_PER_PHASE_LSB;
            let rr = r as f64 * RAD_PER_PHASE_LSB;
            let series = rr + rr.powi(3) / 6.0 + rr.powi(5) / 12.0;
            assert!(
                (got - series).abs() <= 2.0 * RAD_PER_PHASE_LSB,
                "{x}: {got} vs {series}"
            );
            let tol = rr.abs().powi(5) / 120.0 * 1.5 + 2.0 * RAD_PER_PHASE_LSB;
            assert!((got - rr.asin()).abs() <= tol, "{x}: {got} vs {}", rr.asin());
        }
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
