//! One RLG channel as the firmware runs it: the periodic update interrupt
//! reads the encoder timer ([`PulseCounter`]), and on sensor ticks advances the
//! thermal compensation ([`ThermalComp`]); on a dithered gyro the latch
//! interrupt hands each pickoff zero crossing to the stripping
//! ([`DitherStripper`]) and the update takes the stripped angle at the
//! previous update's instant (one update period of delay: the latch after
//! that instant has come by then). The frame words are taken at the frame
//! rate. Configuration is immutable ([`RlgConfig`]), state mutable.
//!
//! Formats: the output angle i64 Q16 counts (1/K deg, K = counts per
//! degree); B_TC Q16 deg/h; rates in the compensation: i64 nano-degrees per
//! second (ndps); frame rate word i32 micro-degrees per second (+-2147
//! deg/s, LSB 0.0036 deg/h). A frame's whole counts are the differences of
//! the floored cumulative angle, so they add up to it: no count is lost to
//! the fraction.

use super::counter::PulseCounter;
use super::dither::{DitherStripper, LatchSample, StripConfig, StripFlags};
use super::thermal::{RlgFlags, Temperatures, ThermalComp, ThermalConfig};

/// Updates a dithered channel waits at start for its first stripped angle
/// before it outputs the raw count, flagged (50 ms: a dead pickoff).
const START_WAIT: u32 = 25;

/// ndps per (deg/h), Q16: 1e9/3600 * 2^16.
const NDPS_PER_DPH_Q16: i64 = 18_204_444_444;

/// `rate - B_TC`: the compensation applied to a rate, the one place where it
/// is done (firmware frames and `gyro-lab compensate` call this).
/// rate: ndps; B_TC: Q16 deg/h (|B| < 2^47 Q16 keeps the product in i64).
#[inline(always)]
pub fn compensate_rate_ndps(rate_ndps: i64, bias_q16_dph: i64) -> i64 {
    let b = bias_q16_dph.clamp(-(1 << 40), 1 << 40);
    rate_ndps - ((b * (NDPS_PER_DPH_Q16 >> 16) + (1 << 15)) >> 16)
}

#[derive(Clone, Copy, Debug)]
pub struct RlgConfig {
    pub thermal: ThermalConfig,
    /// Nano-degrees per count, Q16.
    ndeg_per_count_q16: i64,
    /// RLG updates per second.
    update_hz: u32,
    /// A dithered gyro's stripping; None: the counter is read as it is.
    pub dither: Option<StripConfig>,
}

impl RlgConfig {
    /// `counts_per_deg`: K x 4 (quadrature edges); `update_hz`: the interrupt rate.
    pub fn new(thermal: ThermalConfig, counts_per_deg: f64, update_hz: u32) -> Self {
        let k = if counts_per_deg.is_finite() && counts_per_deg >= 1.0 {
            counts_per_deg
        } else {
            1.0
        };
        Self {
            thermal,
            ndeg_per_count_q16: (1e9 / k * 65_536.0) as i64,
            update_hz: update_hz.max(1),
            dither: None,
        }
    }

    /// The same on a dithered gyro.
    pub fn with_dither(self, strip: StripConfig) -> Self {
        Self {
            dither: Some(strip),
            ..self
        }
    }
}

/// The RLG words of one output frame.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct RlgWords {
    /// Counts over the frame (the angle increment, lossless).
    pub delta_counts: i32,
    /// Compensated rate over the frame, micro-deg/s.
    pub rate_comp_udps: i32,
    /// B_TC, Q16 deg/h, saturated to i32 (+-32768 deg/h).
    pub bias_q16_dph: i32,
    /// Sensor readings in use, Q8 degC (held values while a sensor is bad).
    pub t_mono_a_q8: i16,
    pub t_mono_b_q8: i16,
    pub t_case_q8: i16,
    /// Sensor and coefficient faults.
    pub flags: RlgFlags,
}

/// The angle span of one frame (from `take_frame`), Q16 counts, and the
/// updates in it.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct FrameSpan {
    pub from_q16: i64,
    pub to_q16: i64,
    pub updates: u32,
}

impl FrameSpan {
    /// Whole counts of the frame: differences of the floored cumulative angle.
    pub fn counts(&self) -> i64 {
        (self.to_q16 >> 16).wrapping_sub(self.from_q16 >> 16)
    }
}

#[derive(Clone, Copy, Debug, Default)]
pub struct RlgChannel {
    pub counter: PulseCounter,
    pub thermal: ThermalComp,
    pub strip: DitherStripper,
    /// The previous update's latch-timer time and raw angle (Q16 counts).
    prev: Option<(u32, i64)>,
    /// Output angle (stripped on a dithered gyro) at the latest update, and
    /// where the last frame taken ended; Q16 counts.
    out_q16: i64,
    taken_q16: i64,
    started: bool,
    /// The stripping has given an angle (after that, none is a fault), and
    /// the updates waited for it at start.
    stripping: bool,
    waited: u32,
    frame_updates: u32,
}

