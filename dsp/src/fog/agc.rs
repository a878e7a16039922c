//! Slow AGC: the demodulated error is normalised by a low-passed detector DC,
//! so the loop gain does not depend on optical power, without correlating
//! the gain with the closure's own error. The DC filter takes the DC the
//! light would give with no residual spread: a residual spread within the
//! closure raises the DC by -A*cos(phi0)*<delta^2>/2 (the "DC moment",
//! docs/fog.md, "AGC and the DC moment"), which would otherwise lower the
//! loop gain under dynamics.

use super::config::FogParams;
#[allow(unused_imports)] // f64 maths comes from libm where core lacks it
use num_traits::float::Float;

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
}

impl AgcConfig {
    /// From the nominal and dark detector levels per sample, the kept
    /// samples per half period, the depth and the half periods per closure.
    pub fn new(p: &FogParams, n_half: usize) -> Self {
        let kept = p.samples_per_half.saturating_sub(p.skip_samples) as f64;
        let h0_nominal = p.nominal_dc_lsb * kept;
        let nf = n_half as f64;
        let moment = -(1.0 / p.phi0_rad.tan()) / (2.0 * nf) * crate::RAD_PER_PHASE_LSB;
        Self {
            h0_nominal: h0_nominal.round() as u32,
            h0_min: (h0_nominal * 0.25).round().max(2.0) as u32,
            dark_half: (p.dark_lsb.max(0.0) * kept).round() as u32,
            spread_q8: (256.0 * 2.0 * (nf * nf - 1.0) / (3.0 * nf * nf)).round() as i32,
            moment_q60: (moment * (1u64 << 60) as f64)
                .round()
                .clamp(i32::MIN as f64, i32::MAX as f64) as i32,
        }
    }

    /// Detector DC of one half period, dark level removed, from the
    /// closure's kept-sample sum over `n_half` half periods.
    #[inline(always)]
    pub fn dc_half(&self, dc_sum: u32, n_half: usize) -> u32 {
        (dc_sum / n_half as u32).saturating_sub(self.dark_half)
    }
}

/// The DC filter: one half period's DC, ADC LSB in Q12 (below 2^32);
/// time constant 4096 closures (0.33 s). Slow on purpose: a closure's DC has
/// a first-order term in the in-closure residual slope (proportional to
/// eps), so a fast AGC would modulate the loop gain at the vibration
/// frequency and rectify a second eps^2 drift.
#[derive(Clone, Copy, Debug)]
pub struct Agc {
    dc_q12: u32,
    /// Holds a measured value (seeded on the first good closure).
    valid: bool,
}

/// The in-closure residual spread the DC moment is measured from: the
/// demodulated sums, the slope and the residual (closure.rs).
#[derive(Clone, Copy, Debug)]
pub struct Spread {
    /// Sum of the first half's signed levels less the second's, LSB.
    pub diff: i32,
    /// In-closure slope, 2^8 phase LSB (|slope| <= 2^20).
    pub slope: i32,
    /// Minus the closure's signed level sum, LSB.
    pub neg_sum: i32,
    /// Mean residual, phase LSB.
    pub residual: i32,
}

impl Agc {
    pub fn new(cfg: &AgcConfig) -> Self {
        Self {
            dc_q12: cfg.h0_nominal.min(MAX_HALF_SUM) << 12,
            valid: false,
        }
    }

    /// No light: the AGC restarts from the next good closure.
    pub fn light_lost(&mut self) {
        self.valid = false;
    }

    /// The normalising DC for this closure: returns 2^32/H (H not below
    /// h0_min, the error scaling's range) and whether the filter was just
    /// seeded from this closure's DC (not while the ADC clips).
    #[inline(always)]
    pub fn normaliser(
        &mut self,
        cfg: &AgcConfig,
        dc_half: u32,
        adc_over_range: bool,
    ) -> (u32, bool) {
        let seeding = !self.valid;
        if seeding {
            self.dc_q12 = dc_half.min(MAX_HALF_SUM) << 12;
            self.valid = !adc_over_range;
        }
        let h = (self.dc_q12 >> 12).max(cfg.h0_min).max(2);
        (u32::MAX / h, seeding)
    }

