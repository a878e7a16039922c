//! The stream decoder: bytes in, frames out, nothing lost silently.
//!
//! - Resynchronisation: bytes that do not start a frame are skipped until
//!   the sync word starts one whose CRC holds. A frame that fails its CRC
//!   where a frame was due (the stream was in step) is counted as a CRC
//!   failure; candidates found while hunting are not (a sync pattern inside
//!   data is not a frame).
//! - Lost frames: sequence numbers (u16) locate gaps; the closure counter
//!   resolves a gap longer than the sequence's wrap.
//! - Time base: the closure counter, unwrapped, since the board started.
//! - Angles: the wire's words are cumulative, so each frame's increment is
//!   the difference from the previous decoded frame, exact across any gap.
//! - A whole frame of another version (sync, length and CRC all hold) is an
//!   error: this decoder does not know its fields.

use gyro_sp::frame::{any_version, Frame, FrameError, FRAME_LEN, SYNC, VERSION};

/// What makes a stream unreadable.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum StreamError {
    /// A whole frame of another format version at this byte offset.
    OtherVersion { offset: u64, version: u8 },
}

impl core::fmt::Display for StreamError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            StreamError::OtherVersion { offset, version } => write!(
                f,
                "byte {offset}: a frame of version {version}; this tool reads version {VERSION}"
            ),
        }
    }
}

/// The frame's angle words as increments since the previous decoded frame.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Increments {
    /// FOG angle, eps^2-corrected, angle LSB.
    pub fog: i64,
    /// FOG angle without the eps^2 correction.
    pub fog_raw: i64,
    /// FOG angle with the scale factor and bias over temperature applied.
    pub fog_comp: i64,
    /// RLG counts.
    pub rlg_counts: i64,
}

/// One decoded frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Decoded {
    /// As on the wire (its angle words cumulative).
    pub frame: Frame,
    /// Byte offset of its sync word in the stream.
    pub offset: u64,
    /// Closure periods since the board started, at the frame's end.
    pub counter: u64,
    /// Frames lost between the previous decoded frame and this one.
    pub lost_before: u32,
    /// Closure periods since the previous decoded frame.
    pub span_closures: u64,
    /// Increments since the previous decoded frame; `None` for the first
    /// frame of a record that joined a running board (it anchors the
    /// cumulative words; the increments before it are not the record's).
    pub increments: Option<Increments>,
}

impl Decoded {
    /// Closure periods whose angle the increments hold: the span less the
    /// closures this frame says the board missed (the frames lost in a gap
    /// may have missed some too; their count went with them).
    pub fn processed_closures(&self) -> u64 {
        self.span_closures
            .saturating_sub(self.frame.closures_missed as u64)
    }
}

/// The previous decoded frame's words.
#[derive(Clone, Copy, Debug)]
struct Prev {
    seq: u16,
    counter: u64,
    fog: i64,
    fog_raw: i64,
    fog_comp: i64,
    rlg: i32,
}

/// A resynchronising decoder over a byte stream given in any chunks.
#[derive(Debug, Default)]
pub struct Decoder {
    buf: Vec<u8>,
    /// Stream offset of `buf[0]`.
    offset: u64,
    prev: Option<Prev>,
    /// The last bytes consumed ended a good frame (a frame is due next).
    in_step: bool,
    /// Bytes taken in.
    pub bytes: u64,
    /// Frames that failed their CRC (or length) where a frame was due.
    pub crc_errors: u64,
    /// Times the decoder hunted for the sync word and found a frame again.
    pub resyncs: u64,
    /// Bytes skipped while hunting.
    pub skipped_bytes: u64,
    /// Frames decoded, and frames found lost by their sequence numbers.
    pub frames: u64,
    pub lost_frames: u64,
    /// Frames dropped as exact repeats of the previous one.
    pub duplicates: u64,
}

impl Decoder {
    pub fn new() -> Self {
        Self::default()
    }

