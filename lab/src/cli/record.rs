//! `gyro-lab record`: the board's frames from a serial port (or a raw
//! capture) into a record directory: `raw.bin` (every byte received),
//! `fog.csv` and `rlg.csv` (run files, time from the board's closure
//! counter), `record.json` (the summary). The decoding and the files are
//! gyro-frames' `Recorder`, the one `cargo xtask qemu` uses too.

use crate::cli::args::{Json, Out, RunRead};
use crate::cli::out_path::{self, FileKind};
use crate::cli::output::print_json;
use clap::Args;
use gyro_frames::reference::RateLogError;
use gyro_frames::{RateLog, RecordError, Recorder, Reference, Scales};
use gyro_lab_core::commands::frames::{summary_json, RecordJson};
use gyro_lab_core::data::run_file::{self, Column};
use gyro_lab_core::data::table::TextTable;
use gyro_lab_core::error::LabError;
use std::io::{ErrorKind, Read};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

#[derive(Args, Debug, Clone)]
#[command(group(clap::ArgGroup::new("source").required(true).args(["port", "from"])))]
#[command(group(clap::ArgGroup::new("reference_source").args(["ref_rate", "reference"])))]
pub struct RecordArgs {
    /// Serial port the board's frames arrive on (a USB-serial adapter, or a
    /// pseudo-terminal).
    #[arg(long)]
    pub port: Option<PathBuf>,
    /// Baud rate of the port.
    #[arg(long, default_value_t = 2_000_000)]
    pub baud: u32,
    /// Decode a raw capture (a `raw.bin`) instead of a port.
    #[arg(long)]
    pub from: Option<PathBuf>,
    #[command(flatten)]
    pub out: Out,
    /// How to read the --reference log (its column names, units, stretch).
    #[command(flatten)]
    pub read: RunRead,
    /// Stop after this many seconds (of the host's clock; a capture is read
    /// to its end). Without it a port is read until Ctrl-C or it goes away.
    #[arg(long)]
    pub duration_s: Option<f64>,
    /// A constant reference rate, deg/s (e.g. the Earth-rate component on
    /// a static bench).
    #[arg(long = "ref-rate-dps", allow_negative_numbers = true)]
    pub ref_rate: Option<f64>,
    /// A rate-table log (`t_s`, `ref_rate_dps`), merged by time.
    #[arg(long)]
    pub reference: Option<PathBuf>,
    /// The board's time at the log's zero, s (board time = log time + offset).
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
    pub reference_offset_s: f64,
    /// RLG encoder counts per degree (quadrature edges, x4).
    #[arg(long, default_value_t = 8_000.0)]
    pub rlg_counts_per_deg: f64,
    #[command(flatten)]
    pub json: Json,
}

/// How long a read waits for bytes before the loop looks at the clock.
const READ_TIMEOUT: Duration = Duration::from_millis(100);
/// How often the progress line is redrawn.
const PROGRESS_EVERY: Duration = Duration::from_millis(500);
/// On a stderr that is not a terminal (a log file, a pipe), a plain line
/// this often instead of the redrawn one: no terminal escape codes.
const PROGRESS_LOG_EVERY: Duration = Duration::from_secs(10);

/// Where the bytes come from.
enum Source {
    Port(Box<dyn serialport::SerialPort>),
    Capture(std::fs::File),
}

impl Source {
    /// Reads what is there: `Ok(0)` on a port's timeout, `Ok(None)` at a
    /// capture's end.
    fn read(&mut self, buf: &mut [u8]) -> std::io::Result<Option<usize>> {
        match self {
            Source::Port(p) => match p.read(buf) {
                Ok(0) => Err(std::io::Error::new(
                    ErrorKind::UnexpectedEof,
                    "the port closed",
                )),
                Ok(n) => Ok(Some(n)),
                Err(e) if e.kind() == ErrorKind::TimedOut || e.kind() == ErrorKind::Interrupted => {
                    Ok(Some(0))
                }
                Err(e) => Err(e),
            },
            Source::Capture(f) => match f.read(buf)? {
                0 => Ok(None),
                n => Ok(Some(n)),
            },
        }
    }
}

