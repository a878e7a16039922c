//! `gyro-lab bench record`: can the recorder keep up with a board? A
//! ten-minute capture at the board's 500 frames/s (sim/board_stream.rs) is
//! written to a file and decoded through the recorder in 4 kB reads, as a
//! serial port delivers it; the CPU time it takes against the ten minutes
//! the board took to send it.

use crate::cli::args::Json;
use crate::cli::output::print_json;
use clap::Args;
use gyro_frames::{Recorder, Reference, Scales};
use gyro_lab_core::error::LabError;
use gyro_lab_core::sim::board_stream::{BoardStream, RLG_COUNTS_PER_DEG};

#[derive(Args, Debug, Clone)]
pub struct RecordBenchArgs {
    /// Minutes of capture at 500 frames/s.
    #[arg(long, default_value_t = 10.0)]
    pub minutes: f64,
    #[command(flatten)]
    pub json: Json,
}

/// CPU seconds (user + system) of this process so far.
fn cpu_s() -> f64 {
    // SAFETY: getrusage fills the struct it is given.
    let mut u: libc::rusage = unsafe { std::mem::zeroed() };
    unsafe { libc::getrusage(libc::RUSAGE_SELF, &mut u) };
    let tv = |t: libc::timeval| t.tv_sec as f64 + t.tv_usec as f64 * 1e-6;
    tv(u.ru_utime) + tv(u.ru_stime)
}

pub fn run(a: &RecordBenchArgs) -> Result<(), LabError> {
    if !(a.minutes.is_finite() && a.minutes > 0.0 && a.minutes <= 600.0) {
        return Err(LabError::Usage(format!(
            "--minutes {}: 0 < minutes <= 600",
            a.minutes
        )));
    }
    let board_s = a.minutes * 60.0;
    let frames = (board_s * 500.0).round() as usize;
    let stream = BoardStream {
        frames,
        rate_dps: 15.0,
        noise_dps: 0.05,
        seed: 7,
    }
    .generate();
    let dir = std::env::temp_dir().join(format!("gyro-lab-bench-record-{}", std::process::id()));
    let capture = dir.join("capture.bin");
    std::fs::create_dir_all(&dir).map_err(|e| LabError::io(&dir, e))?;
    std::fs::write(&capture, &stream.bytes).map_err(|e| LabError::io(&capture, e))?;
    let scales = Scales {
        rlg_counts_per_deg: RLG_COUNTS_PER_DEG,
        ..Scales::board()
    };
    let (cpu0, wall0) = (cpu_s(), std::time::Instant::now());
    let mut rec = Recorder::create(
        &dir.join("record"),
        scales,
        Reference::Constant(15.0),
        "bench",
    )
    .map_err(|e| LabError::Bench(e.to_string()))?;
    let bytes = std::fs::read(&capture).map_err(|e| LabError::io(&capture, e))?;
    for chunk in bytes.chunks(4096) {
        rec.push(chunk)
            .map_err(|e| LabError::Bench(e.to_string()))?;
    }
    let angles = rec.angles();
    let summary = rec.finish().map_err(|e| LabError::Bench(e.to_string()))?;
    let (cpu, wall) = (cpu_s() - cpu0, wall0.elapsed().as_secs_f64());
    let _ = std::fs::remove_dir_all(&dir);
    let angle_err = angles.0 - stream.fog_angle_deg;
    if summary.frames as usize != frames || angles.1 != stream.rlg_counts || angle_err.abs() > 1e-6
    {
        return Err(LabError::Bench(format!(
            "decoded {} of {frames} frames, RLG {} of {} counts, FOG angle off by {angle_err:e} deg",
            summary.frames, angles.1, stream.rlg_counts
        )));
    }
    let j = serde_json::json!({
        "record_board_s": board_s,
        "record_frames": frames,
        "record_cpu_s": cpu,
        "record_wall_s": wall,
        "record_core_share": cpu / board_s,
        "record_frames_per_cpu_s": frames as f64 / cpu.max(1e-9),
    });
    if !a.json.json {
        println!(
            "{frames} frames ({board_s:.0} s of board time, {:.1} MB): decoded and written in {cpu:.2} s of CPU \
             ({wall:.2} s wall): {:.2} % of one core at the board's rate; angle and counts exact",
            stream.bytes.len() as f64 / 1e6,
            100.0 * cpu / board_s
        );
    }
    print_json(&j)
}
