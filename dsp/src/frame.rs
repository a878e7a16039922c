//! Output frame sent over the USART: fixed size, little-endian, CRC-protected.
//!
//! | offset | type | field |
//! |---|---|---|
//! | 0 | u8 x2 | sync 0xA5 0x5A |
//! | 2 | u8 | version (4) |
//! | 3 | u8 | payload length after this byte, CRC included (82) |
//! | 4 | u16 | sequence number (wraps) |
//! | 6 | u16 | fault flags, OR over the frame's closures ([`Faults`]) |
//! | 8 | u16 | closures in this frame |
//! | 10 | u32 | closure counter at the end of the frame: closure periods since start, missed ones included, so it is the time base (wraps) |
//! | 14 | i64 | FOG angle, corrected, cumulative since start (wrapping): sum of `sagnac_phase_corrected` over every half period (angle LSB = 2*pi/2^32 rad * tau / K_s) |
//! | 22 | i64 | FOG angle without the epsilon-squared correction, cumulative |
//! | 30 | i32 | FOG residual of the last closure, phase LSB |
//! | 34 | u32 | 2*pi loop gain, DAC codes per turn, Q8 |
//! | 38 | u32 | detector DC, kept-sample sum of one half period, ADC LSB |
//! | 42 | i32 | RLG angle, counts (1/K deg, K = counts per degree), cumulative since start (wrapping) |
//! | 46 | i32 | RLG compensated rate over the frame, micro-deg/s |
//! | 50 | i32 | RLG thermal bias B_TC in use, Q16 deg/h |
//! | 54 | i16 x3 | RLG temperatures in use: monoblock A, monoblock B, case; Q8 degC |
//! | 60 | u8 | RLG flags ([`RlgFlags`]: sensor A, B, case bad; coefficients refused) |
//! | 61 | u8 | why the board last started ([`ResetCause`]), in the first frame after a start; 0 in every other |
//! | 62 | i64 | FOG angle compensated, cumulative: the corrected angle with the scale factor and bias over coil temperature applied ([`crate::fog::scale_factor`]), same LSB |
//! | 70 | i32 | FOG scale-factor correction in use: output times 1 + x/2^32 |
//! | 74 | i32 | FOG bias removed, Q16 deg/h |
//! | 78 | i16 | FOG coil temperature the table was read at (sensor plus lag lead), Q8 degC |
//! | 80 | i16 | FOG coil sensor value in use (held while bad), Q8 degC |
//! | 82 | u8 | FOG temperature flags ([`FogTempFlags`]: coil sensor bad, out of the calibrated range, table refused) |
//! | 83 | u8 | closures missed in this frame (the sampling overran: their angle is lost), saturating at 255 |
//! | 84 | u16 | CRC-16/CCITT-FALSE over bytes 2..84 |
//!
//! Version 1 (44 bytes) was the FOG part alone; version 2 (64 bytes) ended
//! after byte 61; version 3 carried each frame's angle increments (a lost
//! frame lost its angle), had bytes 61 and 83 reserved and no overrun faults.
//!
//! The angle words are cumulative on the wire, so a frame lost on the way
//! loses no angle: the next one's words include it. Inside the frame path
//! a [`Frame`] holds the frame's own increments (the builder sums them, the
//! scale-factor table compensates them); [`AngleTotals::stamp`] makes them
//! the cumulative words as the frame is sent. Over a lost frame the
//! difference of two frames' words is exact while the angle between them
//! stays below 2^63 LSB (the FOG) and 2^31 counts (the RLG).

use crate::fog::closure::ClosureOutput;
use crate::fog::faults::Faults;
use crate::fog::scale_factor::{FogTempFlags, FogTempWords, ScaleFactorComp, ScaleFactorConfig};
use crate::rlg::channel::RlgWords;
use crate::rlg::thermal::RlgFlags;
use crc::{Crc, CRC_16_IBM_3740};

pub const FRAME_LEN: usize = 86;
pub const SYNC: [u8; 2] = [0xA5, 0x5A];
pub const VERSION: u8 = 4;
const CRC16: Crc<u16> = Crc::<u16>::new(&CRC_16_IBM_3740);

