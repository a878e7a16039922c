//! The closure step: everything the 12.5 kHz interrupt does for the FOG.
//!
//! Batch processing as in quartiq's stabilizer: the interrupt hands over the ADC
//! samples of step k (taken while the DAC words of step k were applied) and gets
//! back the DAC words of step k+1, or with one step of DAC latency (the hw
//! DMA ping-pong) of step k+2. The immutable [`FogConfig`] is passed in; all
//! mutable state lives in [`FogLoop`].

use super::config::{FogConfig, Kernel};
use super::demod::demodulate;
use super::faults::Faults;
use super::gain_loop;
use super::modulator::{Carries, Modulator};
use super::shr_saturate;
use super::vibration::VibrationCorrection;

/// What one closure step produces.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ClosureOutput {
    /// Sagnac phase measured over this step (feedback step applied plus the
    /// demodulated residual), phase LSB (2*pi/2^32 rad; rate = step *
    /// RAD_PER_PHASE_LSB / K_s). Not wrapped: it counts whole fringes beyond +-pi.
    pub step: i64,
    /// `step` less the epsilon-squared bias estimate (equal to `step` when off).
    pub step_corrected: i64,
    /// Demodulated mean residual of this step, phase LSB.
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
    /// Where the words reset (for the 2*pi loop).
    carries: Carries,
    /// Their depth dither's gain factor less one, Q32 (see `write_next`).
    dither_fm1_q32: i32,
    /// The feedback step they carry, phase LSB. Kept only with DAC latency;
    /// without, it is [`FogLoop::step`].
    step: i64,
}

/// Mutable state of one FOG channel.
#[derive(Clone, Copy, Debug)]
pub struct FogLoop {
    /// Integrator: the feedback step last written, phase LSB, unwrapped.
    step: i64,
    /// Digital gain, DAC codes per turn in Q8.
    cpt_q8: u32,
    /// Low-passed DC of one half period, ADC LSB in Q12 (below 2^32: a half
    /// period's kept sum is below 2^20); time constant 4096 steps (0.33 s).
    /// Slow on purpose: a step's DC has a first-order term in the
    /// in-step residual slope (proportional to eps), so a fast AGC would modulate
    /// the loop gain at the vibration frequency and rectify a second eps^2 drift.
    dc_q12: u32,
    /// The DC filter holds a measured value (seeded on the first good step).
    dc_valid: bool,
    modulator: Modulator,
    /// The DAC words the next call's samples were taken with.
    applied: Written,
    /// With one step of DAC latency: the words written last call, applied
    /// after `applied`.
    in_flight: Written,
    vibration: VibrationCorrection,
    unlocked_steps: u16,
    faults: Faults,
    /// xorshift32 state of the depth dither.
    dither: u32,
}

/// Largest kept-sample sum of one half period, ADC LSB (15 kept samples of
/// 16-bit codes), so the Q12 DC filter fits a u32.
const MAX_HALF_SUM: u32 = (1 << 20) - 1;

/// Feedback-step clamp: +-2^40 LSB is +-256 turns, about +-1200 rad/s at K_s = 1.35 s.
const STEP_LIMIT: i64 = 1 << 40;

/// `step` clamped to [-STEP_LIMIT, STEP_LIMIT - 1]: the high word decides
/// (one `ssat`), not a 64-bit compare.
#[inline(always)]
fn clamp_step(step: i64) -> i64 {
    const LIM: i32 = (STEP_LIMIT >> 32) as i32;
    let hi = (step >> 32) as i32;
    let sat = hi.clamp(-LIM, LIM - 1);
    if sat == hi {
        step
    } else {
        (sat as i64) << 32 | (!(sat >> 31) as u32) as i64
    }
}

impl FogLoop {
    pub fn new(cfg: &FogConfig) -> Self {
        Self {
            step: 0,
            cpt_q8: cfg.cpt_nominal_q8,
            dc_q12: cfg.h0_nominal.min(MAX_HALF_SUM) << 12,
            dc_valid: false,
            modulator: Modulator::default(),
            applied: Written::default(),
            in_flight: Written::default(),
            vibration: VibrationCorrection::default(),
            unlocked_steps: 0,
            faults: Faults::default(),
            dither: 0x9E37_79B9,
        }
    }

