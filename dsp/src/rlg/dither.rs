//! Dither stripping (docs/rlg.md): the encoder counter is latched in
//! hardware at each zero crossing of the dither pickoff, where the dither
//! angle is zero whatever its amplitude; the photodiode pair, sampled just
//! after, places the angle within the count. The stripped angle at any
//! instant is interpolated between the latches around it.
//!
//! Why latches and not a filter with zeros at f_d: the dither's random
//! amplitude (what randomises the lock-in crossings) is not a line at f_d
//! and its harmonics; a comb leaves a share of each half swing's amplitude
//! change in the output (docs/notes/issue-33-dither.md), while the angle at
//! the pickoff's zero is zero every time.
//!
//! Formats:
//! - times: `u32` ticks of the latch timer (`StripConfig::clock_hz`),
//!   wrapping; intervals are wrapping differences (below 2^31 ticks);
//! - angles: `i64` Q16 counts (1/65536 count), on the counter's unwrapped
//!   scale (`PulseCounter`): 2^47 counts of range;
//! - fringe phase: `u32` turns (2^32 per fringe, wrapping), from a CORDIC;
//!   4 counts per fringe, so Q16 counts = turns >> 14.
//!
//! The three corrections, each learnt from the latches themselves:
//! - the quadrant offset between the counter and the photodiodes' phase
//!   (the counter starts anywhere): a whole number of counts, the rounded
//!   mean of `N + 1/2 - c` over the first 64 latches (N the latched count,
//!   c the phase's count mod 4), learnt again if they disagree;
//! - the alternation: a delay of the pickoff's comparator or of the ADC
//!   after the latch puts the angle ahead by `r * delay` on rising
//!   crossings and behind on falling ones (r the dither's count rate): the
//!   second difference of three latches is twice it, averaged over 256
//!   latches;
//! - a latch that does not alternate or comes sooner than the shortest
//!   half period is a glitch: refused and flagged; one later than the
//!   longest restarts the history (crossings were missed).
//!
//! Nothing here can panic: the ring is a power-of-two array indexed with a
//! mask, divisions go through `checked_div` with a fallback, shifts are
//! constants or `wrapping_shr` of bounded counts.

use super::counter::PulseCounter;

/// Latches kept: 8 span 4 dither periods (the bracket needs 2, the
/// alternation 3).
const RING: usize = 8;
const MASK: usize = RING - 1;
const Q16: i64 = 1 << 16;
/// One fringe in Q16 counts.
const FRINGE_Q16: i64 = 4 * Q16;
/// Alternation average: 2^8 latches (about 0.3 s at 400 Hz).
const ALT_SHIFT: u32 = 8;
/// Latches with photodiodes that vote the quadrant offset before their
/// phase is used.
const LEARN: u32 = 64;
/// Smallest photodiode vector length (codes) that carries a phase: 64
/// codes (a fringe of 3200 codes peak-to-peak on the reference board).
const MIN_PD_NORM2: i64 = 64 * 64;

/// atan(2^-i) in turns (2^32 per turn).
const ATAN_TURNS: [u32; 16] = [
    536_870_912,
    316_933_406,
    167_458_907,
    85_004_756,
    42_667_331,
    21_354_465,
    10_679_838,
    5_340_245,
    2_670_163,
    1_335_087,
    667_544,
    333_772,
    166_886,
    83_443,
    41_722,
    20_861,
];

/// `atan2(y, x)` in turns (2^32 per turn, wrapping: 0 along +x, a quarter
/// turn along +y), by 16 CORDIC rotations (error below 2e-5 turn).
/// |x|, |y| < 2^14.
pub fn atan2_turns(y: i32, x: i32) -> u32 {
    let (mut x, mut y) = (
        x.clamp(-16_383, 16_383) << 16,
        y.clamp(-16_383, 16_383) << 16,
    );
    let mut z: u32 = 0;
    if x < 0 {
        // Into the right half plane by half a turn.
        x = -x;
        y = -y;
        z = 1 << 31;
    }
    for (i, &a) in ATAN_TURNS.iter().enumerate() {
        let (dx, dy) = (y.wrapping_shr(i as u32), x.wrapping_shr(i as u32));
        if y > 0 {
            x = x.wrapping_add(dx);
            y = y.wrapping_sub(dy);
            z = z.wrapping_add(a);
        } else {
            x = x.wrapping_sub(dx);
            y = y.wrapping_add(dy);
            z = z.wrapping_sub(a);
        }
    }
    z
}

/// One pickoff zero crossing as the latch interrupt reads it.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct LatchSample {
    /// The latch timer's count at the crossing.
    pub time: u32,
    /// The encoder counter captured at the crossing.
    pub counter: u16,
    /// The dither angle rose through zero (the pickoff edge's polarity).
    pub rising: bool,
    /// Photodiode ADC codes `[A, B]` (A follows sin, B cos of the fringe
    /// phase; right-aligned codes) sampled just after the latch; None on a
    /// board without them (the latch then stands for the middle of its count).
    pub photodiodes: Option<[u16; 2]>,
}