fn reference(a: &RecordArgs) -> Result<Reference, LabError> {
    if let Some(r) = a.ref_rate {
        if !r.is_finite() {
            return Err(LabError::Usage(format!("--ref-rate-dps {r}: not finite")));
        }
        return Ok(Reference::Constant(r));
    }
    let Some(path) = &a.reference else {
        return Ok(Reference::Constant(0.0));
    };
    let spec = a.read.spec()?;
    let owned = spec.clone();
    let rules = Box::new(move |name: &str| run_file::rule(name, &owned));
    let t = TextTable::read_with(path, &spec, Some(Column::Time.name()), Some(rules))?;
    t.require(&[Column::Time.name(), Column::RefRate.name()])?;
    let time = t.time(Column::Time.name(), 2)?;
    let rate = t.column(Column::RefRate.name())?;
    RateLog::new(time, rate, a.reference_offset_s)
        .map(Reference::Log)
        .map_err(|e| {
            LabError::input(
                path,
                match e {
                    RateLogError::TooShort => "fewer than two reference samples".to_string(),
                    RateLogError::NotIncreasing { index } => {
                        format!(
                            "reference sample {index} is not after the one before, or not finite"
                        )
                    }
                },
            )
        })
}

fn record_error(e: RecordError, source: &Path) -> LabError {
    match e {
        RecordError::Io { path, error } => LabError::io(path, error),
        RecordError::Stream(s) => LabError::input(source, s.to_string()),
    }
}

pub fn run(a: &RecordArgs) -> Result<(), LabError> {
    if !(a.rlg_counts_per_deg.is_finite() && a.rlg_counts_per_deg > 0.0) {
        return Err(LabError::Usage(format!(
            "--rlg-counts-per-deg {}: must be positive",
            a.rlg_counts_per_deg
        )));
    }
    if let Some(d) = a.duration_s {
        if !(d.is_finite() && d > 0.0) {
            return Err(LabError::Usage(format!(
                "--duration-s {d}: must be positive"
            )));
        }
    }
    let mut inputs: Vec<(&str, &Path)> = vec![];
    if let Some(f) = &a.from {
        inputs.push(("--from", f));
    }
    if let Some(r) = &a.reference {
        inputs.push(("--reference", r));
    }
    out_path::folder(
        "record",
        &a.out.out,
        &[
            ("raw.bin", FileKind::Binary),
            ("fog.csv", FileKind::Csv),
            ("rlg.csv", FileKind::Csv),
            ("record.json", FileKind::Json),
        ],
        &inputs,
        a.out.force,
    )?;
    let reference = reference(a)?;
    let (mut source, source_path) = match (&a.port, &a.from) {
        (Some(p), _) => {
            let port = serialport::new(p.to_string_lossy(), a.baud)
                .timeout(READ_TIMEOUT)
                .open()
                .map_err(|e| LabError::input(p, format!("cannot open the port: {e}")))?;
            (Source::Port(port), p.clone())
        }
        (None, Some(f)) => {
            let file = std::fs::File::open(f)
                .map_err(|e| LabError::input(f, format!("cannot read: {e}")))?;
            (Source::Capture(file), f.clone())
        }
        (None, None) => return Err(LabError::Usage("--port or --from is needed".into())),
    };
    let scales = Scales {
        rlg_counts_per_deg: a.rlg_counts_per_deg,
        ..Scales::board()
    };
    let comment = format!("gyro-lab record from {}", source_path.display());
    let mut rec = Recorder::create(&a.out.out, scales, reference, &comment)
        .map_err(|e| record_error(e, &source_path))?;
    let stop = Arc::new(AtomicBool::new(false));
    if matches!(source, Source::Port(_)) {
        let s = stop.clone();
        // A second handler (a test harness) is not an error: Ctrl-C then
        // ends the process as usual, after the last flush.
        let _ = ctrlc::set_handler(move || s.store(true, Ordering::SeqCst));
    }
    let start = Instant::now();
    let mut progress = Progress::new(
        !a.json.json,
        std::io::IsTerminal::is_terminal(&std::io::stderr()),
    );
    let mut buf = vec![0u8; 64 * 1024];
    let mut ended: Option<LabError> = None;
    loop {
        if stop.load(Ordering::SeqCst) {
            break;
        }
        if a.duration_s
            .is_some_and(|d| start.elapsed().as_secs_f64() >= d)
        {
            break;
        }
        match source.read(&mut buf) {
            Ok(None) => break,
            Ok(Some(n)) => {
                if let Err(e) = rec.push(&buf[..n]) {
                    ended = Some(record_error(e, &source_path));
                    break;
                }
            }
            Err(e) => {
                ended = Some(LabError::input(
                    &source_path,
                    format!("the port went away: {e}"),
                ));
                break;
            }
        }
        progress.show(&rec, start.elapsed());
    }
    progress.clear();
    let angles = rec.angles();
    let summary = rec.finish().map_err(|e| record_error(e, &source_path))?;
    if ended.is_none() && summary.frames == 0 {
        ended = Some(LabError::input(
            &source_path,
            format!("no frame found in {} bytes", summary.bytes),
        ));
    }
    let json = summary_json(
        &summary,
        &source_path.display().to_string(),
        start.elapsed(),
        angles,
        a.rlg_counts_per_deg,
        ended.as_ref().map(|e| e.to_string()),
    );
    let path = a.out.out.join("record.json");
    let text = serde_json::to_string_pretty(&json).map_err(|e| LabError::io(&path, e))?;
    gyro_lab_core::data::atomic::write(&path, text + "\n")?;
    if a.json.json {
        print_json(&json)?;
    } else {
        print_summary(&json, &a.out.out);
    }
    match ended {
        Some(e) => Err(e),
        None => Ok(()),
    }
}