    /// Writes the first step's DAC words (before any ADC data exists). With
    /// one step of DAC latency the caller copies them into the other buffer
    /// too: both are applied before the first new words.
    pub fn start(&mut self, cfg: &FogConfig, dac: &mut [u16]) {
        if let Some(dac) = dac.get_mut(..cfg.n_half) {
            if cfg.params.dac_latency_steps == 0 {
                self.write_next::<0>(cfg, dac);
            } else {
                self.write_next::<1>(cfg, dac);
                self.applied = self.in_flight;
            }
        }
    }

    /// Writes the next step's DAC words at depth phi0 + r, r the depth dither,
    /// uniform in [-2^(dither_bits-1), 2^(dither_bits-1)) phase LSB
    /// (xorshift32; a golden-ratio sequence was tried and its lines beat with
    /// the reset pattern at some rates), and keeps r's gain factor for the
    /// step that will demodulate these words, `LATENCY` calls later.
    #[inline(always)]
    fn write_next<const LATENCY: usize>(&mut self, cfg: &FogConfig, dac: &mut [u16]) {
        let mut x = self.dither;
        x ^= x << 13;
        x ^= x >> 17;
        x ^= x << 5;
        self.dither = x;
        // bits = 0: off.
        let r = (x as i32).checked_shr(32 - cfg.dither_bits).unwrap_or(0);
        // 1 - r*cot(phi0) less one, Q32, from x = r * 2^(32 - bits) (the
        // dropped low bits are under 2^-bits of it).
        let dither_fm1_q32 = ((x as i32 as i64 * cfg.dither_gain as i64) >> 32) as i32;
        let carries = self.modulator.write_step(
            self.step as u32,
            cfg.phi0.wrapping_add_signed(r),
            self.cpt_q8,
            dac,
        );
        if LATENCY == 0 {
            self.applied.carries = carries;
            self.applied.dither_fm1_q32 = dither_fm1_q32;
        } else {
            self.applied = self.in_flight;
            self.in_flight = Written {
                carries,
                dither_fm1_q32,
                step: self.step,
            };
        }
    }

    /// One closure step. `adc`: `cfg.n_samples` samples of the step just applied;
    /// `adc_over_range`: the ADC's analog watchdog fired during them;
    /// `dac`: receives `cfg.n_half` words for the next step. Never panics: short
    /// buffers are treated as a lost (held) step. Inlined so the interrupt
    /// (and the rig's `process_core`) holds the step without a call.
    #[inline(always)]
    pub fn process(
        &mut self,
        cfg: &FogConfig,
        adc: &[u16],
        adc_over_range: bool,
        dac: &mut [u16],
    ) -> ClosureOutput {
        let layout = (cfg.n_half, cfg.samples_per_half, cfg.skip_samples);
        match cfg.kernel {
            Kernel::Half16 => self.step_with::<0>((16, 4, 1), cfg, adc, adc_over_range, dac),
            Kernel::Half32 => self.step_with::<0>((32, 4, 1), cfg, adc, adc_over_range, dac),
            Kernel::Any => self.step_with::<0>(layout, cfg, adc, adc_over_range, dac),
            Kernel::AnyLatency1 => self.step_with::<1>(layout, cfg, adc, adc_over_range, dac),
        }
    }

