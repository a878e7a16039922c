//! The board's frames (docs/frame.md) decoded from a capture's bytes into
//! the FOG and RLG run files' columns, through gyro-frames (the decoder
//! and the rows `gyro-lab record` writes), and what the record held (the
//! summary `record.json` holds).

use crate::error::LabError;
use gyro_frames::rows::{RunWriter, FOG_COLUMNS, RLG_COLUMNS};
use gyro_frames::{Decoder, Scales, Summary};

/// `record.json` and the `--json` line.
#[derive(serde::Serialize)]
pub struct RecordJson {
    pub source: String,
    /// Host seconds the record took.
    pub elapsed_s: f64,
    /// Board time of the first and last frame, s.
    pub first_s: f64,
    pub last_s: f64,
    pub frames: u64,
    pub bytes: u64,
    pub crc_errors: u64,
    pub resyncs: u64,
    pub skipped_bytes: u64,
    pub duplicates: u64,
    /// Frames lost on the way, with the sequence numbers either side.
    pub lost_frames: Vec<LostJson>,
    pub lost_frame_count: u64,
    /// Closures the board reported missed (their angle is lost).
    pub closures_missed: u64,
    /// Each fault flag seen: frames with it, first and last board time.
    pub faults: std::collections::BTreeMap<String, FlagJson>,
    /// Starts of the board the record saw: board time and cause.
    pub starts: Vec<(f64, String)>,
    /// The angle over the record: FOG (deg, eps^2-corrected, nominal scale
    /// factor) and RLG (counts, deg).
    pub fog_angle_deg: f64,
    pub rlg_counts: i64,
    pub rlg_angle_deg: f64,
    /// Why the record ended early, if it did.
    pub error: Option<String>,
}

#[derive(serde::Serialize)]
pub struct LostJson {
    pub after_seq: u16,
    pub before_seq: u16,
    pub frames: u32,
    pub from_s: f64,
    pub to_s: f64,
}

#[derive(serde::Serialize)]
pub struct FlagJson {
    pub frames: u64,
    pub first_s: f64,
    pub last_s: f64,
}

pub fn summary_json(
    s: &Summary,
    source: &str,
    elapsed: std::time::Duration,
    angles: (f64, i64),
    counts_per_deg: f64,
    error: Option<String>,
) -> RecordJson {
    RecordJson {
        source: source.to_string(),
        elapsed_s: elapsed.as_secs_f64(),
        first_s: s.first_s,
        last_s: s.last_s,
        frames: s.frames,
        bytes: s.bytes,
        crc_errors: s.crc_errors,
        resyncs: s.resyncs,
        skipped_bytes: s.skipped_bytes,
        duplicates: s.duplicates,
        lost_frames: s
            .lost
            .iter()
            .map(|l| LostJson {
                after_seq: l.after_seq,
                before_seq: l.before_seq,
                frames: l.frames,
                from_s: l.from_s,
                to_s: l.to_s,
            })
            .collect(),
        lost_frame_count: s.lost_frames,
        closures_missed: s.closures_missed,
        faults: s
            .flags
            .iter()
            .map(|f| {
                (
                    f.name.clone(),
                    FlagJson {
                        frames: f.frames,
                        first_s: f.first_s,
                        last_s: f.last_s,
                    },
                )
            })
            .collect(),
        starts: s
            .starts
            .iter()
            .map(|(t, c)| (*t, format!("{c:?}")))
            .collect(),
        fog_angle_deg: angles.0,
        rlg_counts: angles.1,
        rlg_angle_deg: angles.1 as f64 / counts_per_deg,
        error,
    }
}

/// The capture decoded: each channel's columns by name, and the summary.
pub struct DecodedFrames {
    pub fog: Vec<(String, Vec<f64>)>,
    pub rlg: Vec<(String, Vec<f64>)>,
    pub summary: RecordJson,
}

/// Decodes a capture's bytes (`raw.bin`, or what a port gave) as `gyro-lab
/// record --from` does, the reference rate 0 (a board at rest):
/// `rlg_counts_per_deg` the RLG's scale factor (the board's default
/// without it).
pub fn decode_frames(
    bytes: &[u8],
    name: &str,
    rlg_counts_per_deg: Option<f64>,
) -> Result<DecodedFrames, LabError> {
    let t0 = std::time::Instant::now();
    let board = Scales::board();
    let scales = Scales {
        rlg_counts_per_deg: rlg_counts_per_deg.unwrap_or(board.rlg_counts_per_deg),
        ..board
    };
    if !(scales.rlg_counts_per_deg.is_finite() && scales.rlg_counts_per_deg > 0.0) {
        return Err(LabError::Usage(format!(
            "RLG counts per degree {}: must be positive",
            scales.rlg_counts_per_deg
        )));
    }
    let mut decoder = Decoder::new();
    let mut decoded = vec![];
    let stream = decoder.push(bytes, &mut decoded);
    let mut summary = Summary::default();
    let comment = format!("gyro-lab decode_frames of {name}");
    let mut rows = RunWriter::new(Vec::new(), Vec::new(), scales, &comment)
        .map_err(|e| LabError::input(name, e.to_string()))?;
    for d in &decoded {
        summary.add(d, &scales);
        rows.row(d, 0.0)
            .map_err(|e| LabError::input(name, e.to_string()))?;
    }
    summary.finish(&decoder);
    let angles = (rows.fog_angle_deg(), rows.rlg_counts());
    let (fog, rlg) = rows
        .into_inner()
        .map_err(|e| LabError::input(name, e.to_string()))?;
    let error = stream.err().map(|e| e.to_string());
    if summary.frames == 0 {
        return Err(LabError::input(
            name,
            format!(
                "no frame found in {} bytes{}",
                summary.bytes,
                error.as_ref().map_or(String::new(), |e| format!(" ({e})"))
            ),
        ));
    }
    Ok(DecodedFrames {
        fog: columns(&fog, FOG_COLUMNS),
        rlg: columns(&rlg, RLG_COLUMNS),
        summary: summary_json(
            &summary,
            name,
            t0.elapsed(),
            angles,
            scales.rlg_counts_per_deg,
            error,
        ),
    })
}

/// The rows the writer made, back into columns: every cell is a number
/// it wrote.
fn columns(text: &[u8], header: &str) -> Vec<(String, Vec<f64>)> {
    let names: Vec<&str> = header.split(',').collect();
    let mut cols: Vec<Vec<f64>> = vec![vec![]; names.len()];
    let text = String::from_utf8_lossy(text);
    for line in text.lines().filter(|l| !l.starts_with('#') && *l != header) {
        for (k, cell) in line.split(',').enumerate().take(names.len()) {
            cols[k].push(cell.parse().unwrap_or(f64::NAN));
        }
    }
    names.into_iter().map(str::to_owned).zip(cols).collect()
}
