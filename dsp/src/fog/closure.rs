//! The closure: everything the 12.5 kHz interrupt does for the FOG.
//!
//! Batch processing as in quartiq's stabilizer: the interrupt hands over the
//! ADC samples of closure k (taken while the DAC words of closure k were
//! applied) and gets back the DAC words of closure k+1, or with one closure
//! of DAC latency (the hw DMA ping-pong) of closure k+2. The immutable
//! [`FogConfig`] is passed in; all mutable state lives in [`FogLoop`], one
//! field per block.

use super::agc::{Agc, AgcInput, Spread};
use super::config::FogConfig;
use super::demod::demodulate;
use super::dither::Dither;
use super::faults::Faults;
use super::gain_loop::GainLoop;
use super::layout::Kernel;
use super::lock::LockDetector;
use super::modulator::{Modulator, Resets};
use super::residual::Sine;
use super::vibration::VibrationCorrection;
use crate::fixed::shr_saturate;

/// What one closure produces.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ClosureOutput {
    /// Sagnac phase measured over this closure (feedback phase applied plus
    /// the demodulated residual), phase LSB (2*pi/2^32 rad; rate = phase *
    /// RAD_PER_PHASE_LSB / K_s). Not wrapped: it counts whole fringes beyond +-pi.
    pub sagnac_phase: i64,
    /// `sagnac_phase` less the epsilon-squared bias estimate (equal when off).
    pub sagnac_phase_corrected: i64,
    /// Mean residual phase of this closure, phase LSB: asin of the
    /// demodulated residual (residual.rs).
    pub residual: i32,
    /// Digital modulator gain (DAC codes per turn, Q8) from the 2*pi loop.
    pub codes_per_turn_q8: u32,
    /// Detector DC, kept-sample sum of one half period, ADC LSB.
    pub dc: u32,
    pub faults: Faults,
}

/// What the closure needs to know about DAC words when their samples come back.
#[derive(Clone, Copy, Debug, Default)]
struct Written {
    /// Where the serrodyne resets fell (for the 2*pi loop).
    resets: Resets,
    /// Their depth dither's gain factor less one, Q32.
    dither_gain_m1_q32: i32,
    /// The feedback phase they carry, phase LSB. Kept only with DAC
    /// latency; without, it is [`FogLoop::feedback`].
    feedback: i64,
}

/// Mutable state of one FOG channel.
#[derive(Clone, Copy, Debug)]
pub struct FogLoop {
    /// Integrator: the feedback phase last written, phase LSB, unwrapped.
    feedback: i64,
    /// The 2*pi loop: the digital gain, DAC codes per turn.
    gain_loop: GainLoop,
    agc: Agc,
    modulator: Modulator,
    /// The DAC words the next call's samples were taken with.
    applied: Written,
    /// With one closure of DAC latency: the words written last call,
    /// applied after `applied`.
    in_flight: Written,
    vibration: VibrationCorrection,
    lock: LockDetector,
    faults: Faults,
    dither: Dither,
}

/// Feedback-phase clamp: +-2^40 LSB is +-256 turns, about +-1200 rad/s at K_s = 1.35 s.
const FEEDBACK_LIMIT: i64 = 1 << 40;

/// `phase` clamped to [-FEEDBACK_LIMIT, FEEDBACK_LIMIT - 1]: the high word
/// decides (one `ssat`), not a 64-bit compare.
#[inline(always)]
fn clamp_feedback(phase: i64) -> i64 {
    const LIM: i32 = (FEEDBACK_LIMIT >> 32) as i32;
    let hi = (phase >> 32) as i32;
    let sat = hi.clamp(-LIM, LIM - 1);
    if sat == hi {
        phase
    } else {
        (sat as i64) << 32 | (!(sat >> 31) as u32) as i64
    }
}

/// `(neg_sum * gain + 2^15) >> 16` saturated to the i32 range: the
/// residual (phase LSB) rounded to the nearest LSB. The unrounded product's
/// high word decides the saturation, one step early at the top (2^16 LSB,
/// 1e-4 rad short of half a turn, where the residual only says "far out"),
/// so the rounding's carry cannot wrap: one `smull`, an add with carry and
/// the high-word compare, no 64-bit clamp.
#[inline(always)]
fn round_residual(neg_sum: i32, gain: i32) -> i32 {
    const LIM: i32 = 1 << 15;
    let p = neg_sum as i64 * gain as i64;
    let hi = (p >> 32) as i32;
    if hi.clamp(-LIM, LIM - 2) == hi {
        ((p + (1 << 15)) >> 16) as i32
    } else {
        (hi >> 31) ^ i32::MAX
    }
}