    /// [`Self::process`] for `(n_half, samples_per_half, skip)` = `layout`
    /// and DAC latency `LATENCY` (equal to the config's).
    #[inline(always)]
    fn step_with<const LATENCY: usize>(
        &mut self,
        (n_half, samples_per_half, skip): (usize, usize, usize),
        cfg: &FogConfig,
        adc: &[u16],
        adc_over_range: bool,
        dac: &mut [u16],
    ) -> ClosureOutput {
        let n_samples = n_half * samples_per_half;
        let (Some(adc), Some(dac)) = (adc.get(..n_samples), dac.get_mut(..n_half)) else {
            self.faults.set(Faults::ADC_SATURATION, true);
            return self.output(self.step, 0, 0, 0);
        };
        // The feedback step these samples were taken with.
        let applied_step = if LATENCY == 0 {
            self.step
        } else {
            self.applied.step
        };
        let sums = demodulate(adc, samples_per_half, skip, n_half, &self.applied.carries);
        // Detector DC of one half period, ADC dark level removed (per-half sum).
        let h_step = (sums.dc / n_half as u32).saturating_sub(cfg.dark_half);
        let power_low = h_step < cfg.h0_min;
        self.faults.set(Faults::OPTICAL_POWER_LOW, power_low);
        self.faults.set(Faults::ADC_SATURATION, adc_over_range);

        let mut residual = 0i32;
        let mut bias = 0i32;
        // Sagnac phase measured over this step: applied step plus residual.
        let mut measured = applied_step;
        if power_low {
            // Safe path: the error means nothing without light. Hold the step and
            // the gain; the output repeats the last good step (flagged); the AGC
            // restarts when the light comes back.
            self.dc_valid = false;
        } else {
            // Slow AGC: normalise by a low-passed DC so the loop gain does not depend
            // on optical power, without correlating the gain with this step's error.
            // Frozen while the ADC clips (the DC is then wrong).
            let h_step = h_step.min(MAX_HALF_SUM);
            // Seeded from this step's DC, then re-seeded below with its flat value.
            let seeding = !self.dc_valid;
            if seeding {
                self.dc_q12 = h_step << 12;
                self.dc_valid = !adc_over_range;
            }
            // Not below h0_min (kn's range; the DC filter can sit under it while
            // this step's DC is above).
            let h = (self.dc_q12 >> 12).max(cfg.h0_min).max(2);
            // 2^32 / H.
            let recip_h = u32::MAX / h;
            // Residual per unit sum(sign*h), phase LSB in Q16: k_meas/H, times
            // the dither's factor for this step's depth (1 - r*cot(phi0)):
            // undone per step, the dither's slope change would multiply the
            // residual by a random gain, a white error that grows with the
            // residual under vibration. Config bounds k_meas/h0_min times the
            // factor so that kn < 2^31; the factor is one `smmla`.
            let kn = ((cfg.k_meas as u64 * recip_h as u64) >> 16) as i32;
            let kn = kn + ((kn as i64 * self.applied.dither_fm1_q32 as i64) >> 32) as i32;
            // Kept sums < 2^20 per half, at most 64 halves: |sum|, |diff| < 2^26;
            // kn < 2^31: both products below 2^57. The residual
            // saturates at +-half a turn: the error is periodic, so an estimate
            // beyond that only says "far out" (lock acquisition then takes
            // several steps, as it would anyway).
            let neg_sum = -(sums.first + sums.second);
            residual = shr_saturate::<16, 32>(neg_sum as i64 * kn as i64);
            // In-step slope (second half's residual less the first's), 2^-3
            // phase LSB, saturated to the i32 range (+-0.37 rad).
            let diff = sums.first - sums.second;
            let slope_q3 = shr_saturate::<12, 32>(diff as i64 * kn as i64);
            // The same in 2^8 LSB, saturated at +-2^20.
            let slope = slope_q3 >> 11;

            // Clipped samples still give the error's sign, so the main loop keeps
            // running through over-range (holding it could lock it there); the
            // gain loop and the correction, which need true levels, pause.
            measured = applied_step + residual as i64;
            let correction = if LATENCY == 0 {
                // |residual| < 2^31, gain < 2^17 (Q16 below 2): one 32x32 product.
                (residual as i64 * cfg.loop_gain_q16 as i64) >> 16
            } else {
                // The words in flight already carry a step this measurement
                // has not seen: integrating the residual alone would count
                // it twice (unit gain then sits on the stability limit,
                // z^2 - z + 1). Correcting toward the measured phase from
                // the last step written (a Smith predictor for the pure
                // delay) keeps the latency-free loop's dynamics, delayed by
                // one step. |measured - step| < 2^42: the product < 2^59.
                ((measured - self.step) * cfg.loop_gain_q16 as i64) >> 16
            };
            self.step = clamp_step(self.step + correction);
            if !adc_over_range {
                // Under strong dynamics the step's DC carries the residual's
                // delta^2 (22 % of it at 0.19 rad near the dark fringe),
                // far more than a reset's 2*pi*g: the 2*pi loop holds while
                // |residual| > gain_hold_limit (V_pi drifts slowly).
                if residual.unsigned_abs() <= cfg.gain_hold_limit {
                    let err = gain_loop::reset_error(&sums, &self.applied.carries, n_half as u32);
                    self.cpt_q8 = gain_loop::update(
                        self.cpt_q8,
                        err,
                        cfg.gain_loop,
                        recip_h,
                        cfg.cpt_min_q8,
                        cfg.cpt_max_q8,
                    );
                }
                if cfg.vibration_correction {
                    bias = self.vibration.update(slope_q3, residual, cfg.vib_coeff);
                }
                // The DC filter takes the DC the light would give with no
                // residual: the step's spread of residual raises the DC by
                // dc_moment * m (config.rs), m >= 0 in ADC LSB x phase LSB.
                // |diff| < 2^27, |slope * spread| < 2^29, |sum| < 2^27,
                // |residual| < 2^31: |m| < 2^58 and its high word below 2^26
                // (dropping the low word costs under 1e-4 of the DC).
                let m = diff as i64 * slope.wrapping_mul(cfg.dc_spread_q8) as i64
                    + neg_sum as i64 * residual as i64;
                let excess = ((m >> 32) * cfg.dc_moment_q60 as i64) >> 28;
                let h_flat = (h_step as i32 - excess as i32).clamp(0, MAX_HALF_SUM as i32) as u32;
                self.dc_q12 = if seeding {
                    h_flat << 12
                } else {
                    self.dc_q12 - (self.dc_q12 >> 12) + h_flat
                };
            }
            let unlocked = residual.unsigned_abs() > cfg.lock_limit;
            self.unlocked_steps = if unlocked {
                self.unlocked_steps.saturating_add(1)
            } else {
                0
            };
            if self.unlocked_steps >= cfg.lock_steps {
                self.faults.set(Faults::OUT_OF_LOCK, true);
            } else if self.unlocked_steps == 0 {
                self.faults.set(Faults::OUT_OF_LOCK, false);
            }
        }
        // The DAC words first: written straight from registers (built
        // after the output, they were spilled to the stack).
        self.write_next::<LATENCY>(cfg, dac);
        self.output(measured, residual, bias, h_step)
    }

