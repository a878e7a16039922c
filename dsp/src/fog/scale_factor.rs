//! FOG scale factor and bias over coil temperature, applied to the output at
//! the frame rate (docs/fog.md; the table from `gyro-lab fit
//! scale-factor`, record in gyro-coeffs).
//!
//! The gyro's output with the nominal scale factor is `y = (1 + sf(T))*w +
//! b(T)`; the compensated angle is `(y - b(T)) * g(T)` with `g = 1/(1 + sf)`.
//! Both g and b are tabulated at the nodes and interpolated linearly (the
//! difference between interpolating sf and 1/(1 + sf) is below 1e-8 for
//! segments that change sf by less than 300 ppm).
//!
//! The table is read when the coil temperature changes, at each sensor
//! update (a binary search over up to 64 nodes, 6 steps); the frame path
//! applies the g and b read there, so its cost does not grow with the
//! table (`compensate` is a subtraction, two multiplies and the words).
//!
//! Formats:
//! - temperatures: i32 Q8 degC; the coil temperature is the sensor's plus
//!   `lag * dT/dt` (the lead that undoes the sensor's first-order lag behind
//!   the coil), dT/dt from a [`Derivative`] with a [`LEAD_FILTER_TAU_S`]
//!   time constant, Q32 degC/s; the lag Q16 s;
//! - g - 1: i32, 2^-32 per LSB (0.00023 ppm), within +-2 %;
//! - bias: i32 Q16 deg/h; per closure in frame-angle LSB, Q8;
//! - angles: the frame's i64 angle LSB (2*pi/2^32 rad * tau / K_s).
//!
//! Faults: a bad coil sensor ([`crate::sensor`]) holds the last good
//! temperature (the lead decays to 0) and sets [`FogTempFlags::COIL_SENSOR`]; a
//! coil temperature outside the calibrated range uses the end node and sets
//! [`FogTempFlags::OUT_OF_RANGE`]; a refused record runs with no compensation and
//! sets [`FogTempFlags::COEFFS_REFUSED`]. Before the first good read the table is
//! read at the middle of the calibrated range (flagged as a bad sensor).

use super::config::FogConfig;
use crate::derivative::{Derivative, DerivativeConfig};
use crate::phase::RAD_PER_PHASE_LSB;
use crate::sensor::SensorHold;
pub use gyro_coeffs::fog_scale_factor::ScaleFactorTable;
use gyro_coeffs::fog_scale_factor::MAX_NODES;
#[allow(unused_imports)] // f64 maths comes from libm where core lacks it
use num_traits::float::Float;

/// Time constant of the coil temperature's differentiator, s. Long, because
/// the lead multiplies its noise by the lag: with 0.006 degC of sensor noise
/// at 1 Hz and a 30 s lag the coil estimate carries about 0.025 degC.
pub const LEAD_FILTER_TAU_S: f64 = 60.0;

bitflags::bitflags! {
    /// Fault bits of the FOG temperature compensation (frame byte 82).
    #[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
    pub struct FogTempFlags: u8 {
        /// The coil sensor is bad (failed, implausible or stuck): last good
        /// temperature held.
        const COIL_SENSOR = 1 << 0;
        /// Coil temperature outside the calibrated range: end node used.
        const OUT_OF_RANGE = 1 << 1;
        /// The stored table was refused: no compensation.
        const COEFFS_REFUSED = 1 << 2;
    }
}

/// Immutable fixed-point form of a table for one FOG configuration and
/// sensor period.
#[derive(Clone, Copy, Debug)]
pub struct ScaleFactorConfig {
    n: usize,
    t_q8: [i32; MAX_NODES],
    /// g - 1 at the nodes, 2^-32.
    g_q32: [i32; MAX_NODES],
    /// Per segment i (node i to i+1): d(g_q32)/d(t_q8), Q16.
    g_slope_q16: [i64; MAX_NODES],
    bias_q16: [i32; MAX_NODES],
    bias_slope_q16: [i64; MAX_NODES],
    /// Sensor lag, Q16 s.
    lag_q16: i64,
    lead: DerivativeConfig,
    /// Frame-angle LSB per closure per deg/h, Q8.
    angle_per_closure_dph_q8: i64,
    /// Table input before the first good read: the calibrated range's middle.
    t_start_q8: i32,
    /// The table read there: (g - 1, bias, outside the range).
    start: (i32, i32, bool),
    pub coeffs_refused: bool,
}

/// The FOG temperature words of one output frame.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct FogTempWords {
    /// Scale-factor correction in use: the output is multiplied by
    /// 1 + sf_corr/2^32.
    pub sf_corr_q32: i32,
    /// Bias removed, Q16 deg/h.
    pub bias_q16_dph: i32,
    /// Coil temperature the table was read at, Q8 degC.
    pub t_coil_q8: i16,
    /// Coil sensor value in use (held while bad), Q8 degC.
    pub t_sensor_q8: i16,
    /// What went wrong, if anything.
    pub flags: FogTempFlags,
}