impl RlgChannel {
    /// A pickoff zero crossing (the latch interrupt).
    #[inline(always)]
    pub fn latch(&mut self, cfg: &RlgConfig, l: &LatchSample) {
        if let Some(sc) = &cfg.dither {
            self.strip.latch(sc, l, &self.counter);
        }
    }

    /// A pickoff crossing the latch hardware overwrote before it was read
    /// (flagged; the stripping refuses or restarts on the next one).
    #[inline(always)]
    pub fn latch_lost(&mut self) {
        self.strip.flag(StripFlags::LATCH_REFUSED);
    }

    /// The update interrupt at latch-timer time `time`: one counter read; the
    /// output angle (stripped at the previous update's instant on a dithered
    /// gyro, the raw count at this one otherwise); on sensor ticks (`temps`)
    /// the compensation advances too.
    #[inline(always)]
    pub fn update(
        &mut self,
        cfg: &RlgConfig,
        time: u32,
        raw_counter: u16,
        temps: Option<&Temperatures>,
    ) {
        self.counter.update(raw_counter);
        let raw_q16 = self.counter.angle_counts().wrapping_shl(16);
        let out = match &cfg.dither {
            None => Some(raw_q16),
            Some(_) => {
                let out = self.prev.and_then(|(t, raw_prev)| match self.strip.at(t) {
                    Some(v) => {
                        self.stripping = true;
                        Some(v)
                    }
                    None if self.stripping || self.waited >= START_WAIT => {
                        // Safe path: the raw count (with its dither), flagged.
                        self.strip.flag(StripFlags::NO_PICKOFF);
                        Some(raw_prev)
                    }
                    None => {
                        // Start-up: the frames start from the first stripped
                        // angle (a raw one carries the dither as an offset).
                        self.waited += 1;
                        None
                    }
                });
                self.prev = Some((time, raw_q16));
                out
            }
        };
        if let Some(o) = out {
            self.out_q16 = o;
            if !self.started {
                // Frames start from the first output (no step from zero).
                self.taken_q16 = o;
                self.started = true;
            }
        }
        self.frame_updates = self.frame_updates.wrapping_add(1);
        if let Some(t) = temps {
            self.thermal.update(&cfg.thermal, t);
        }
    }

    /// The output angle at the latest update, Q16 counts.
    pub fn angle_q16(&self) -> i64 {
        self.out_q16
    }

    /// The frame's span since the last call (main loop or the update task).
    pub fn take_frame(&mut self) -> FrameSpan {
        let span = FrameSpan {
            from_q16: self.taken_q16,
            to_q16: self.out_q16,
            updates: self.frame_updates,
        };
        self.taken_q16 = self.out_q16;
        self.frame_updates = 0;
        span
    }

    /// Puts back a span `take_frame` gave whose words could not be
    /// delivered: it goes out with the next update's.
    pub fn restore_frame(&mut self, span: FrameSpan) {
        self.taken_q16 = span.from_q16;
        self.frame_updates = self.frame_updates.wrapping_add(span.updates);
    }

    /// Builds the frame words from `take_frame`'s span (divides: the update
    /// task or the main loop, not the closure).
    pub fn words(&mut self, cfg: &RlgConfig, span: &FrameSpan) -> RlgWords {
        // rate = angle * ndeg/count * update_hz / updates, in i128: angles
        // per frame up to 2^47 Q16 and ndeg/count up to 2^46 (Q16) do not
        // fit i64.
        let n = span.updates.max(1) as i128;
        let d = span.to_q16.wrapping_sub(span.from_q16) as i128;
        let rate = ((d * cfg.ndeg_per_count_q16 as i128) >> 32) * cfg.update_hz as i128 / n;
        let rate_ndps = rate.clamp(i64::MIN as i128, i64::MAX as i128) as i64;
        let b = self.thermal.bias_q16();
        let comp = compensate_rate_ndps(rate_ndps, b);
        let t = self.thermal.in_use_q8();
        let q8 = |x: i32| x.clamp(i16::MIN as i32, i16::MAX as i32) as i16;
        let strip = self.strip.take_flags();
        let mut flags = self.thermal.flags();
        flags.set(RlgFlags::NO_PICKOFF, strip.contains(StripFlags::NO_PICKOFF));
        flags.set(
            RlgFlags::LATCH_REFUSED,
            strip.intersects(StripFlags::LATCH_REFUSED | StripFlags::PHOTODIODES_WEAK),
        );
        RlgWords {
            delta_counts: span.counts().clamp(i32::MIN as i64, i32::MAX as i64) as i32,
            rate_comp_udps: (comp / 1000).clamp(i32::MIN as i64, i32::MAX as i64) as i32,
            bias_q16_dph: b.clamp(i32::MIN as i64, i32::MAX as i64) as i32,
            t_mono_a_q8: q8(t[0]),
            t_mono_b_q8: q8(t[1]),
            t_case_q8: q8(t[2]),
            flags,
        }
    }
}