    fn output(&self, measured: i64, residual: i32, bias: i32, dc: u32) -> ClosureOutput {
        ClosureOutput {
            step: measured,
            step_corrected: measured - bias as i64,
            residual,
            codes_per_turn_q8: self.cpt_q8,
            dc,
            faults: self.faults,
        }
    }

    /// Current feedback step, phase LSB.
    pub fn step(&self) -> i64 {
        self.step
    }
}

#[cfg(test)]
mod tests {
    use super::{clamp_step, STEP_LIMIT};

    /// The high-word clamp equals the plain 64-bit clamp everywhere, the
    /// edges and the whole i64 range included.
    #[test]
    fn clamp_step_is_the_64_bit_clamp() {
        let reference = |s: i64| s.clamp(-STEP_LIMIT, STEP_LIMIT - 1);
        let edges = [
            i64::MIN,
            i64::MIN + 1,
            -STEP_LIMIT - 1,
            -STEP_LIMIT,
            -STEP_LIMIT + 1,
            -1,
            0,
            1,
            STEP_LIMIT - 2,
            STEP_LIMIT - 1,
            STEP_LIMIT,
            STEP_LIMIT + 1,
            i64::MAX - 1,
            i64::MAX,
        ];
        for s in edges {
            assert_eq!(clamp_step(s), reference(s), "step {s}");
        }
        // A deterministic sweep over every magnitude (splitmix64).
        let mut x: u64 = 0x9E37_79B9_7F4A_7C15;
        for _ in 0..100_000 {
            x = x.wrapping_add(0x9E37_79B9_7F4A_7C15);
            let mut z = x;
            z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
            z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
            let s = ((z ^ (z >> 31)) as i64) >> (z % 64);
            assert_eq!(clamp_step(s), reference(s), "step {s}");
        }
    }
}
