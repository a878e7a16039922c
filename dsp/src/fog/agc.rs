//! Slow AGC: the demodulated error is normalised by a low-passed detector DC,
//! so the loop gain does not depend on optical power, without correlating
//! the gain with the closure's own error. The DC filter takes the DC the
//! light would give with no residual spread: a residual spread within the
//! closure raises the DC by -A*cos(phi0)*<delta^2>/2 (the "DC moment",
//! docs/fog.md, "AGC and the DC moment"), which would otherwise lower the
//! loop gain under dynamics.

use super::residual::Sine;
use crate::fixed::smmul;
use crate::phase::RAD_PER_PHASE_LSB;
use core::num::NonZeroU32;
#[allow(unused_imports)] // f64 maths comes from libm where core lacks it
use num_traits::float::Float;

/// The DC filter's time constant, closures: the update's shift of its Q12
/// state (`dc - dc >> 12 + flat`). The slowest loop of the closure: what
/// starts with it (a run's first DC under vibration) decays at this rate.
pub const DC_FILTER_CLOSURES: u32 = 1 << 12;

/// Largest kept-sample sum of one half period, ADC LSB (15 kept samples of
/// 16-bit codes), so the Q12 DC filter fits a u32.
pub const MAX_HALF_SUM: u32 = (1 << 20) - 1;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct AgcConfig {
    /// Kept-sample sum of one half period at the nominal operating point, LSB.
    pub h0_nominal: u32,
    /// Below this DC (per-half sum above dark) the optical power is low.
    pub h0_min: u32,
    /// Dark level of one half period's kept-sample sum, LSB.
    pub dark_half: u32,
    /// Weight of the in-closure spread in the moment, 2^8 * 2(n^2-1)/(3n^2).
    pub spread_q8: i32,
    /// DC excess (ADC LSB of one half period's kept sum) per unit of the
    /// moment m (ADC LSB x phase LSB), Q60: -(cot(phi0)/(2n)) * 2*pi/2^32;
    /// below 2^31 for every valid depth (|cot| <= 10, n >= 4).
    pub moment_q60: i32,
    /// Half periods per closure, non-zero by its type: the DC's division
    /// cannot fault in the closure.
    pub n_half: NonZeroU32,
}

impl AgcConfig {
    /// From the detector's DC at the operating point and its dark level
    /// (ADC LSB per sample, above dark and absolute), the kept samples per
    /// half period, the depth phi0 and the half periods per closure.
    pub fn new(
        nominal_dc_lsb: f64,
        dark_lsb: f64,
        kept_per_half: usize,
        phi0_rad: f64,
        n_half: usize,
    ) -> Self {
        let kept = kept_per_half as f64;
        let h0_nominal = nominal_dc_lsb * kept;
        let nf = n_half as f64;
        let moment = -(1.0 / phi0_rad.tan()) / (2.0 * nf) * RAD_PER_PHASE_LSB;
        Self {
            h0_nominal: h0_nominal.round() as u32,
            h0_min: (h0_nominal * 0.25).round().max(2.0) as u32,
            dark_half: (dark_lsb.max(0.0) * kept).round() as u32,
            spread_q8: (256.0 * 2.0 * (nf * nf - 1.0) / (3.0 * nf * nf)).round() as i32,
            moment_q60: (moment * (1u64 << 60) as f64)
                .round()
                .clamp(i32::MIN as f64, i32::MAX as f64) as i32,
            // FogConfig refuses a layout without half periods before this.
            n_half: NonZeroU32::new(n_half as u32).unwrap_or(NonZeroU32::MIN),
        }
    }

    /// Detector DC of one half period, dark level removed, from the
    /// closure's kept-sample sum over its half periods: `H` of them when the
    /// closure's kernel knows the layout at compile time (a constant
    /// divisor), else the configuration's.
    #[inline(always)]
    pub fn dc_half<const H: usize>(&self, dc_sum: u32) -> u32 {
        let n = NonZeroU32::new(H as u32).unwrap_or(self.n_half);
        (dc_sum / n).saturating_sub(self.dark_half)
    }
}

/// The DC filter: one half period's DC, ADC LSB in Q12 (below 2^32);
/// time constant 4096 closures (0.33 s). Slow on purpose: a closure's DC has
/// a first-order term in the in-closure residual slope (proportional to
/// eps), so a fast AGC would modulate the loop gain at the vibration
/// frequency and rectify a second eps^2 drift.
///
/// Its output, the normaliser, is read before the closure's residual
/// exists ([`Agc::normaliser`], no state change); the closure then feeds its
/// own DC and spread back through the one update ([`Agc::update`]).
#[derive(Clone, Copy, Debug)]
pub struct Agc {
    dc_q12: u32,
    /// Holds a measured value (seeded on the first good closure).
    valid: bool,
}

