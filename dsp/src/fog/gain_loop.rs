//! Second loop: 2*pi gain control.
//!
//! If the DAC-to-phase gain is (1 + g) turns per nominal turn, a reset leaves a
//! phase error of `-2*pi*g*w` for one half period (w = +1 for an upward reset).
//! With the half period's residual estimate `d_j = -sign_j*(h_j - H)*cot(phi0/2)/H`,
//! `sum_j w_j*sign_j*(h_j - H)` over the reset half periods is proportional to +g;
//! integrating it against the digital gain (codes per turn) keeps a reset exactly 2*pi.
//!
//! Two gears: a fast gain acquires V_pi after start or a fault, a slow one
//! tracks it once the loop has been in lock for a while. The fast loop's
//! equilibrium fluctuates with the resets, and under a low-amplitude
//! vibration the resets follow the vibration's phase, so its fluctuations
//! rectify into a drift of about one output LSB (docs/fog.md, "The 2*pi
//! loop's gear"); V_pi itself only drifts with temperature. The gear is
//! chosen outside the closure ([`GainLoop::supervise`], once per frame on
//! the board): the closure reads the gain in use from the state, as before
//! from the configuration, so the shift costs it nothing.

use super::demod::DemodSums;
use super::modulator::Resets;
use crate::fixed::shr_saturate;
use crate::phase::{phase_from_rad, Phase};
use core::f64::consts::TAU;
#[allow(unused_imports)] // f64 maths comes from libm where core lacks it
use num_traits::float::Float;

/// The 2*pi loop's two gains (fraction of a measured gain error corrected
/// per reset) and the closures in lock after which it shifts from the first
/// to the second.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GainLoopGears {
    pub acquire: f64,
    pub track: f64,
    pub acquire_closures: u32,
}

/// The 2*pi loop's gains, the digital gain's range and when it holds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct GainLoopConfig {
    /// Acquisition gain: DAC Q8 codes-per-turn per unit normalised reset
    /// error (sum c_j*h_j / H), divided by n_half (the estimate comes n
    /// times larger), Q4; below 2^20 (clamped: only depths near 0 or pi
    /// with few half periods reach it, and then acquire more slowly).
    pub gain: i32,
    /// Tracking gain, the same units.
    pub track_gain: i32,
    /// Closures in lock before the shift to `track_gain`.
    pub acquire_closures: u32,
    /// Nominal DAC codes per turn, and the clamp of the digital gain
    /// (-20 %, +25 %), Q15 (below 2^31: at most 65 535 codes, config).
    pub nominal_q15: i32,
    pub min_q15: i32,
    pub max_q15: i32,
    /// Residual beyond which the loop holds (0.1 rad), phase LSB: under
    /// strong dynamics a closure's DC carries the residual's delta^2, far
    /// more than a reset's 2*pi error, and V_pi drifts slowly anyway.
    pub hold_limit: Phase,
}

impl GainLoopConfig {
    /// The `gears`' fractions of a measured gain error corrected per reset,
    /// at the error's scale cot(phi0/2)/(2*pi) per unit, for `n_half` half
    /// periods, around `dac_codes_per_turn` (2*pi at nominal V_pi).
    pub fn new(
        gears: GainLoopGears,
        dac_codes_per_turn: u32,
        phi0_rad: f64,
        n_half: usize,
    ) -> Self {
        let cot_half = 1.0 / (phi0_rad / 2.0).tan();
        let per_unit = dac_codes_per_turn as f64 * 256.0 * cot_half / TAU * 16.0 / n_half as f64;
        let q4 = |g: f64| (g * per_unit).round().clamp(0.0, ((1 << 20) - 1) as f64) as i32;
        Self {
            gain: q4(gears.acquire),
            track_gain: q4(gears.track),
            acquire_closures: gears.acquire_closures,
            nominal_q15: (dac_codes_per_turn.min(65_535) << 15) as i32,
            min_q15: ((dac_codes_per_turn as f64 * 0.8).min(65_535.0) * 32_768.0) as i32,
            max_q15: ((dac_codes_per_turn as f64 * 1.25).min(65_535.0) * 32_768.0) as i32,
            hold_limit: phase_from_rad(HOLD_LIMIT_RAD),
        }
    }
}

