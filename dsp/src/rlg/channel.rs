//! One RLG channel as the firmware runs it: the periodic update interrupt
//! reads the encoder timer ([`PulseCounter`]), and on sensor ticks advances the
//! thermal compensation ([`ThermalComp`]); the frame words are taken at the
//! frame rate. Configuration is immutable ([`RlgConfig`]), state mutable.
//!
//! Formats: counts (1/K deg, K = counts per degree); B_TC Q16 deg/h; rates in
//! the compensation: i64 nano-degrees per second (ndps); frame rate word i32
//! micro-degrees per second (+-2147 deg/s, LSB 0.0036 deg/h).

use super::counter::PulseCounter;
use super::thermal::{RlgFlags, Temperatures, ThermalComp, ThermalConfig};

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

#[derive(Clone, Copy, Debug, Default)]
pub struct RlgChannel {
    pub counter: PulseCounter,
    pub thermal: ThermalComp,
    frame_counts: i64,
    frame_updates: u32,
}

impl RlgChannel {
    /// The update interrupt: one counter read; on sensor ticks (`temps`) the
    /// compensation advances too.
    #[inline(always)]
    pub fn update(&mut self, cfg: &RlgConfig, raw_counter: u16, temps: Option<&Temperatures>) {
        let d = self.counter.update(raw_counter);
        self.frame_counts += d as i64;
        self.frame_updates += 1;
        if let Some(t) = temps {
            self.thermal.update(&cfg.thermal, t);
        }
    }

    /// Frame words over the updates since the last call (main loop, not the ISR:
    /// it divides).
    pub fn take_frame(&mut self) -> (i64, u32) {
        let r = (self.frame_counts, self.frame_updates);
        self.frame_counts = 0;
        self.frame_updates = 0;
        r
    }

    /// Puts back counts `take_frame` gave whose words could not be delivered:
    /// they go out with the next update's.
    pub fn restore_frame(&mut self, counts: i64, updates: u32) {
        self.frame_counts += counts;
        self.frame_updates += updates;
    }

    /// Builds the frame words from `take_frame`'s counts and updates.
    pub fn words(&self, cfg: &RlgConfig, counts: i64, updates: u32) -> RlgWords {
        // rate = counts * ndeg/count * update_hz / updates, in i128: counts
        // per frame up to 2^31 and ndeg/count up to 2^46 (Q16) do not fit i64.
        let n = updates.max(1) as i128;
        let rate =
            ((counts as i128 * cfg.ndeg_per_count_q16 as i128) >> 16) * cfg.update_hz as i128 / n;
        let rate_ndps = rate.clamp(i64::MIN as i128, i64::MAX as i128) as i64;
        let b = self.thermal.bias_q16();
        let comp = compensate_rate_ndps(rate_ndps, b);
        let t = self.thermal.in_use_q8();
        let q8 = |x: i32| x.clamp(i16::MIN as i32, i16::MAX as i32) as i16;
        RlgWords {
            delta_counts: counts.clamp(i32::MIN as i64, i32::MAX as i64) as i32,
            rate_comp_udps: (comp / 1000).clamp(i32::MIN as i64, i32::MAX as i64) as i32,
            bias_q16_dph: b.clamp(i32::MIN as i64, i32::MAX as i64) as i32,
            t_mono_a_q8: q8(t[0]),
            t_mono_b_q8: q8(t[1]),
            t_case_q8: q8(t[2]),
            flags: self.thermal.flags(),
        }
    }
}