/// The in-closure residual spread the DC moment is measured from: the
/// demodulated sums, the slope and the residual's sine (closure.rs).
#[derive(Clone, Copy, Debug)]
pub struct Spread {
    /// Sum of the first half's signed levels less the second's, LSB.
    pub diff: i32,
    /// In-closure slope, 2^8 phase LSB (|slope| <= 2^20).
    pub slope: i32,
    /// Minus the closure's signed level sum, LSB.
    pub neg_sum: i32,
    /// Mean demodulated residual r (the sine), phase LSB, and r^2 in rad^2,
    /// Q31 ([`Sine`]).
    pub sine: Sine,
}

/// What one closure tells the AGC.
#[derive(Clone, Copy, Debug)]
pub enum AgcInput {
    /// Optical power low: the filter restarts from the next lit closure.
    Dark,
    /// A lit closure with true levels (not clipped): its DC of one half
    /// period (dark removed, ADC LSB) and its residual spread.
    Lit { dc_half: u32, spread: Spread },
}

impl Agc {
    pub fn new(cfg: &AgcConfig) -> Self {
        Self {
            dc_q12: cfg.h0_nominal.min(MAX_HALF_SUM) << 12,
            valid: false,
        }
    }

    /// The normalising DC for the closure whose DC is `dc_half`: 2^32/H (H
    /// not below h0_min, the error scaling's range), H the filtered DC, or
    /// this closure's own until the filter holds a measured value.
    #[inline(always)]
    pub fn normaliser(&self, cfg: &AgcConfig, dc_half: u32) -> u32 {
        let dc = if self.valid {
            self.dc_q12 >> 12
        } else {
            dc_half.min(MAX_HALF_SUM)
        };
        u32::MAX / dc.max(cfg.h0_min).max(2)
    }

    /// Advances the filter with a lit closure's DC less its moment excess
    /// (the first after start or darkness seeds it with that flat value),
    /// or restarts it after darkness. Clipped closures are not fed: their
    /// levels are not true.
    ///
    /// The excess is `-A*cos(phi0)*n*E`, E = 1 - sqrt(1 - r^2 - S/(1 - r^2))
    /// exactly (docs/fog.md, "AGC and the DC moment"): r the demodulated
    /// residual, S the in-closure spread's share. With the levels' own
    /// amplitude (neg_sum = A*sin(phi0)*n*r, diff = A*sin(phi0)*n*d/2),
    /// `2E*A*sin(phi0)*n = neg_sum*(r + 3/2*(asin(r) - r)) + w*diff*d*(1 +
    /// 3q/2)` to r^6 (0.02 % of E at r = 0.37), w = 2(n^2 - 1)/(3n^2),
    /// q = r^2.
    /// |diff| < 2^27, |slope * spread| < 2^29 (weighted below 2^30), |neg_sum|
    /// < 2^27, the moment's residual below 1.1 * 2^28: |m| < 2^58 and its
    /// high word below 2^26 (dropping the low word costs under 1e-4 of the
    /// DC), so 16 times it fits an i32.
    #[inline(always)]
    pub fn update(&mut self, cfg: &AgcConfig, input: AgcInput) {
        let AgcInput::Lit { dc_half, spread: s } = input else {
            self.valid = false;
            return;
        };
        // The spread's weight times 1 + 3q/2 = 1 - 9h (h = -q/6, Q32; |9h|
        // < 0.24).
        let h = s.sine.h;
        let w = s.slope.wrapping_mul(cfg.spread_q8);
        let w = w - smmul(w, h + (h << 3));
        // r + 3/2*(asin(r) - r) (n_lift is minus the step to asin).
        let r_m = s.sine.r - s.sine.n_lift - (s.sine.n_lift >> 1);
        let m = s.diff as i64 * w as i64 + s.neg_sum as i64 * r_m as i64;
        // Q60 weight: (m >> 32) * moment >> 28 = smmul(16 * (m >> 32), moment).
        let excess = smmul(((m >> 32) as i32) << 4, cfg.moment_q60);
        let dc = dc_half.min(MAX_HALF_SUM) as i32;
        let flat = (dc - excess).clamp(0, MAX_HALF_SUM as i32) as u32;
        self.dc_q12 = if self.valid {
            self.dc_q12 - (self.dc_q12 >> 12) + flat
        } else {
            flat << 12
        };
        self.valid = true;
    }