/// Residual beyond which the loop holds, rad.
pub const HOLD_LIMIT_RAD: f64 = 0.1;

/// State: the digital gain, DAC codes per turn in Q15 (the modulator
/// takes Q8; the finer integrator keeps the slow gear's updates, which in
/// Q8 would round to nothing below about 5e-5 of V_pi without noise), and
/// the gear.
#[derive(Clone, Copy, Debug)]
pub struct GainLoop {
    codes_per_turn_q15: i32,
    /// The gain in use, [`GainLoopConfig::gain`]'s units.
    gain: i32,
    /// Closures in lock so far (saturating), up to the shift.
    in_lock: u32,
}

impl GainLoop {
    pub fn new(cfg: &GainLoopConfig) -> Self {
        Self {
            codes_per_turn_q15: cfg.nominal_q15,
            gain: cfg.gain,
            in_lock: 0,
        }
    }

    /// The gear, from outside the closure: `closures` more closures have
    /// run, `healthy` if the last was in lock with light and true levels.
    /// A fault goes back to the acquisition gain and restarts the count;
    /// after `cfg.acquire_closures` healthy ones the tracking gain is used.
    pub fn supervise(&mut self, cfg: &GainLoopConfig, closures: u32, healthy: bool) {
        self.in_lock = if healthy {
            self.in_lock.saturating_add(closures)
        } else {
            0
        };
        self.gain = if self.tracking(cfg) {
            cfg.track_gain
        } else {
            cfg.gain
        };
    }

    /// True once the loop runs on its tracking gain.
    pub fn tracking(&self, cfg: &GainLoopConfig) -> bool {
        self.in_lock >= cfg.acquire_closures
    }

    /// The digital gain in use, DAC codes per turn, Q8.
    #[inline(always)]
    pub fn codes_per_turn_q8(&self) -> u32 {
        (self.codes_per_turn_q15 >> 7) as u32
    }

    /// One closure with true levels: its demodulated sums, the resets of
    /// the words they were taken with, its mean residual (phase LSB) and
    /// the AGC's 2^32/H. Holds beyond [`GainLoopConfig::hold_limit`];
    /// otherwise trims the gain by the resets' phase error. Returns the gain.
    #[inline(always)]
    pub(crate) fn update(
        &mut self,
        cfg: &GainLoopConfig,
        sums: &DemodSums,
        resets: &Resets,
        n_half: u32,
        residual: i32,
        recip_h: u32,
    ) -> u32 {
        if residual.unsigned_abs() <= cfg.hold_limit {
            let err = reset_error(sums, resets, n_half);
            self.trim(err, cfg, recip_h);
        }
        self.codes_per_turn_q8()
    }
}

