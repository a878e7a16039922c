//! A record on disk as bytes arrive: every byte to `raw.bin` at once (a
//! capture can always be decoded again), frames decoded into `fog.csv` and
//! `rlg.csv` with their rows flushed at least every second, and the
//! summary kept up to date. The caller owns the source (a serial port or a
//! capture file) and the progress display.

use crate::decode::{Decoded, Decoder, StreamError};
use crate::reference::Reference;
use crate::rows::{fog_rates, RunWriter};
use crate::scales::Scales;
use crate::summary::Summary;
use std::fs::File;
use std::io::{self, BufWriter, Write};
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

/// Decoded rows wait in memory at most this long before they are flushed.
pub const FLUSH_EVERY: Duration = Duration::from_millis(500);

/// What went wrong while recording.
#[derive(Debug)]
pub enum RecordError {
    /// Writing a file of the record.
    Io { path: PathBuf, error: io::Error },
    /// The stream holds frames this decoder cannot read.
    Stream(StreamError),
}

impl core::fmt::Display for RecordError {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            RecordError::Io { path, error } => write!(f, "{}: {error}", path.display()),
            RecordError::Stream(e) => write!(f, "{e}"),
        }
    }
}

/// The latest frame's values, for a progress line.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Latest {
    /// Board time, s.
    pub t_s: f64,
    pub fog_rate_dps: f64,
    pub rlg_rate_dps: f64,
    pub coil_c: f64,
    pub mono_c: [f64; 2],
    pub case_c: f64,
}

pub struct Recorder {
    dir: PathBuf,
    raw: File,
    decoder: Decoder,
    rows: RunWriter<BufWriter<File>>,
    summary: Summary,
    reference: Reference,
    scales: Scales,
    decoded: Vec<Decoded>,
    last_flush: Instant,
    latest: Option<Latest>,
}

fn io_at(path: &Path) -> impl Fn(io::Error) -> RecordError + '_ {
    move |error| RecordError::Io {
        path: path.to_path_buf(),
        error,
    }
}

impl Recorder {
    /// Creates `raw.bin`, `fog.csv` and `rlg.csv` in `dir` (made if needed).
    pub fn create(
        dir: &Path,
        scales: Scales,
        reference: Reference,
        comment: &str,
    ) -> Result<Self, RecordError> {
        std::fs::create_dir_all(dir).map_err(io_at(dir))?;
        let open = |name: &str| {
            let p = dir.join(name);
            File::create(&p).map_err(|error| RecordError::Io { path: p, error })
        };
        let raw = open("raw.bin")?;
        let rows = RunWriter::new(
            BufWriter::new(open("fog.csv")?),
            BufWriter::new(open("rlg.csv")?),
            scales,
            comment,
        )
        .map_err(io_at(dir))?;
        Ok(Self {
            dir: dir.to_path_buf(),
            raw,
            decoder: Decoder::new(),
            rows,
            summary: Summary::default(),
            reference,
            scales,
            decoded: Vec::new(),
            last_flush: Instant::now(),
            latest: None,
        })
    }

    /// Takes bytes as they arrived: raw first, then the frames they
    /// complete. A stream error (a frame of another version) comes after
    /// the rows before it are written.
    pub fn push(&mut self, bytes: &[u8]) -> Result<(), RecordError> {
        let raw_path = self.dir.join("raw.bin");
        self.raw.write_all(bytes).map_err(io_at(&raw_path))?;
        let stream = self.decoder.push(bytes, &mut self.decoded);
        let decoded = std::mem::take(&mut self.decoded);
        for d in &decoded {
            self.take(d)?;
        }
        if self.last_flush.elapsed() >= FLUSH_EVERY {
            self.flush()?;
        }
        stream.map_err(RecordError::Stream)
    }

    fn take(&mut self, d: &Decoded) -> Result<(), RecordError> {
        self.summary.add(d, &self.scales);
        let s = &self.scales;
        let to = d.counter as f64 * s.closure_s;
        let from = to - d.span_closures as f64 * s.closure_s;
        let reference = self.reference.mean(from, to);
        self.rows.row(d, reference).map_err(io_at(&self.dir))?;
        if let Some(inc) = d.increments {
            let f = &d.frame;
            let q8 = |x: i16| x as f64 / 256.0;
            self.latest = Some(Latest {
                t_s: to,
                fog_rate_dps: fog_rates(d, &inc, s).map_or(f64::NAN, |r| r.rate_comp_dps),
                rlg_rate_dps: f.rlg.rate_comp_udps as f64 * 1e-6,
                coil_c: q8(f.fog_temp.t_sensor_q8),
                mono_c: [q8(f.rlg.t_mono_a_q8), q8(f.rlg.t_mono_b_q8)],
                case_c: q8(f.rlg.t_case_q8),
            });
        }
        Ok(())
    }

    /// Flushes the rows (raw.bin is written unbuffered).
    pub fn flush(&mut self) -> Result<(), RecordError> {
        self.last_flush = Instant::now();
        self.rows.flush().map_err(io_at(&self.dir))?;
        self.raw.flush().map_err(io_at(&self.dir))
    }

    /// The summary so far (the decoder's counts included).
    pub fn summary(&self) -> Summary {
        let mut s = self.summary.clone();
        s.finish(&self.decoder);
        s
    }

    pub fn latest(&self) -> Option<Latest> {
        self.latest
    }

    /// The FOG angle (deg) and RLG counts since the record's start.
    pub fn angles(&self) -> (f64, i64) {
        (self.rows.fog_angle_deg(), self.rows.rlg_counts())
    }

    /// Flushes everything and returns the summary.
    pub fn finish(mut self) -> Result<Summary, RecordError> {
        self.flush()?;
        Ok(self.summary())
    }
}