fn q(x: f64, frac: u32) -> i64 {
    (x * (1u64 << frac) as f64).round() as i64
}

impl ScaleFactorConfig {
    /// `sensor_dt_s`: coil sensor period. A table that fails its check is
    /// replaced by no compensation with `coeffs_refused` up.
    pub fn new(table: &ScaleFactorTable, fog: &FogConfig, sensor_dt_s: f64) -> Self {
        const SAFE: &ScaleFactorTable = &ScaleFactorTable::SAFE;
        let (t, refused) = match table.check() {
            Ok(()) => (table, false),
            Err(_) => (SAFE, true),
        };
        let n = t.n;
        let mut c = Self {
            n,
            t_q8: [0; MAX_NODES],
            g_q32: [0; MAX_NODES],
            g_slope_q16: [0; MAX_NODES],
            bias_q16: [0; MAX_NODES],
            bias_slope_q16: [0; MAX_NODES],
            lag_q16: q(t.sensor_lag_s, 16),
            lead: DerivativeConfig::new(sensor_dt_s, LEAD_FILTER_TAU_S),
            angle_per_closure_dph_q8: 0,
            t_start_q8: q((t.temps_c[0] + t.temps_c[n - 1]) / 2.0, 8) as i32,
            start: (0, 0, false),
            coeffs_refused: refused,
        };
        for k in 0..n {
            c.t_q8[k] = q(t.temps_c[k], 8) as i32;
            // |sf| <= 2 %: g - 1 within +-2.1 %, far inside i32 at 2^-32.
            c.g_q32[k] = q(1.0 / (1.0 + t.sf_ppm[k] * 1e-6) - 1.0, 32) as i32;
            c.bias_q16[k] = q(t.bias_dph[k], 16) as i32;
        }
        for k in 0..n.saturating_sub(1) {
            // Nodes at least 0.5 degC (128 LSB) apart: slopes below 2^37.
            let dt = (c.t_q8[k + 1] - c.t_q8[k]).max(1) as i64;
            c.g_slope_q16[k] = ((c.g_q32[k + 1] as i64 - c.g_q32[k] as i64) << 16) / dt;
            c.bias_slope_q16[k] = ((c.bias_q16[k + 1] as i64 - c.bias_q16[k] as i64) << 16) / dt;
        }
        // bias rad/s * (n_half tau) s / (angle LSB rad), angle LSB =
        // RAD_PER_PHASE_LSB * tau / K_s: about 71 600 at the reference coil.
        let rad_s_per_dph = core::f64::consts::PI / 180.0 / 3600.0;
        let per_step = rad_s_per_dph * fog.n_half as f64 * fog.k_sagnac_s / RAD_PER_PHASE_LSB;
        c.angle_per_closure_dph_q8 = q(per_step, 8);
        c.start = c.lookup(c.t_start_q8);
        c
    }

    /// From a stored record; a refused record gives no compensation, flagged.
    pub fn from_record(record: &[u8], fog: &FogConfig, sensor_dt_s: f64) -> Self {
        match ScaleFactorTable::from_record(record) {
            Ok(t) => Self::new(&t, fog, sensor_dt_s),
            Err(_) => {
                let mut c = Self::new(&ScaleFactorTable::SAFE, fog, sensor_dt_s);
                c.coeffs_refused = true;
                c
            }
        }
    }