/// Returns n * (sum_j c_j * h_j) over the closure (n = `n_half`), exact: no
/// division, so no rounding that correlates with the resets. The weights are
/// c_j = w_j - W/n - (R/n)*sign_j, w_j = r_j * sign_j, r_j the reset
/// direction (see [`Carries::weight`]), W = sum w_j, R = sum r_j: the mean
/// level and the closure's common residual (mean of sign_j * h_j: the main
/// loop's error, or the lag under acceleration) drop out, so only the
/// resets' own phase error remains.
///
/// With the residual delta_j = dbar + a*t_j + e_j (t_j = j - (n-1)/2, e_j the
/// reset error) the level is h_j = H - sign_j*k*delta_j, and
/// sum c_j*h_j = -k*(sum c_j*sign_j*e_j) - k*a*S1, S1 = sum_j r_j*(t_j +
/// sign_j/2). Under a periodic vibration the resets fall at the same places
/// every cycle and S1 correlates with a: the slope's share is taken out with
/// k*a = 4*(first - second)/n^2 (rounded to the nearest unit, so without
/// bias).
///
/// Range: with h_max the largest kept sum of one half period (kept samples
/// x 2^16), |n*c_j| <= 3n and |S1| <= n^2/4, so the result is below
/// 4*n^2*h_max, under 2^31 for the layouts config accepts (n^2 * kept <
/// 8192); the arithmetic wraps on purpose only beyond that.
#[inline(always)]
fn reset_error(sums: &DemodSums, resets: &Resets, n_half: u32) -> i32 {
    let pairs = (n_half / 2) as i32;
    let n = n_half.max(4) as i32;
    let (neg_p, neg_m) = (resets.plus_negative, resets.minus_negative);
    // dc = P + M < 2^26 and diff = P - M = first + second: P = (dc + diff)/2
    // exactly (dc + diff = 2P >= 0).
    let dc = sums.dc as i32;
    let diff = sums.first.wrapping_add(sums.second);
    let plus_all = (dc.wrapping_add(diff) as u32 >> 1) as i32;
    let minus_all = dc.wrapping_sub(plus_all);
    let mut weighted = sums.carried;
    if neg_p {
        weighted = weighted.wrapping_sub(plus_all);
    }
    if neg_m {
        weighted = weighted.wrapping_add(minus_all);
    }
    let (plus, minus) = (moment(resets.plus, pairs), moment(resets.minus, pairs));
    let (n_plus, n_minus) = (plus.count as i32, minus.count as i32);
    let (neg_p, neg_m) = (neg_p as i32, neg_m as i32);
    let w_sum = n_plus - n_minus + (neg_m - neg_p) * pairs;
    let r_sum = n_plus + n_minus - (neg_p + neg_m) * pairs;
    // S1: pair i's two halves (bit P-1-i) both sit at 2i + 1 - P, and
    // r = carry - [negative] on both (a minus half's r is -w); the constant
    // parts sum to zero over the closure.
    let s1 = (pairs - 1) * (n_plus + n_minus) - 2 * (plus.weighted + minus.weighted) as i32;
    // 4*(first - second)*S1/n, rounded: the product (below 2^57) in 64 bits.
    let slope = sums.first.wrapping_sub(sums.second) as i64 * s1 as i64;
    let q = (n / 4) as i64;
    // Floor division (a shift for the reference layouts, where q is 4 or 8).
    let rounded = slope + q / 2;
    let slope_share = if q.count_ones() == 1 {
        (rounded >> q.trailing_zeros()) as i32
    } else {
        rounded.div_euclid(q) as i32
    };
    weighted
        .wrapping_mul(n)
        .wrapping_sub(dc.wrapping_mul(w_sum))
        .wrapping_sub(diff.wrapping_mul(r_sum))
        .wrapping_add(slope_share)
}

/// Set bits of a carry mask and their bit-index moment.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct MaskMoment {
    /// Number of set bits.
    pub count: u32,
    /// Sum of the set bits' indices (bit 0 counts 0).
    pub weighted: u32,
}

/// [`MaskMoment`] of the low `pairs` bits of `mask`. Up to 8 bits (16 half
/// periods) one table lookup; up to 16 two; beyond, a loop.
#[inline(always)]
fn moment(mask: u32, pairs: i32) -> MaskMoment {
    // Only the low `pairs` bits belong to the closure.
    let mask = mask
        & u32::MAX
            .checked_shr(32 - pairs.clamp(0, 32) as u32)
            .unwrap_or(0);
    let byte = |b: u32| BYTE_MOMENT[(b & 0xFF) as usize];
    let unpack = |m: u16| MaskMoment {
        count: (m >> 8) as u32,
        weighted: (m & 0xFF) as u32,
    };
    if pairs <= 8 {
        unpack(byte(mask))
    } else if pairs <= 16 {
        let (lo, hi) = (unpack(byte(mask)), unpack(byte(mask >> 8)));
        MaskMoment {
            count: lo.count + hi.count,
            weighted: lo.weighted + hi.weighted + 8 * hi.count,
        }
    } else {
        let mut m = MaskMoment {
            count: 0,
            weighted: 0,
        };
        for b in 0..pairs.min(32) as u32 {
            let bit = (mask >> b) & 1;
            m.count += bit;
            m.weighted += b * bit;
        }
        m
    }
}