/// Immutable configuration of the stripping.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct StripConfig {
    /// Latch timer ticks per second.
    pub clock_hz: u32,
    /// Accepted latch-to-latch intervals (half dither periods), ticks.
    pub min_half: u32,
    pub max_half: u32,
    /// Photodiode codes at zero signal.
    pub pd_offset: [i32; 2],
    /// Use the photodiodes' phase within the count.
    pub interpolate: bool,
}

impl StripConfig {
    /// For a dither between `f_min` and `f_max` Hz (the half periods
    /// accepted: 0.8/f_max .. 1.25/f_min, room for the amplitude noise's
    /// timing and the drift), photodiodes centred on `pd_offset`.
    pub fn new(clock_hz: u32, f_min: f64, f_max: f64, pd_offset: [i32; 2]) -> Self {
        let ok = |f: f64| f.is_finite() && f >= 1.0;
        let (f_min, f_max) = if ok(f_min) && ok(f_max) && f_min <= f_max {
            (f_min, f_max)
        } else {
            (250.0, 700.0)
        };
        let clk = clock_hz.max(1) as f64;
        let ticks = |s: f64| (s * clk).clamp(1.0, (1u64 << 30) as f64) as u32;
        Self {
            clock_hz: clock_hz.max(1),
            min_half: ticks(0.8 * 0.5 / f_max),
            max_half: ticks(1.25 * 0.5 / f_min),
            pd_offset,
            interpolate: true,
        }
    }
}

bitflags::bitflags! {
    /// What the stripping saw since the flags were last taken.
    #[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
    pub struct StripFlags: u8 {
        /// No latch after the instant asked for: the raw counter stood in
        /// (the dither not stripped), or the history restarted.
        const NO_PICKOFF = 1 << 0;
        /// A pickoff edge refused (same polarity twice, or too soon).
        const LATCH_REFUSED = 1 << 1;
        /// Photodiodes too weak for a phase, or their phase disagreeing with
        /// the count: the latch stood for its count's middle.
        const PHOTODIODES_WEAK = 1 << 2;
    }
}

#[derive(Clone, Copy, Debug, Default)]
struct Stored {
    time: u32,
    angle_q16: i64,
    rising: bool,
}

/// The stripping's state.
#[derive(Clone, Copy, Debug, Default)]
pub struct DitherStripper {
    ring: [Stored; RING],
    /// Index of the newest latch (masked), and how many are held.
    head: usize,
    len: usize,
    /// Angle lead at a rising latch, Q16 counts.
    alt_q16: i64,
    /// Counter minus photodiode quadrant offset, whole counts (Q16) in [0, 4).
    offset_q16: i64,
    offset_sum: i64,
    pd_seen: u32,
    disagree: u32,
    flags: StripFlags,
}

/// Wraps Q16 counts into [-2, 2) counts (half a fringe either way).
fn wrap_fringe(v: i64) -> i64 {
    (v + 2 * Q16).rem_euclid(FRINGE_Q16) - 2 * Q16
}

fn sign(rising: bool) -> i64 {
    if rising {
        1
    } else {
        -1
    }
}

impl DitherStripper {
    /// One latch (the latch interrupt); `counter` unwraps its 16-bit count.
    pub fn latch(&mut self, cfg: &StripConfig, l: &LatchSample, counter: &PulseCounter) {
        let Some(n) = counter.unwrap(l.counter) else {
            // No counter read yet: nothing to place the latch against.
            return;
        };
        if self.len > 0 {
            let last = self.newest();
            let dt = l.time.wrapping_sub(last.time);
            // Not after the newest (a wrapping difference of 2^31 or more),
            // the same polarity twice, or too soon: a glitch.
            if l.rising == last.rising || dt < cfg.min_half || dt >= 1 << 31 {
                self.flags |= StripFlags::LATCH_REFUSED;
                return;
            }
            if dt > cfg.max_half {
                // Crossings were missed: the old latches do not bracket.
                self.len = 0;
                self.flags |= StripFlags::NO_PICKOFF;
            }
        }
        let angle = self.place(cfg, n, l.photodiodes);
        if self.len >= 2 {
            self.learn_alternation(l.time, angle);
        }
        self.head = (self.head + 1) & MASK;
        self.ring[self.head & MASK] = Stored {
            time: l.time,
            angle_q16: angle,
            rising: l.rising,
        };
        self.len = (self.len + 1).min(RING);
    }