impl FogLoop {
    pub fn new(cfg: &FogConfig) -> Self {
        Self {
            feedback: 0,
            gain_loop: GainLoop::new(&cfg.gain_loop),
            agc: Agc::new(&cfg.agc),
            modulator: Modulator::default(),
            applied: Written::default(),
            in_flight: Written::default(),
            vibration: VibrationCorrection::default(),
            lock: LockDetector::default(),
            faults: Faults::default(),
            dither: Dither::default(),
        }
    }

    /// Writes the first closure's DAC words (before any ADC data exists).
    /// With one closure of DAC latency the caller copies them into the other
    /// buffer too: both are applied before the first new words.
    pub fn start(&mut self, cfg: &FogConfig, dac: &mut [u16]) {
        if let Some(dac) = dac.get_mut(..cfg.n_half) {
            if cfg.params.dac_latency == 0 {
                self.write_next::<0, 0>(cfg, dac);
            } else {
                self.write_next::<1, 0>(cfg, dac);
                self.applied = self.in_flight;
            }
        }
    }

    /// Writes the next closure's DAC words (`H` half periods, 0: the
    /// config's) at depth phi0 + r, r the dither, and keeps what the closure
    /// that demodulates them, `LATENCY` calls later, needs.
    #[inline(always)]
    fn write_next<const LATENCY: usize, const H: usize>(
        &mut self,
        cfg: &FogConfig,
        dac: &mut [u16],
    ) {
        let depth = self.dither.update(&cfg.dither);
        let dither_gain_m1_q32 = depth.gain_m1_q32;
        let resets = self.modulator.write_closure::<H>(
            self.feedback as u32,
            cfg.phi0.wrapping_add(depth.offset),
            self.gain_loop.codes_per_turn_q8(),
            dac,
        );
        if LATENCY == 0 {
            self.applied.resets = resets;
            self.applied.dither_gain_m1_q32 = dither_gain_m1_q32;
        } else {
            self.applied = self.in_flight;
            self.in_flight = Written {
                resets,
                dither_gain_m1_q32,
                feedback: self.feedback,
            };
        }
    }

    /// One closure. `adc`: `cfg.n_samples` samples of the closure just
    /// applied; `adc_over_range`: the ADC's analog watchdog fired during
    /// them; `dac`: receives `cfg.n_half` words for the next closure. Never
    /// panics: short buffers are treated as a lost (held) closure. Inlined
    /// so the interrupt (and the rig's `process_core`) holds it without a call.
    #[inline(always)]
    pub fn process(
        &mut self,
        cfg: &FogConfig,
        adc: &[u16],
        adc_over_range: bool,
        dac: &mut [u16],
    ) -> ClosureOutput {
        // The one place a layout becomes sizes: (latency, half periods,
        // samples per half, skipped); 0 sizes are the config's at run time.
        match cfg.kernel {
            Kernel::Half16 => self.closure_with::<0, 16, 4, 1>(cfg, adc, adc_over_range, dac),
            Kernel::Half32 => self.closure_with::<0, 32, 4, 1>(cfg, adc, adc_over_range, dac),
            Kernel::Any => self.closure_with::<0, 0, 0, 0>(cfg, adc, adc_over_range, dac),
            Kernel::AnyLatency1 => self.closure_with::<1, 0, 0, 0>(cfg, adc, adc_over_range, dac),
        }
    }