/// Why the board last started, from the reset flags and what the firmware
/// left in RAM before it reset (the board's `reset_cause`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
#[repr(u8)]
pub enum ResetCause {
    /// Not the first frame after a start.
    #[default]
    None = 0,
    /// Power-on or brown-out.
    PowerOn = 1,
    /// The reset pin (a debugger or the supervisor).
    Pin = 2,
    /// The independent watchdog: the firmware stopped feeding it (a hang).
    Watchdog = 3,
    /// A HardFault: the handler logged it and reset.
    HardFault = 4,
    /// A software reset the firmware asked for (a refused configuration).
    Software = 5,
    /// A panic: start-up or the idle loop (no interrupt handler can,
    /// `cargo xtask isr-proof`); the panic handler left its mark and reset.
    Panic = 6,
}

impl ResetCause {
    /// The frame byte's cause; unknown values read as `None`.
    pub fn from_byte(b: u8) -> Self {
        match b {
            1 => Self::PowerOn,
            2 => Self::Pin,
            3 => Self::Watchdog,
            4 => Self::HardFault,
            5 => Self::Software,
            6 => Self::Panic,
            _ => Self::None,
        }
    }

    /// The board restarted after a fault (watchdog, hard fault or panic).
    pub fn is_recovery(self) -> bool {
        matches!(self, Self::Watchdog | Self::HardFault | Self::Panic)
    }
}

#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Frame {
    pub seq: u16,
    pub faults: Faults,
    pub closures: u16,
    pub closure_counter: u32,
    pub fog_angle: i64,
    pub fog_angle_raw: i64,
    pub fog_residual: i32,
    pub codes_per_turn_q8: u32,
    pub dc: u32,
    pub rlg: RlgWords,
    pub fog_angle_comp: i64,
    pub fog_temp: FogTempWords,
    /// Why the board started (first frame after a start only).
    pub reset_cause: ResetCause,
    /// Closures whose samples the sampling overran in this frame.
    pub closures_missed: u8,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FrameError {
    Sync,
    Version,
    Length,
    Crc,
}

/// The frame's CRC-16/CCITT-FALSE over `data`.
pub fn crc16(data: &[u8]) -> u16 {
    CRC16.checksum(data)
}

/// Whether `b` starts with a whole frame of any version: the sync, then
/// its declared length (byte 3 counts the bytes after it) and a CRC over
/// bytes 2..len-2 that matches. `Some(version)` if so.
pub fn any_version(b: &[u8]) -> Option<u8> {
    if b.get(..2)? != SYNC {
        return None;
    }
    let len = *b.get(3)? as usize + 4;
    let body = b.get(2..len.checked_sub(2)?)?;
    let crc = u16::from_le_bytes([*b.get(len - 2)?, *b.get(len - 1)?]);
    (len >= 8 && CRC16.checksum(body) == crc).then_some(b[2])
}

impl Frame {
    pub fn encode(&self) -> [u8; FRAME_LEN] {
        let mut b = [0u8; FRAME_LEN];
        let mut w = Writer {
            buf: &mut b,
            pos: 0,
        };
        w.put(&SYNC);
        w.put(&[VERSION, (FRAME_LEN - 4) as u8]);
        w.put(&self.seq.to_le_bytes());
        w.put(&self.faults.bits().to_le_bytes());
        w.put(&self.closures.to_le_bytes());
        w.put(&self.closure_counter.to_le_bytes());
        w.put(&self.fog_angle.to_le_bytes());
        w.put(&self.fog_angle_raw.to_le_bytes());
        w.put(&self.fog_residual.to_le_bytes());
        w.put(&self.codes_per_turn_q8.to_le_bytes());
        w.put(&self.dc.to_le_bytes());
        let g = &self.rlg;
        w.put(&g.delta_counts.to_le_bytes());
        w.put(&g.rate_comp_udps.to_le_bytes());
        w.put(&g.bias_q16_dph.to_le_bytes());
        w.put(&g.t_mono_a_q8.to_le_bytes());
        w.put(&g.t_mono_b_q8.to_le_bytes());
        w.put(&g.t_case_q8.to_le_bytes());
        w.put(&[g.flags.bits(), self.reset_cause as u8]);
        w.put(&self.fog_angle_comp.to_le_bytes());
        let t = &self.fog_temp;
        w.put(&t.sf_corr_q32.to_le_bytes());
        w.put(&t.bias_q16_dph.to_le_bytes());
        w.put(&t.t_coil_q8.to_le_bytes());
        w.put(&t.t_sensor_q8.to_le_bytes());
        w.put(&[t.flags.bits(), self.closures_missed]);
        let crc = CRC16.checksum(b.get(2..FRAME_LEN - 2).unwrap_or(&[]));
        if let Some(t) = b.get_mut(FRAME_LEN - 2..) {
            t.copy_from_slice(&crc.to_le_bytes());
        }
        b
    }