    /// The latch's angle, Q16 counts: the count's middle, or the photodiodes'
    /// phase within the fringe nearest to it.
    fn place(&mut self, cfg: &StripConfig, n: i64, pd: Option<[u16; 2]>) -> i64 {
        let middle = n.wrapping_shl(16).wrapping_add(Q16 / 2);
        let Some([a, b]) = pd.filter(|_| cfg.interpolate) else {
            return middle;
        };
        let y = (a as i32).saturating_sub(cfg.pd_offset[0]);
        let x = (b as i32).saturating_sub(cfg.pd_offset[1]);
        if (x as i64) * (x as i64) + (y as i64) * (y as i64) < MIN_PD_NORM2 {
            self.flags |= StripFlags::PHOTODIODES_WEAK;
            return middle;
        }
        // The count mod 4 the phase says (Q16 counts in [0, 4)).
        let c = (atan2_turns(y, x) >> 14) as i64;
        if self.pd_seen < LEARN {
            // The counter's quadrant against the phase's: a whole number of
            // counts (the counter started anywhere), the mean of N + 1/2 - c
            // rounded. Each is taken against the first (a circular mean:
            // they spread by under a count, the wrap is at two). At rest the
            // count's fraction is not uniform, so the mean is off by up to
            // half a count: only its rounding is used.
            if self.pd_seen == 0 {
                self.offset_q16 = wrap_fringe(middle - c);
                self.offset_sum = 0;
            }
            self.offset_sum = self
                .offset_sum
                .wrapping_add(wrap_fringe(middle - c - self.offset_q16));
            self.pd_seen += 1;
            if self.pd_seen == LEARN {
                let mean = self.offset_q16 + self.offset_sum / LEARN as i64;
                self.offset_q16 = ((mean + Q16 / 2) >> 16).rem_euclid(4) << 16;
            }
            return middle;
        }
        // The value the phase gives nearest the latched count's middle.
        let d = wrap_fringe(c + self.offset_q16 - middle);
        if d.abs() > Q16 + Q16 / 4 {
            // Phase and count disagree (counts lost by the counter, or a
            // photodiode fault): after 16 in a row the offset is learnt again.
            self.disagree += 1;
            if self.disagree >= 16 {
                self.pd_seen = 0;
                self.offset_sum = 0;
                self.disagree = 0;
                self.flags |= StripFlags::PHOTODIODES_WEAK;
            }
            return middle;
        }
        self.disagree = 0;
        middle + d
    }

    /// The second difference of the newest two latches and a new one is
    /// twice the alternation (the signs alternate).
    fn learn_alternation(&mut self, time: u32, angle: i64) {
        let b = self.newest();
        let a = self.ring[self.head.wrapping_sub(1) & MASK];
        let (t_ab, t_ac) = (b.time.wrapping_sub(a.time), time.wrapping_sub(a.time));
        let pred = a.angle_q16
            + (angle - a.angle_q16)
                .saturating_mul(t_ab as i64)
                .checked_div(t_ac as i64)
                .unwrap_or(0);
        let d = (b.angle_q16 - pred).clamp(-64 * Q16, 64 * Q16);
        let sample = sign(b.rising) * d / 2;
        self.alt_q16 += (sample - self.alt_q16) >> ALT_SHIFT;
    }

    fn newest(&self) -> Stored {
        self.ring[self.head & MASK]
    }

    /// The stripped angle at latch-timer time `t` (Q16 counts), between the
    /// latches around it with the alternation removed; None without a latch
    /// on both sides.
    pub fn at(&self, t: u32) -> Option<i64> {
        let mut later: Option<Stored> = None;
        for k in 0..self.len {
            let s = self.ring[self.head.wrapping_sub(k) & MASK];
            // Ahead of t (a positive wrapping difference), or at/behind it.
            if (s.time.wrapping_sub(t) as i32) > 0 {
                later = Some(s);
                continue;
            }
            let b = later?;
            let (va, vb) = (self.corrected(&s), self.corrected(&b));
            let span = b.time.wrapping_sub(s.time) as i64;
            let into = t.wrapping_sub(s.time) as i64;
            return Some(
                va + (vb - va)
                    .saturating_mul(into)
                    .checked_div(span)
                    .unwrap_or(0),
            );
        }
        None
    }

    fn corrected(&self, s: &Stored) -> i64 {
        s.angle_q16 - sign(s.rising) * self.alt_q16
    }

    /// The alternation learnt (angle lead at a rising latch), Q16 counts.
    pub fn alternation_q16(&self) -> i64 {
        self.alt_q16
    }

    /// The quadrant offset learnt, Q16 counts.
    pub fn offset_q16(&self) -> i64 {
        self.offset_q16
    }

    /// Flags since the last call, cleared.
    pub fn take_flags(&mut self) -> StripFlags {
        core::mem::take(&mut self.flags)
    }

    /// Flags without clearing them.
    pub fn flags(&self) -> StripFlags {
        self.flags
    }

    pub(crate) fn flag(&mut self, f: StripFlags) {
        self.flags |= f;
    }
}