    /// Advances the filter with this closure's DC less its moment excess
    /// (re-seeds with that flat value on the seeding closure).
    /// |diff| < 2^27, |slope * spread| < 2^29, |sum| < 2^27, |residual| <
    /// 2^31: |m| < 2^58 and its high word below 2^26 (dropping the low word
    /// costs under 1e-4 of the DC).
    #[inline(always)]
    pub fn update(&mut self, cfg: &AgcConfig, dc_half: u32, s: Spread, seeding: bool) {
        let m = s.diff as i64 * s.slope.wrapping_mul(cfg.spread_q8) as i64
            + s.neg_sum as i64 * s.residual as i64;
        let excess = ((m >> 32) * cfg.moment_q60 as i64) >> 28;
        let dc = dc_half.min(MAX_HALF_SUM) as i32;
        let flat = (dc - excess as i32).clamp(0, MAX_HALF_SUM as i32) as u32;
        self.dc_q12 = if seeding {
            flat << 12
        } else {
            self.dc_q12 - (self.dc_q12 >> 12) + flat
        };
    }

    /// Filtered DC of one half period, ADC LSB.
    pub fn dc(&self) -> u32 {
        self.dc_q12 >> 12
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A DC step settles with the filter's time constant: after 4096
    /// closures 1 - 1/e of the way (first-order, to 1e-3).
    #[test]
    fn filter_time_constant_is_4096_closures() {
        let p = FogParams::default();
        let cfg = AgcConfig::new(&p, 16);
        let mut agc = Agc::new(&cfg);
        let flat = Spread {
            diff: 0,
            slope: 0,
            neg_sum: 0,
            residual: 0,
        };
        let (_, seeding) = agc.normaliser(&cfg, 10_000, false);
        agc.update(&cfg, 10_000, flat, seeding);
        for _ in 0..4096 {
            let (_, seeding) = agc.normaliser(&cfg, 20_000, false);
            assert!(!seeding);
            agc.update(&cfg, 20_000, flat, seeding);
        }
        let got = (agc.dc() as f64 - 10_000.0) / 10_000.0;
        let expect = 1.0 - (-1.0f64).exp();
        assert!((got - expect).abs() < 1e-3, "{got} vs {expect}");
    }

    /// The moment's excess is what the formula gives: at 3pi/4 a spread
    /// raises the DC (cos(phi0) < 0), so the excess removed is positive.
    #[test]
    fn moment_removes_the_spread_excess() {
        let p = FogParams::default();
        let n = 16;
        let cfg = AgcConfig::new(&p, n);
        let s = Spread {
            diff: 0,
            slope: 0,
            neg_sum: 1 << 20,
            residual: 1 << 26,
        };
        let mut agc = Agc::new(&cfg);
        agc.update(&cfg, 50_000, s, true);
        let m = (s.neg_sum as f64) * (s.residual as f64);
        let excess = m * -(1.0 / p.phi0_rad.tan()) / (2.0 * n as f64) * crate::RAD_PER_PHASE_LSB;
        let removed = 50_000.0 - agc.dc() as f64;
        assert!(excess > 0.0);
        assert!(
            (removed - excess).abs() <= 1.0 + 1e-3 * excess,
            "{removed} vs {excess}"
        );
    }

    #[test]
    fn seeds_on_first_good_closure_and_after_light_loss() {
        let cfg = AgcConfig::new(&FogParams::default(), 16);
        let mut agc = Agc::new(&cfg);
        assert!(agc.normaliser(&cfg, 30_000, true).1);
        // Seeded while clipping: not valid, seeds again.
        assert!(agc.normaliser(&cfg, 30_000, false).1);
        assert!(!agc.normaliser(&cfg, 30_000, false).1);
        agc.light_lost();
        let (recip, seeding) = agc.normaliser(&cfg, 40_000, false);
        assert!(seeding);
        assert_eq!(recip, u32::MAX / 40_000);
    }
}
