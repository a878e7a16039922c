//! What a record held: frames, errors, the lost frames with their sequence
//! numbers and times, each fault flag with its count and first and last
//! time, the closures the board missed and why it started.

use crate::decode::{Decoded, Decoder};
use crate::scales::Scales;
use gyro_sp::frame::ResetCause;

/// Frames lost between two decoded ones.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LostSpan {
    /// Sequence numbers of the frames either side.
    pub after_seq: u16,
    pub before_seq: u16,
    pub frames: u32,
    /// Board time of the two frames' ends, s.
    pub from_s: f64,
    pub to_s: f64,
}

/// How often one fault flag was up, and when.
#[derive(Clone, Debug, PartialEq)]
pub struct FlagStat {
    /// `fog.` (frame faults), `rlg.` or `fog_temp.` and the flag's name.
    pub name: String,
    pub frames: u64,
    pub first_s: f64,
    pub last_s: f64,
}

#[derive(Clone, Debug, Default, PartialEq)]
pub struct Summary {
    pub frames: u64,
    pub bytes: u64,
    pub crc_errors: u64,
    pub resyncs: u64,
    pub skipped_bytes: u64,
    pub duplicates: u64,
    pub lost_frames: u64,
    pub lost: Vec<LostSpan>,
    pub flags: Vec<FlagStat>,
    /// Closures the board reported missed (their angle is lost).
    pub closures_missed: u64,
    /// Starts the record saw (board time, cause).
    pub starts: Vec<(f64, ResetCause)>,
    /// Board time of the first and last decoded frame, s.
    pub first_s: f64,
    pub last_s: f64,
    last_seq: Option<(u16, f64)>,
}

impl Summary {
    /// Takes one decoded frame.
    pub fn add(&mut self, d: &Decoded, s: &Scales) {
        let t = d.counter as f64 * s.closure_s;
        if self.last_seq.is_none() {
            self.first_s = t;
        }
        self.last_s = t;
        if let (Some((seq, t0)), true) = (self.last_seq, d.lost_before > 0) {
            self.lost.push(LostSpan {
                after_seq: seq,
                before_seq: d.frame.seq,
                frames: d.lost_before,
                from_s: t0,
                to_s: t,
            });
        }
        self.last_seq = Some((d.frame.seq, t));
        self.closures_missed += d.frame.closures_missed as u64;
        if d.frame.reset_cause != ResetCause::None {
            self.starts.push((t, d.frame.reset_cause));
        }
        let f = &d.frame;
        let names = f
            .faults
            .iter_names()
            .map(|(n, _)| ("fog", n))
            .chain(f.rlg.flags.iter_names().map(|(n, _)| ("rlg", n)))
            .chain(f.fog_temp.flags.iter_names().map(|(n, _)| ("fog_temp", n)));
        for (group, n) in names {
            let name = format!("{group}.{}", n.to_ascii_lowercase());
            match self.flags.iter_mut().find(|x| x.name == name) {
                Some(x) => {
                    x.frames += 1;
                    x.last_s = t;
                }
                None => self.flags.push(FlagStat {
                    name,
                    frames: 1,
                    first_s: t,
                    last_s: t,
                }),
            }
        }
    }

    /// The decoder's counts at the end.
    pub fn finish(&mut self, dec: &Decoder) {
        self.frames = dec.frames;
        self.bytes = dec.bytes;
        self.crc_errors = dec.crc_errors;
        self.resyncs = dec.resyncs;
        self.skipped_bytes = dec.skipped_bytes;
        self.duplicates = dec.duplicates;
        self.lost_frames = dec.lost_frames;
    }
}