    pub fn decode(b: &[u8]) -> Result<Self, FrameError> {
        let b: &[u8; FRAME_LEN] = b
            .get(..FRAME_LEN)
            .and_then(|s| s.try_into().ok())
            .ok_or(FrameError::Length)?;
        if b[..2] != SYNC {
            return Err(FrameError::Sync);
        }
        if b[3] as usize != FRAME_LEN - 4 {
            return Err(FrameError::Length);
        }
        let crc = u16::from_le_bytes([b[FRAME_LEN - 2], b[FRAME_LEN - 1]]);
        if CRC16.checksum(&b[2..FRAME_LEN - 2]) != crc {
            return Err(FrameError::Crc);
        }
        // Checked after the CRC: a Version error is a whole frame of another
        // version, not noise.
        if b[2] != VERSION {
            return Err(FrameError::Version);
        }
        let mut r = Reader { buf: b, pos: 4 };
        Ok(Self {
            seq: u16::from_le_bytes(r.take()),
            faults: Faults::from_bits_retain(u16::from_le_bytes(r.take())),
            closures: u16::from_le_bytes(r.take()),
            closure_counter: u32::from_le_bytes(r.take()),
            fog_angle: i64::from_le_bytes(r.take()),
            fog_angle_raw: i64::from_le_bytes(r.take()),
            fog_residual: i32::from_le_bytes(r.take()),
            codes_per_turn_q8: u32::from_le_bytes(r.take()),
            dc: u32::from_le_bytes(r.take()),
            rlg: RlgWords {
                delta_counts: i32::from_le_bytes(r.take()),
                rate_comp_udps: i32::from_le_bytes(r.take()),
                bias_q16_dph: i32::from_le_bytes(r.take()),
                t_mono_a_q8: i16::from_le_bytes(r.take()),
                t_mono_b_q8: i16::from_le_bytes(r.take()),
                t_case_q8: i16::from_le_bytes(r.take()),
                flags: RlgFlags::from_bits_retain(r.take::<1>()[0]),
            },
            reset_cause: ResetCause::from_byte(r.take::<1>()[0]),
            fog_angle_comp: i64::from_le_bytes(r.take()),
            fog_temp: FogTempWords {
                sf_corr_q32: i32::from_le_bytes(r.take()),
                bias_q16_dph: i32::from_le_bytes(r.take()),
                t_coil_q8: i16::from_le_bytes(r.take()),
                t_sensor_q8: i16::from_le_bytes(r.take()),
                flags: FogTempFlags::from_bits_retain(r.take::<1>()[0]),
            },
            closures_missed: r.take::<1>()[0],
        })
    }

    /// Fills the compensated FOG angle and its words from the frame's
    /// corrected angle (at frame completion, so a frame merged back after a
    /// full queue is compensated whole).
    pub fn compensate_fog(&mut self, sf: &ScaleFactorComp, cfg: &ScaleFactorConfig) {
        let (angle, words) = sf.compensate(cfg, self.fog_angle, self.closures);
        self.fog_angle_comp = angle;
        self.fog_temp = words;
    }
}

struct Writer<'a> {
    buf: &'a mut [u8],
    pos: usize,
}
impl Writer<'_> {
    fn put(&mut self, bytes: &[u8]) {
        if let Some(d) = self.buf.get_mut(self.pos..self.pos + bytes.len()) {
            d.copy_from_slice(bytes);
        }
        self.pos += bytes.len();
    }
}
struct Reader<'a> {
    buf: &'a [u8],
    pos: usize,
}
impl Reader<'_> {
    fn take<const N: usize>(&mut self) -> [u8; N] {
        let mut out = [0u8; N];
        if let Some(s) = self.buf.get(self.pos..self.pos + N) {
            out.copy_from_slice(s);
        }
        self.pos += N;
        out
    }
}

/// The running totals of the angle words: the cumulative values the wire
/// carries (wrapping, differenced by the receiver).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct AngleTotals {
    fog: i64,
    fog_raw: i64,
    fog_comp: i64,
    rlg_counts: i32,
}