    /// (g - 1 in 2^-32, bias Q16 deg/h, outside the calibrated range) at
    /// coil temperature `t_q8`.
    #[inline]
    pub fn lookup(&self, t_q8: i32) -> (i32, i32, bool) {
        let n = self.n.clamp(1, MAX_NODES);
        let (i, dt, out) = if t_q8 < self.t_q8[0] {
            (0, 0, n > 1)
        } else if t_q8 > self.t_q8[n - 1] {
            (n - 1, 0, n > 1)
        } else {
            // Binary search for the last node at or below t, at most n - 2
            // (t_q8[lo] <= t <= t_q8[hi] throughout): log2(n) steps.
            let (mut lo, mut hi) = (0, n - 1);
            while hi - lo > 1 {
                let mid = (lo + hi) / 2;
                if self.t_q8.get(mid).is_some_and(|&x| x <= t_q8) {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
            let t_lo = self.t_q8.get(lo).copied().unwrap_or(t_q8);
            (lo, (t_q8 - t_lo) as i64, false)
        };
        // dt within the node span (< 2^16), slopes below 2^37 (differences
        // below 2^28 over at least 128 LSB, Q16): products below 2^53.
        let at = |v: &[i32; MAX_NODES], s: &[i64; MAX_NODES]| {
            let (v, s) = (
                v.get(i).copied().unwrap_or(0) as i64,
                s.get(i).copied().unwrap_or(0),
            );
            (v + ((s * dt) >> 16)) as i32
        };
        (
            at(&self.g_q32, &self.g_slope_q16),
            at(&self.bias_q16, &self.bias_slope_q16),
            out,
        )
    }
}

/// `x * g / 2^32` for an i64 x and an i32 g, without a 128-bit product:
/// x = hi*2^32 + lo, so it is hi*g + lo*g/2^32 (two multiplies; rounds down).
#[inline(always)]
fn mul_q32(x: i64, g: i32) -> i64 {
    let hi = x >> 32;
    let lo = x & 0xFFFF_FFFF;
    hi * g as i64 + ((lo * g as i64) >> 32)
}

/// Mutable state: the coil sensor and its lead, and the table read at the
/// coil temperature.
#[derive(Clone, Copy, Debug, Default)]
pub struct ScaleFactorComp {
    sensor: SensorHold,
    lead: Derivative,
    /// Coil temperature estimate, Q8 degC; None before the first good read.
    t_coil_q8: Option<i32>,
    sensor_bad: bool,
    /// The table at `t_coil_q8`: g - 1 (2^-32), bias (Q16 deg/h), outside
    /// the calibrated range. Read at each update; meaningless while
    /// `t_coil_q8` is None.
    read: (i32, i32, bool),
}

impl ScaleFactorComp {
    /// One coil sensor read (`None`: the read failed), Q8 degC.
    pub fn update_temperature(&mut self, cfg: &ScaleFactorConfig, read_q8: Option<i32>) {
        let (t, bad) = self.sensor.take(read_q8);
        self.sensor_bad = bad;
        let d_q32 = self.lead.update(&cfg.lead, t, !bad);
        if bad && self.t_coil_q8.is_none() {
            return;
        }
        // lag < 2^26 (Q16), |dT/dt| <= 2^35 (Q32): below 2^61; Q48 -> Q8.
        let lead_q8 = (cfg.lag_q16 * d_q32) >> 40;
        let t_coil = (t as i64 + lead_q8).clamp(-200 * 256, 200 * 256) as i32;
        self.t_coil_q8 = Some(t_coil);
        self.read = cfg.lookup(t_coil);
    }

    /// Compensates one frame's angle increment (`closures` closures):
    /// returns `(y - b) * g` and the words that say what was applied. The
    /// table was read at the last update (before the first good read, at
    /// the middle of the calibrated range: `cfg` holds that reading).
    #[inline]
    pub fn compensate(
        &self,
        cfg: &ScaleFactorConfig,
        angle: i64,
        closures: u16,
    ) -> (i64, FogTempWords) {
        let (t, (g, b_q16, out)) = match self.t_coil_q8 {
            Some(t) => (t, self.read),
            None => (cfg.t_start_q8, cfg.start),
        };
        // |b| <= 2^26 (Q16), per-closure factor < 2^26 (Q8): per closure below
        // 2^36 (Q8), times closures < 2^16: below 2^52.
        let b_closure_q8 = (b_q16 as i64 * cfg.angle_per_closure_dph_q8) >> 16;
        // Saturating: a frame's angle is far inside i64 (2^40 LSB is 4 deg
        // at the reference coil), but no input may overflow.
        let x = angle.saturating_sub((b_closure_q8 * closures as i64) >> 8);
        let comp = x.saturating_add(mul_q32(x, g));
        let mut flags = FogTempFlags::empty();
        flags.set(
            FogTempFlags::COIL_SENSOR,
            self.sensor_bad || self.t_coil_q8.is_none(),
        );
        flags.set(FogTempFlags::OUT_OF_RANGE, out);
        flags.set(FogTempFlags::COEFFS_REFUSED, cfg.coeffs_refused);
        let sat16 = |v: i32| v.clamp(i16::MIN as i32, i16::MAX as i32) as i16;
        let words = FogTempWords {
            sf_corr_q32: g,
            bias_q16_dph: b_q16,
            t_coil_q8: sat16(t),
            t_sensor_q8: sat16(self.sensor.value_q8()),
            flags,
        };
        (comp, words)
    }

    /// Coil temperature estimate, Q8 degC (None before the first good read).
    pub fn coil_q8(&self) -> Option<i32> {
        self.t_coil_q8
    }

    /// The lead's inputs: the sensor value in use (Q8 degC), its filtered
    /// derivative (Q32 degC/s) and whether the sensor is bad. The fit forms
    /// the coil temperature for any lag from these, as this block does.
    pub fn lead_inputs(&self) -> (i32, i64, bool) {
        (
            self.sensor.value_q8(),
            self.lead.value_q32(),
            self.sensor_bad,
        )
    }
}