    /// Filtered DC of one half period, ADC LSB.
    pub fn dc(&self) -> u32 {
        self.dc_q12 >> 12
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use core::f64::consts::PI;

    /// The reference instrument: 8 000 LSB per sample above a 1 024 dark
    /// level, 3 kept samples per half period, 3*pi/4, 16 half periods.
    fn reference() -> AgcConfig {
        AgcConfig::new(8_000.0, 1_024.0, 3, 0.75 * PI, 16)
    }

    const FLAT: Spread = Spread {
        diff: 0,
        slope: 0,
        neg_sum: 0,
        sine: Sine {
            r: 0,
            h: 0,
            n_lift: 0,
        },
    };

    fn lit(dc_half: u32, spread: Spread) -> AgcInput {
        AgcInput::Lit { dc_half, spread }
    }

    /// A DC step settles with the filter's time constant: after 4096
    /// closures 1 - 1/e of the way (first-order, to 1e-3).
    #[test]
    fn filter_time_constant_is_4096_closures() {
        let cfg = reference();
        let mut agc = Agc::new(&cfg);
        agc.update(&cfg, lit(10_000, FLAT));
        for _ in 0..4096 {
            agc.update(&cfg, lit(20_000, FLAT));
        }
        let got = (agc.dc() as f64 - 10_000.0) / 10_000.0;
        let expect = 1.0 - (-1.0f64).exp();
        assert!((got - expect).abs() < 1e-3, "{got} vs {expect}");
    }

    /// The moment's excess is the exact DC excess of a closure whose
    /// residual has sine r and slope d: `-cos(phi0)*A*E`, E = 1 - sqrt(1 -
    /// r^2 - S/(1 - r^2)), S = (n^2 - 1)d^2/(3n^2), with the levels a
    /// closure of amplitude A gives (neg_sum = A*sin(phi0)*n*r, diff =
    /// A*sin(phi0)*n*d/2), to the series' 5e-4 at r = 0.35 rad. At 3pi/4 a
    /// spread raises the DC (cos(phi0) < 0), so the excess removed is
    /// positive; without a slope it is the residual's alone.
    #[test]
    fn moment_removes_the_spread_excess() {
        let (phi0, n) = (0.75 * PI, 16);
        let cfg = AgcConfig::new(8_000.0, 1_024.0, 3, phi0, n);
        let nf = n as f64;
        for (r_rad, d_rad) in [(0.35, 0.05), (0.35, 0.0), (-0.2, 0.08), (0.01, 0.0)] {
            let neg_sum = if r_rad < 0.0 { -(1 << 20) } else { 1 << 20 };
            let a = neg_sum as f64 / (phi0.sin() * nf * r_rad);
            let diff = (a * phi0.sin() * nf * d_rad / 2.0).round() as i32;
            let r = (r_rad / RAD_PER_PHASE_LSB).round() as i32;
            let slope = (d_rad / RAD_PER_PHASE_LSB / 256.0).round() as i32;
            let s = Spread {
                diff,
                slope,
                neg_sum,
                sine: Sine::new(r),
            };
            let mut agc = Agc::new(&cfg);
            agc.update(&cfg, lit(50_000, s));
            let q = r_rad * r_rad;
            let spread = (nf * nf - 1.0) * d_rad * d_rad / (3.0 * nf * nf);
            let e = 1.0 - (1.0 - q - spread / (1.0 - q)).sqrt();
            let excess = -phi0.cos() * a * e;
            let removed = 50_000.0 - agc.dc() as f64;
            assert!(excess > 0.0);
            assert!(
                (removed - excess).abs() <= 1.0 + 5e-4 * excess,
                "r {r_rad} d {d_rad}: {removed} vs {excess}"
            );
        }
    }

    /// Until a lit closure is fed (at start, after clipped closures, after
    /// darkness) the normaliser is the closure's own DC; then the filter's.
    #[test]
    fn seeds_on_first_good_closure_and_after_light_loss() {
        let cfg = reference();
        let mut agc = Agc::new(&cfg);
        assert_eq!(agc.normaliser(&cfg, 30_000), u32::MAX / 30_000);
        // A clipped closure is not fed: the next still normalises by its own.
        assert_eq!(agc.normaliser(&cfg, 35_000), u32::MAX / 35_000);
        agc.update(&cfg, lit(30_000, FLAT));
        assert_eq!(agc.normaliser(&cfg, 99_000), u32::MAX / 30_000);
        agc.update(&cfg, AgcInput::Dark);
        assert_eq!(agc.normaliser(&cfg, 40_000), u32::MAX / 40_000);
        // Never below the power-low threshold: the error scaling's range.
        assert_eq!(agc.normaliser(&cfg, 10), u32::MAX / cfg.h0_min);
    }

    /// The derived constants against their formulas.
    #[test]
    fn config_follows_the_detector_levels() {
        let cfg = reference();
        assert_eq!(cfg.h0_nominal, 24_000);
        assert_eq!(cfg.h0_min, 6_000);
        assert_eq!(cfg.dark_half, 3_072);
        // 2^8 * 2(n^2 - 1)/(3 n^2) at n = 16.
        assert_eq!(
            cfg.spread_q8,
            (256.0 * 2.0 * 255.0 / 768.0f64).round() as i32
        );
    }
}