impl AngleTotals {
    /// `f` (its angle words the frame's increments) as sent: its words
    /// cumulative; and the totals after it, to keep once it is sent.
    pub fn stamp(&self, f: &Frame) -> (Frame, AngleTotals) {
        let after = AngleTotals {
            fog: self.fog.wrapping_add(f.fog_angle),
            fog_raw: self.fog_raw.wrapping_add(f.fog_angle_raw),
            fog_comp: self.fog_comp.wrapping_add(f.fog_angle_comp),
            rlg_counts: self.rlg_counts.wrapping_add(f.rlg.delta_counts),
        };
        let mut wire = *f;
        wire.fog_angle = after.fog;
        wire.fog_angle_raw = after.fog_raw;
        wire.fog_angle_comp = after.fog_comp;
        wire.rlg.delta_counts = after.rlg_counts;
        (wire, after)
    }
}

/// Accumulates closures into frames: angle increments are summed exactly,
/// so a frame that could not be sent is merged back and nothing is lost.
#[derive(Clone, Copy, Debug)]
pub struct FrameBuilder {
    acc: Frame,
    closures_per_frame: u16,
    n_half: i64,
    next_seq: u16,
}

impl FrameBuilder {
    pub fn new(closures_per_frame: u16, n_half: usize) -> Self {
        Self {
            acc: Frame::default(),
            closures_per_frame: closures_per_frame.max(1),
            n_half: n_half as i64,
            next_seq: 0,
        }
    }

    /// Adds one closure; returns a complete frame every `closures_per_frame` closures.
    pub fn push(&mut self, out: &ClosureOutput, closure_counter: u32) -> Option<Frame> {
        let a = &mut self.acc;
        a.closures = a.closures.saturating_add(1);
        a.faults |= out.faults;
        a.closure_counter = closure_counter;
        a.fog_angle = a
            .fog_angle
            .wrapping_add(out.sagnac_phase_corrected.wrapping_mul(self.n_half));
        a.fog_angle_raw = a
            .fog_angle_raw
            .wrapping_add(out.sagnac_phase.wrapping_mul(self.n_half));
        a.fog_residual = out.residual;
        a.codes_per_turn_q8 = out.codes_per_turn_q8;
        a.dc = out.dc;
        if a.closures >= self.closures_per_frame {
            let mut f = core::mem::take(a);
            f.seq = self.next_seq;
            self.next_seq = self.next_seq.wrapping_add(1);
            Some(f)
        } else {
            None
        }
    }

    /// Closures the sampling overran before the next one pushed: their
    /// angle is lost, so the frame says how many (and the fault), and the
    /// caller's closure counter counts them as periods.
    pub fn lost_closures(&mut self, n: u32, faults: Faults) {
        let a = &mut self.acc;
        a.closures_missed = a
            .closures_missed
            .saturating_add(n.min(u8::MAX as u32) as u8);
        a.faults |= faults;
    }

    /// Marks the frame being built as the first after a start.
    pub fn set_reset_cause(&mut self, cause: ResetCause) {
        self.acc.reset_cause = cause;
        if cause.is_recovery() {
            self.acc.faults |= Faults::RESET_RECOVERED;
        }
    }

    /// True when the next closure pushed completes a frame.
    pub fn completes_next(&self) -> bool {
        self.acc.closures.saturating_add(1) >= self.closures_per_frame
    }

    /// Puts the RLG words of this frame in (counts add up, the rest is latest).
    pub fn set_rlg(&mut self, w: RlgWords) {
        let d = self.acc.rlg.delta_counts;
        self.acc.rlg = RlgWords {
            delta_counts: d.wrapping_add(w.delta_counts),
            ..w
        };
    }

    /// Takes back a frame that could not be queued: its closures go into the next
    /// frame (flagged), which reuses its sequence number, so no angle is lost.
    pub fn restore(&mut self, f: Frame) {
        let a = &mut self.acc;
        a.closures = a.closures.saturating_add(f.closures);
        a.faults |= f.faults | Faults::QUEUE_FULL;
        a.fog_angle = a.fog_angle.wrapping_add(f.fog_angle);
        a.fog_angle_raw = a.fog_angle_raw.wrapping_add(f.fog_angle_raw);
        a.rlg.delta_counts = a.rlg.delta_counts.wrapping_add(f.rlg.delta_counts);
        a.rlg.flags |= f.rlg.flags;
        a.closures_missed = a.closures_missed.saturating_add(f.closures_missed);
        if a.reset_cause == ResetCause::None {
            a.reset_cause = f.reset_cause;
        }
        self.next_seq = f.seq;
    }
}