/// Per byte: set bits (high byte) and the sum of their indices (low byte, at
/// most 28). 512 bytes of flash for a single load per mask in the interrupt.
static BYTE_MOMENT: [u16; 256] = {
    let mut t = [0u16; 256];
    let mut v = 0;
    while v < 256 {
        let (mut count, mut weighted, mut b) = (0u16, 0u16, 0);
        while b < 8 {
            if (v >> b) & 1 == 1 {
                count += 1;
                weighted += b as u16;
            }
            b += 1;
        }
        t[v] = (count << 8) | weighted;
        v += 1;
    }
    t
};

impl GainLoop {
    /// New digital gain (DAC codes per turn, Q15) after one closure's reset
    /// error. `err`: [`reset_error`], n x ADC LSB; the gear's gain: Q8 codes
    /// per unit normalised error (err/(n*H)), Q4 (config folds the 1/n in),
    /// below 2^20; `recip_h`: 2^32 / H (H = DC of one half period's kept
    /// samples, at least 2, so below 2^31).
    #[inline(always)]
    fn trim(&mut self, err: i32, cfg: &GainLoopConfig, recip_h: u32) {
        // err/H in Q20, saturated at |err/H| < 2^8 (n/16 times a 25 % gain
        // error, the clamp's end): only a wild start converges slower.
        let e_q20 = shr_saturate::<12, 29>(err as i64 * (recip_h as i32) as i64) as i64;
        // Q20 x Q4 gain = Q8 codes in Q24, >> 17 = Q15 codes, rounded;
        // |product| < 2^28 * 2^20, so |delta| < 2^31.
        let delta = ((e_q20 * self.gain as i64 + (1 << 16)) >> 17) as i32;
        // The gain, min, max < 2^31 (config); the subtraction saturates.
        self.codes_per_turn_q15 = self
            .codes_per_turn_q15
            .saturating_sub(delta)
            .max(cfg.min_q15)
            .min(cfg.max_q15);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The reference instrument's loop: 3pi/4, 16 half periods, the
    /// default gears.
    fn reference_config() -> GainLoopConfig {
        let gears = GainLoopGears {
            acquire: 0.05,
            track: 0.0001,
            acquire_closures: 3_125,
        };
        GainLoopConfig::new(gears, 49_152, 0.75 * core::f64::consts::PI, 16)
    }

    /// A closure whose eight plus half periods all reset upward, at a DC of
    /// 30 000 per half period, those half periods at `reset_level`: its
    /// resets, sums and 2^32/H.
    fn upward_resets(reset_level: i32) -> (Resets, DemodSums, u32) {
        let resets = Resets {
            plus: 0xFF,
            minus: 0,
            plus_negative: false,
            minus_negative: false,
        };
        let sums = DemodSums {
            first: 0,
            second: 0,
            dc: 16 * 30_000,
            carried: 8 * reset_level,
        };
        (resets, sums, u32::MAX / 30_000)
    }

    /// The table-based count and index moment of carry masks against the plain
    /// bit loop, every 8- and 16-bit mask; bits above the closure's pairs ignored.
    #[test]
    fn mask_moment_matches_bit_loop() {
        let naive = |m: u32, pairs: u32| {
            let m = m & ((1u64 << pairs) - 1) as u32;
            let weighted: u32 = (0..32).filter(|b| (m >> b) & 1 == 1).sum();
            (m.count_ones(), weighted)
        };
        for m in 0..65_536u32 {
            for pairs in [2, 4, 6, 8, 10, 16, 32] {
                let mask = m | (m << 16) | 0x8000_0000;
                let got = moment(mask, pairs as i32);
                assert_eq!(
                    (got.count, got.weighted),
                    naive(mask, pairs),
                    "mask {mask:#x} pairs {pairs}"
                );
            }
        }
    }

    /// Beyond the hold limit the gain does not move, whatever the error;
    /// inside it a large error drives it to the clamp and no further.
    #[test]
    fn holds_under_dynamics_and_saturates_at_the_clamp() {
        let cfg = reference_config();
        let (resets, sums, recip_h) = upward_resets(31_000);
        let mut g = GainLoop::new(&cfg);
        let beyond = cfg.hold_limit as i32 + 1;
        for _ in 0..1000 {
            g.update(&cfg, &sums, &resets, 16, beyond, recip_h);
            assert_eq!(g.codes_per_turn_q15, cfg.nominal_q15);
        }
        let err = reset_error(&sums, &resets, 16);
        assert_ne!(err, 0);
        for _ in 0..100_000 {
            g.update(&cfg, &sums, &resets, 16, 0, recip_h);
            assert!((cfg.min_q15..=cfg.max_q15).contains(&g.codes_per_turn_q15));
        }
        let last = g.codes_per_turn_q15;
        assert!(last == cfg.min_q15 || last == cfg.max_q15, "{last}");
        assert_eq!(g.codes_per_turn_q8(), (last >> 7) as u32);
    }

    /// The gear: the acquisition gain until `acquire_closures` healthy
    /// closures, then the tracking gain (one step of the same error moves
    /// the digital gain by their ratio, 1/500); a fault goes back.
    #[test]
    fn shifts_to_tracking_after_lock_and_back_on_a_fault() {
        let cfg = reference_config();
        assert!((cfg.gain - 500 * cfg.track_gain).abs() <= 500);
        let (resets, sums, recip_h) = upward_resets(30_100);
        let step = |g: &mut GainLoop| {
            let before = g.codes_per_turn_q15 as i64;
            g.update(&cfg, &sums, &resets, 16, 0, recip_h);
            let after = g.codes_per_turn_q15 as i64;
            g.codes_per_turn_q15 = before as i32;
            after - before
        };
        let mut g = GainLoop::new(&cfg);
        let fast = step(&mut g);
        assert!(fast.abs() > 1000, "{fast}");
        g.supervise(&cfg, cfg.acquire_closures - 1, true);
        assert!(!g.tracking(&cfg));
        assert!((step(&mut g) - fast).abs() <= 1);
        g.supervise(&cfg, 1, true);
        assert!(g.tracking(&cfg));
        let slow = step(&mut g);
        assert!((slow * 500 - fast).abs() <= 1000, "{slow} vs {fast}");
        g.supervise(&cfg, u32::MAX, true);
        assert!(g.tracking(&cfg));
        g.supervise(&cfg, 25, false);
        assert!(!g.tracking(&cfg));
        assert!((step(&mut g) - fast).abs() <= 1);
    }

    /// Updates smaller than the modulator's Q8 step add up in the Q15
    /// integrator: 1 000 closures of an error worth a tenth of a Q8 step
    /// each move the modulator's gain by 100 steps (rounding each in Q8
    /// would move it by none).
    #[test]
    fn sub_step_updates_accumulate() {
        let cfg = reference_config();
        let mut g = GainLoop::new(&cfg);
        g.supervise(&cfg, u32::MAX, true);
        let start = g.codes_per_turn_q8() as i64;
        // err * recip_h >> 12 = e_q20; e_q20 * gain = 2^24 / 10 (Q8 in Q24).
        let recip_h = 1u32 << 12;
        let e_q20 = ((1u64 << 24) / 10) / g.gain as u64;
        for _ in 0..1_000 {
            g.trim(e_q20 as i32, &cfg, recip_h);
        }
        let want = 1_000.0 * (e_q20 * g.gain as u64) as f64 / (1u64 << 24) as f64;
        let moved = start - g.codes_per_turn_q8() as i64;
        assert!(
            (moved as f64 - want).abs() <= 0.04 * want,
            "{moved} vs {want}"
        );
    }
}