    /// [`Self::process`] for a layout of `H` half periods of `S` samples,
    /// `SKIP` skipped (all 0: the config's), and DAC latency `LATENCY`.
    #[inline(always)]
    fn closure_with<const LATENCY: usize, const H: usize, const S: usize, const SKIP: usize>(
        &mut self,
        cfg: &FogConfig,
        adc: &[u16],
        adc_over_range: bool,
        dac: &mut [u16],
    ) -> ClosureOutput {
        let (n_half, samples_per_half, skip) = if H == 0 {
            (cfg.n_half, cfg.samples_per_half, cfg.skip_samples)
        } else {
            (H, S, SKIP)
        };
        let n_samples = n_half * samples_per_half;
        let (Some(adc), Some(dac)) = (adc.get(..n_samples), dac.get_mut(..n_half)) else {
            self.faults.set(Faults::ADC_SATURATION, true);
            return self.output(self.feedback, 0, 0, 0);
        };
        // The feedback phase these samples were taken with.
        let applied = if LATENCY == 0 {
            self.feedback
        } else {
            self.applied.feedback
        };
        let sums =
            demodulate::<H, S, SKIP>(adc, samples_per_half, skip, n_half, &self.applied.resets);
        let dc_half = cfg.agc.dc_half::<H>(sums.dc);
        let power_low = dc_half < cfg.agc.h0_min;
        self.faults.set(Faults::OPTICAL_POWER_LOW, power_low);
        self.faults.set(Faults::ADC_SATURATION, adc_over_range);

        let mut residual = 0i32;
        let mut bias = 0i32;
        // Sagnac phase measured over this closure: applied feedback plus residual.
        let mut measured = applied;
        if power_low {
            // Safe path: the error means nothing without light. Hold the
            // feedback and the gain; the output repeats the last good phase
            // (flagged); the AGC restarts when the light comes back.
            self.agc.update(&cfg.agc, AgcInput::Dark);
        } else {
            let recip_h = self.agc.normaliser(&cfg.agc, dc_half);
            // Residual per unit sum(sign*h), phase LSB in Q16: per_count/H,
            // times the dither's factor for this closure's depth (1 -
            // r*cot(phi0)): not undone, the dither's slope change would
            // multiply the residual by a random gain, a white error that
            // grows with the residual under vibration. Config bounds
            // per_count/h0_min times the factor so that this is below 2^31;
            // the factor is one `smmla`.
            let gain = ((cfg.residual_per_count as u64 * recip_h as u64) >> 16) as i32;
            let gain = gain + ((gain as i64 * self.applied.dither_gain_m1_q32 as i64) >> 32) as i32;
            // Kept sums < 2^20 per half, at most 64 halves: |sum|, |diff| < 2^26;
            // gain < 2^31: both products below 2^57. The residual saturates
            // at +-half a turn: the error is periodic, so an estimate beyond
            // that only says "far out" (lock acquisition then takes several
            // closures, as it would anyway). Rounded: a floored residual
            // would bias the output by half an LSB, since the loop nulls the
            // mean of what it measures.
            let neg_sum = -(sums.first + sums.second);
            let demodulated = round_residual(neg_sum, gain);
            // In-closure slope (second half's residual less the first's),
            // 2^-3 phase LSB, saturated to the i32 range (+-0.37 rad).
            let diff = sums.first - sums.second;
            let slope_q3 = shr_saturate::<12, 32>(diff as i64 * gain as i64);
            // The demodulated residual is the sine of the residual phase:
            // the loop and the output take asin of it (residual.rs), the
            // correction and the AGC its square.
            let sine = Sine::new(demodulated);
            residual = sine.phase(demodulated);

            // Clipped samples still give the error's sign, so the main loop
            // keeps running through over-range (holding it could lock it
            // there); the gain loop, the correction and the AGC, which need
            // true levels, pause (the correction with a zero slope: no bias,
            // its carried fraction kept, and no branch). The correction and
            // the AGC first, while the residual's sine is in registers.
            let slope_true = if adc_over_range { 0 } else { slope_q3 };
            bias = self.vibration.update(&cfg.vibration, slope_true, &sine);
            if !adc_over_range {
                let spread = Spread {
                    diff,
                    // The slope in 2^8 LSB, saturated at +-2^20.
                    slope: slope_q3 >> 11,
                    neg_sum,
                    sine,
                };
                self.agc.update(&cfg.agc, AgcInput::Lit { dc_half, spread });
            }
            measured = applied + residual as i64;
            let correction = if LATENCY == 0 {
                // |residual| < 2^31, gain < 2^17 (Q16 below 2): one 32x32 product.
                (residual as i64 * cfg.loop_gain_q16 as i64) >> 16
            } else {
                // The words in flight already carry a phase this measurement
                // has not seen: integrating the residual alone would count
                // it twice (unit gain then sits on the stability limit,
                // z^2 - z + 1). Correcting toward the measured phase from
                // the last one written (a Smith predictor for the pure
                // delay, docs/fog.md) keeps the latency-free loop's
                // dynamics, delayed by one closure. |measured - feedback| <
                // 2^42: the product < 2^59.
                ((measured - self.feedback) * cfg.loop_gain_q16 as i64) >> 16
            };
            self.feedback = clamp_feedback(self.feedback + correction);
            if !adc_over_range {
                self.gain_loop.update(
                    &cfg.gain_loop,
                    &sums,
                    &self.applied.resets,
                    n_half as u32,
                    residual,
                    recip_h,
                );
            }
            if let Some(lost) = self.lock.update(&cfg.lock, residual) {
                self.faults.set(Faults::OUT_OF_LOCK, lost);
            }
        }
        // The DAC words first: written straight from registers (built
        // after the output, they were spilled to the stack).
        self.write_next::<LATENCY, H>(cfg, dac);
        self.output(measured, residual, bias, dc_half)
    }