    /// Takes `bytes`, appends every frame they complete to `out`.
    pub fn push(&mut self, bytes: &[u8], out: &mut Vec<Decoded>) -> Result<(), StreamError> {
        self.bytes += bytes.len() as u64;
        self.buf.extend_from_slice(bytes);
        let mut i = 0;
        let mut result = Ok(());
        while self.buf.len() - i >= 4 {
            let b = &self.buf[i..];
            if b[..2] != SYNC {
                self.skip(1, &mut i);
                continue;
            }
            if b[2] != VERSION {
                if let Some(v) = any_version(b).filter(|&v| v != VERSION) {
                    result = Err(StreamError::OtherVersion {
                        offset: self.offset + i as u64,
                        version: v,
                    });
                    break;
                }
            }
            if b.len() < FRAME_LEN {
                break;
            }
            match Frame::decode(b) {
                Ok(f) => {
                    let offset = self.offset + i as u64;
                    if !self.in_step && offset > 0 {
                        self.resyncs += 1;
                    }
                    self.in_step = true;
                    i += FRAME_LEN;
                    if let Some(d) = self.next(f, offset) {
                        out.push(d);
                    }
                }
                Err(FrameError::Crc | FrameError::Length) => {
                    if self.in_step {
                        self.crc_errors += 1;
                    }
                    self.skip(1, &mut i);
                }
                Err(FrameError::Version) => {
                    // CRC good, version other: reported above; unreachable
                    // unless `any_version` and `decode` disagree.
                    result = Err(StreamError::OtherVersion {
                        offset: self.offset + i as u64,
                        version: b[2],
                    });
                    break;
                }
                Err(FrameError::Sync) => self.skip(1, &mut i),
            }
        }
        self.buf.drain(..i);
        self.offset += i as u64;
        result
    }

    fn skip(&mut self, n: usize, i: &mut usize) {
        *i += n;
        self.skipped_bytes += n as u64;
        self.in_step = false;
    }