fn print_summary(j: &RecordJson, dir: &Path) {
    println!(
        "{} frames ({} bytes) from {}, board time {:.3} .. {:.3} s; {} CRC errors, {} resyncs, {} frames lost in {} gaps, {} closures missed on the board",
        j.frames,
        j.bytes,
        j.source,
        j.first_s,
        j.last_s,
        j.crc_errors,
        j.resyncs,
        j.lost_frame_count,
        j.lost_frames.len(),
        j.closures_missed
    );
    for l in &j.lost_frames {
        println!(
            "  lost {} frames between sequence {} and {} (board time {:.3} .. {:.3} s)",
            l.frames, l.after_seq, l.before_seq, l.from_s, l.to_s
        );
    }
    for (name, f) in &j.faults {
        println!(
            "  {name}: {} frames, {:.3} .. {:.3} s",
            f.frames, f.first_s, f.last_s
        );
    }
    println!(
        "angle over the record: FOG {:.6} deg, RLG {} counts ({:.6} deg)",
        j.fog_angle_deg, j.rlg_counts, j.rlg_angle_deg
    );
    println!(
        "files: {0}/raw.bin {0}/fog.csv {0}/rlg.csv {0}/record.json",
        dir.display()
    );
}

/// The progress line on stderr while a record runs: redrawn in place on a
/// terminal, a plain line now and then anywhere else.
struct Progress {
    shown: bool,
    terminal: bool,
    last: Option<Instant>,
    frames_then: (u64, Duration),
}

impl Progress {
    fn new(shown: bool, terminal: bool) -> Self {
        Self {
            shown,
            terminal,
            last: None,
            frames_then: (0, Duration::ZERO),
        }
    }

    fn show(&mut self, rec: &Recorder, elapsed: Duration) {
        let every = if self.terminal {
            PROGRESS_EVERY
        } else {
            PROGRESS_LOG_EVERY
        };
        if !self.shown || self.last.is_some_and(|t| t.elapsed() < every) {
            return;
        }
        self.last = Some(Instant::now());
        let s = rec.summary();
        let dt = (elapsed - self.frames_then.1).as_secs_f64().max(1e-9);
        let fps = (s.frames - self.frames_then.0) as f64 / dt;
        self.frames_then = (s.frames, elapsed);
        let latest = rec.latest().map_or(String::from("no frame yet"), |l| {
            format!(
                "FOG {:+.4} deg/s, RLG {:+.4} deg/s, coil {:.2} monoblocks {:.2}/{:.2} case {:.2} degC",
                l.fog_rate_dps, l.rlg_rate_dps, l.coil_c, l.mono_c[0], l.mono_c[1], l.case_c
            )
        });
        let flags: Vec<&str> = s.flags.iter().map(|f| f.name.as_str()).collect();
        let line = format!(
            "{:.1} s  {:.0} frames/s  {latest}  CRC errors {}  gaps {}  flags up [{}]",
            elapsed.as_secs_f64(),
            fps,
            s.crc_errors,
            s.lost.len(),
            flags.join(" ")
        );
        if self.terminal {
            eprint!("\r\x1b[2K{line}");
        } else {
            eprintln!("{line}");
        }
    }

    fn clear(&self) {
        if self.shown && self.terminal && self.last.is_some() {
            eprintln!();
        }
    }
}