    fn output(&self, measured: i64, residual: i32, bias: i32, dc: u32) -> ClosureOutput {
        ClosureOutput {
            sagnac_phase: measured,
            sagnac_phase_corrected: measured - bias as i64,
            residual,
            codes_per_turn_q8: self.gain_loop.codes_per_turn_q8(),
            dc,
            faults: self.faults,
        }
    }

    /// The slow side, outside the closure (the board calls it once per
    /// frame; `closures` closures ran since the last call): shifts the 2*pi
    /// loop to its tracking gain after it has been in lock long enough, and
    /// back to acquisition on a fault (gain_loop.rs). Judged on the last
    /// closure's faults: a lock loss lasts many closures; a fault that comes
    /// and goes between two calls leaves the gear as it was.
    pub fn supervise(&mut self, cfg: &FogConfig, closures: u32) {
        let healthy = !self
            .faults
            .intersects(Faults::OUT_OF_LOCK | Faults::OPTICAL_POWER_LOW | Faults::ADC_SATURATION);
        self.gain_loop.supervise(&cfg.gain_loop, closures, healthy);
    }

    /// True once the 2*pi loop runs on its tracking gain.
    pub fn gain_loop_tracking(&self, cfg: &FogConfig) -> bool {
        self.gain_loop.tracking(&cfg.gain_loop)
    }

    /// Current feedback phase, phase LSB, unwrapped.
    pub fn feedback(&self) -> i64 {
        self.feedback
    }
}

#[cfg(test)]
mod tests {
    use super::{clamp_feedback, round_residual, FEEDBACK_LIMIT};

    /// The rounded residual is the nearest integer of the product / 2^16,
    /// saturated: exact wherever it fits, half-LSB ties up, and at most
    /// 2^16 LSB early at the top.
    #[test]
    fn residual_rounds_to_nearest_and_saturates() {
        let reference = |a: i32, g: i32| {
            let x = (a as i64 * g as i64) as f64 / 65_536.0;
            (x + 0.5).floor().clamp(i32::MIN as f64, i32::MAX as f64) as i64
        };
        let mut x: u64 = 0x2545_F491_4F6C_DD1D;
        for k in 0..200_000u32 {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            let a = (x as i32) >> (k % 24);
            let g = ((x >> 32) as i32 & i32::MAX) >> (k % 8);
            let got = round_residual(a, g) as i64;
            let want = reference(a, g);
            if want < (1 << 31) - (1 << 16) {
                assert_eq!(got, want, "{a} * {g}");
            } else {
                assert!(
                    got == i32::MAX as i64 && want - got <= 1 << 16,
                    "{a} * {g}: {got} vs {want}"
                );
            }
        }
        assert_eq!(round_residual(1, 1 << 15), 1);
        assert_eq!(round_residual(1, (1 << 15) - 1), 0);
        assert_eq!(round_residual(-1, 1 << 15), 0);
        assert_eq!(round_residual(-1, (1 << 15) + 1), -1);
        assert_eq!(round_residual(1 << 26, i32::MAX), i32::MAX);
        assert_eq!(round_residual(-(1 << 26), i32::MAX), i32::MIN);
    }

    /// The high-word clamp equals the plain 64-bit clamp everywhere, the
    /// edges and the whole i64 range included.
    #[test]
    fn clamp_feedback_is_the_64_bit_clamp() {
        let reference = |s: i64| s.clamp(-FEEDBACK_LIMIT, FEEDBACK_LIMIT - 1);
        let edges = [
            i64::MIN,
            i64::MIN + 1,
            -FEEDBACK_LIMIT - 1,
            -FEEDBACK_LIMIT,
            -FEEDBACK_LIMIT + 1,
            -1,
            0,
            1,
            FEEDBACK_LIMIT - 2,
            FEEDBACK_LIMIT - 1,
            FEEDBACK_LIMIT,
            FEEDBACK_LIMIT + 1,
            i64::MAX - 1,
            i64::MAX,
        ];
        for s in edges {
            assert_eq!(clamp_feedback(s), reference(s), "phase {s}");
        }
        // A deterministic sweep over every magnitude (splitmix64).
        let mut x: u64 = 0x9E37_79B9_7F4A_7C15;
        for _ in 0..100_000 {
            x = x.wrapping_add(0x9E37_79B9_7F4A_7C15);
            let mut z = x;
            z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
            let s = ((z ^ (z >> 31)) as i64) >> (z % 64);
            assert_eq!(clamp_feedback(s), reference(s), "phase {s}");
        }
    }
}