    /// The frame after the previous one: time base, gap, increments.
    fn next(&mut self, f: Frame, offset: u64) -> Option<Decoded> {
        let own = f.closures as u64 + f.closures_missed as u64;
        let d = match self.prev {
            None => {
                let counter = f.closure_counter as u64;
                // The board started within this frame: its words are its own
                // increments. Otherwise they include time before the record.
                let from_start = counter <= own.max(1);
                Decoded {
                    frame: f,
                    offset,
                    counter,
                    lost_before: 0,
                    span_closures: own.min(counter),
                    increments: from_start.then_some(Increments {
                        fog: f.fog_angle,
                        fog_raw: f.fog_angle_raw,
                        fog_comp: f.fog_angle_comp,
                        rlg_counts: f.rlg.delta_counts as i64,
                    }),
                }
            }
            Some(p) => {
                let span = f.closure_counter.wrapping_sub(p.counter as u32) as u64;
                if span == 0 && f.seq == p.seq {
                    self.duplicates += 1;
                    return None;
                }
                let gap = f.seq.wrapping_sub(p.seq).wrapping_sub(1) as i64;
                // Frames the span holds, by the counter: resolves gaps of
                // more than 2^16 frames (the sequence number's wrap).
                let by_counter = (span / own.max(1)) as i64 - 1;
                let wraps = ((by_counter - gap) as f64 / 65_536.0).round().max(0.0) as i64;
                let lost = (gap + 65_536 * wraps).clamp(0, u32::MAX as i64) as u32;
                Decoded {
                    frame: f,
                    offset,
                    counter: p.counter + span,
                    lost_before: lost,
                    span_closures: span,
                    increments: Some(Increments {
                        fog: f.fog_angle.wrapping_sub(p.fog),
                        fog_raw: f.fog_angle_raw.wrapping_sub(p.fog_raw),
                        fog_comp: f.fog_angle_comp.wrapping_sub(p.fog_comp),
                        rlg_counts: f.rlg.delta_counts.wrapping_sub(p.rlg) as i64,
                    }),
                }
            }
        };
        self.frames += 1;
        self.lost_frames += d.lost_before as u64;
        self.prev = Some(Prev {
            seq: f.seq,
            counter: d.counter,
            fog: f.fog_angle,
            fog_raw: f.fog_angle_raw,
            fog_comp: f.fog_angle_comp,
            rlg: f.rlg.delta_counts,
        });
        Some(d)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use gyro_sp::fog::{ClosureOutput, Faults};
    use gyro_sp::frame::{AngleTotals, FrameBuilder};
    use gyro_sp::rlg::RlgWords;

    /// `n` frames of 25 closures as the board sends them, with varying
    /// angles, and the sum of their FOG and RLG increments.
    fn board_stream(n: usize) -> (Vec<u8>, i64, i64) {
        let mut b = FrameBuilder::new(25, 16);
        let mut totals = AngleTotals::default();
        let (mut bytes, mut fog, mut rlg) = (Vec::new(), 0i64, 0i64);
        let mut counter = 0u32;
        for k in 0..n * 25 {
            counter += 1;
            let phase = ((k as i64 * 7919) % 100_003) - 50_000;
            let out = ClosureOutput {
                sagnac_phase: phase << 20,
                sagnac_phase_corrected: (phase << 20) - 3,
                ..ClosureOutput::default()
            };
            if b.completes_next() {
                let c = (k as i32 % 13) - 6;
                b.set_rlg(RlgWords {
                    delta_counts: c,
                    ..RlgWords::default()
                });
            }
            if let Some(mut f) = b.push(&out, counter) {
                f.fog_angle_comp = f.fog_angle;
                fog += f.fog_angle;
                rlg += f.rlg.delta_counts as i64;
                let (wire, after) = totals.stamp(&f);
                totals = after;
                bytes.extend_from_slice(&wire.encode());
            }
        }
        (bytes, fog, rlg)
    }

    fn decode_all(bytes: &[u8], chunk: usize) -> (Decoder, Vec<Decoded>) {
        let mut d = Decoder::new();
        let mut out = Vec::new();
        for c in bytes.chunks(chunk.max(1)) {
            d.push(c, &mut out).unwrap();
        }
        (d, out)
    }

    fn sums(out: &[Decoded]) -> (i64, i64) {
        out.iter()
            .filter_map(|d| d.increments)
            .fold((0, 0), |(f, r), i| (f + i.fog, r + i.rlg_counts))
    }

    /// A clean stream in any chunking: every frame, no error, the angles
    /// summed back exactly, the time base from the counter.
    #[test]
    fn clean_stream_round_trips() {
        let (bytes, fog, rlg) = board_stream(200);
        for chunk in [1, 7, 86, 1000, bytes.len()] {
            let (d, out) = decode_all(&bytes, chunk);
            assert_eq!(out.len(), 200);
            assert_eq!((d.crc_errors, d.resyncs, d.lost_frames), (0, 0, 0));
            assert_eq!(sums(&out), (fog, rlg));
            assert_eq!(out.last().unwrap().counter, 200 * 25);
            assert!(out.iter().all(|x| x.span_closures == 25));
        }
    }

    /// Frames cut out, bits flipped, garbage inserted, bytes dropped: the
    /// lost frames are counted exactly, every intact frame is kept, and the
    /// angle at the end equals the clean stream's.
    #[test]
    fn damaged_stream_keeps_the_angle() {
        let (bytes, fog, rlg) = board_stream(300);
        let frame = |k: usize| k * FRAME_LEN..(k + 1) * FRAME_LEN;
        let mut damaged = Vec::new();
        let mut lost = 0;
        let mut crc_hits = 0;
        for k in 0..300 {
            let mut f = bytes[frame(k)].to_vec();
            match k % 37 {
                5 => {
                    // A flipped bit.
                    f[40] ^= 0x10;
                    lost += 1;
                    crc_hits += 1;
                }
                11 => {
                    // A dropped byte.
                    f.remove(20);
                    lost += 1;
                }
                17 => {
                    // A burst of garbage with sync patterns in it, before
                    // an intact frame.
                    damaged.extend_from_slice(&[0xA5, 0x5A, 4, 82, 1, 2, 0xA5, 0xA5, 0x5A, 0]);
                }
                23 => {
                    // A frame missing altogether (a stall).
                    lost += 1;
                    continue;
                }
                _ => {}
            }
            damaged.extend_from_slice(&f);
        }
        let (d, out) = decode_all(&damaged, 64);
        assert_eq!(d.lost_frames, lost as u64);
        assert_eq!(out.len(), 300 - lost);
        assert_eq!(sums(&out), (fog, rlg));
        assert!(d.crc_errors >= crc_hits as u64);
        assert!(d.resyncs > 0);
        // The row after a gap spans the gap.
        let after = out.iter().find(|x| x.lost_before == 1).unwrap();
        assert_eq!(after.span_closures, 50);
    }

    /// Joining a running board: the first frame anchors the words.
    #[test]
    fn joining_midway_anchors_on_the_first_frame() {
        let (bytes, _, _) = board_stream(50);
        let (_, out) = decode_all(&bytes[10 * FRAME_LEN + 3..], 100);
        assert_eq!(out.len(), 39);
        assert!(out[0].increments.is_none());
        assert!(out[1..].iter().all(|x| x.increments.is_some()));
    }

    /// A frame of another version is an error naming its offset.
    #[test]
    fn other_version_is_refused() {
        let (mut bytes, _, _) = board_stream(3);
        // Re-stamp frame 1 as version 3 with a valid CRC.
        let f = FRAME_LEN;
        bytes[f + 2] = 3;
        let crc = crc16_ibm_3740(&bytes[f + 2..2 * f - 2]);
        bytes[2 * f - 2..2 * f].copy_from_slice(&crc.to_le_bytes());
        let mut d = Decoder::new();
        let mut out = Vec::new();
        let e = d.push(&bytes, &mut out).unwrap_err();
        assert_eq!(
            e,
            StreamError::OtherVersion {
                offset: FRAME_LEN as u64,
                version: 3
            }
        );
        assert_eq!(out.len(), 1);
    }

    /// Missed closures: the frame's own count, taken out of the angle's time.
    #[test]
    fn missed_closures_shorten_the_processed_time() {
        let mut b = FrameBuilder::new(25, 16);
        let mut counter = 0;
        let mut frames = vec![];
        for k in 0..60 {
            if k == 30 {
                counter += 2;
                b.lost_closures(2, Faults::CLOSURE_OVERRUN);
            }
            counter += 1;
            if let Some(f) = b.push(&ClosureOutput::default(), counter) {
                frames.push(f);
            }
        }
        let mut bytes = vec![];
        let mut t = AngleTotals::default();
        for f in &frames {
            let (w, a) = t.stamp(f);
            t = a;
            bytes.extend_from_slice(&w.encode());
        }
        let (_, out) = decode_all(&bytes, 86);
        assert_eq!(out[1].span_closures, 27);
        assert_eq!(out[1].processed_closures(), 25);
        assert!(out[1].frame.faults.contains(Faults::CLOSURE_OVERRUN));
    }

    /// CRC-16/CCITT-FALSE (IBM 3740), bitwise: the check the frame uses.
    fn crc16_ibm_3740(data: &[u8]) -> u16 {
        let mut crc = 0xFFFFu16;
        for &b in data {
            crc ^= (b as u16) << 8;
            for _ in 0..8 {
                crc = if crc & 0x8000 != 0 {
                    (crc << 1) ^ 0x1021
                } else {
                    crc << 1
                };
            }
        }
        crc
    }
}
