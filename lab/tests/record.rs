//! `gyro-lab record` on captures of the board's byte stream: what a clean
//! and a damaged capture give, the reference merge, and bad input. (The
//! record from a live pseudo-terminal, and through a relay that damages the
//! stream, run under QEMU in `cargo xtask test`.)

mod common;

use common::{dir, json, lab};
use gyro_lab_core::sim::board_stream::BoardStream;

const FRAME: usize = 86;

fn stream(frames: usize) -> gyro_lab_core::sim::board_stream::Stream {
    BoardStream {
        frames,
        rate_dps: 10.0,
        noise_dps: 0.1,
        seed: 3,
    }
    .generate()
}

fn run_record(
    name: &str,
    bytes: &[u8],
    extra: &[&str],
) -> (i32, serde_json::Value, String, std::path::PathBuf) {
    let d = dir(name);
    let capture = d.join("capture.bin");
    std::fs::write(&capture, bytes).unwrap();
    let out = d.join("rec");
    let mut args = vec![
        "record",
        "--json",
        "--from",
        capture.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ];
    args.extend_from_slice(extra);
    let (code, stdout, stderr) = lab(&args);
    let j = if stdout.trim().is_empty() {
        serde_json::Value::Null
    } else {
        json(&stdout)
    };
    (code, j, stderr, out)
}

/// The data rows of one column of a record's run file.
fn column(path: &std::path::Path, name: &str) -> Vec<f64> {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines().filter(|l| !l.starts_with('#'));
    let head: Vec<&str> = lines.next().unwrap().split(',').collect();
    let k = head.iter().position(|h| *h == name).unwrap();
    lines
        .map(|l| l.split(',').nth(k).unwrap().parse().unwrap())
        .collect()
}

/// A clean capture: every frame, the angles as sent (FOG to the float's
/// precision, RLG exact), the time base 2 ms a row, the constant reference
/// in every row, and the raw bytes kept as they came.
#[test]
fn clean_capture_round_trips() {
    let s = stream(2_000);
    let (code, j, err, out) = run_record("clean", &s.bytes, &["--ref-rate-dps", "0.004178"]);
    assert_eq!(code, 0, "{err}");
    assert_eq!(j["frames"], 2_000);
    assert_eq!(j["lost_frame_count"], 0);
    assert_eq!(j["crc_errors"], 0);
    let fog = j["fog_angle_deg"].as_f64().unwrap();
    assert!(
        (fog - s.fog_angle_deg).abs() < 1e-9,
        "{fog} vs {}",
        s.fog_angle_deg
    );
    assert_eq!(j["rlg_counts"].as_i64().unwrap(), s.rlg_counts);
    assert_eq!(std::fs::read(out.join("raw.bin")).unwrap(), s.bytes);
    let t = column(&out.join("fog.csv"), "t_s");
    assert_eq!(t.len(), 2_000);
    assert!(t.windows(2).all(|w| (w[1] - w[0] - 0.002).abs() < 1e-9));
    assert!(column(&out.join("fog.csv"), "ref_rate_dps")
        .iter()
        .all(|&r| r == 0.004178));
    // The angle column ends at the record's angle.
    let angle = column(&out.join("fog.csv"), "angle_deg");
    assert!((angle.last().unwrap() - fog).abs() < 1e-6);
    let written: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("record.json")).unwrap()).unwrap();
    assert_eq!(written["frames"], 2_000);
}

/// Without --json, on a stderr that is not a terminal (here a pipe): the
/// progress as plain lines, never a terminal's escape codes; the summary
/// on stdout.
#[test]
fn progress_on_a_pipe_has_no_escape_codes() {
    let s = stream(500);
    let d = dir("pipe");
    let capture = d.join("capture.bin");
    std::fs::write(&capture, &s.bytes).unwrap();
    let (code, stdout, stderr) = lab(&[
        "record",
        "--from",
        capture.to_str().unwrap(),
        "--out",
        d.join("rec").to_str().unwrap(),
    ]);
    assert_eq!(code, 0, "{stderr}");
    assert!(
        !stderr.contains('\x1b') && !stderr.contains('\r'),
        "{stderr:?}"
    );
    assert!(stdout.contains("500 frames"), "{stdout}");
}

/// Damage of every kind: exactly the destroyed frames reported lost, the
/// rows after the gaps spanning them, the angle at the end the clean one's.
#[test]
fn damaged_capture_loses_no_angle() {
    let s = stream(1_000);
    let mut bytes = Vec::new();
    let mut destroyed = 0;
    for (k, f) in s.bytes.chunks(FRAME).enumerate() {
        let mut f = f.to_vec();
        match k {
            100 => {
                f[50] ^= 0x80;
                destroyed += 1;
            }
            200 => {
                f.truncate(60);
                destroyed += 1;
            }
            300 => bytes.extend_from_slice(&[0xA5, 0x5A, 4, 82, 0, 0, 0xA5]),
            400..=409 => {
                destroyed += 1;
                continue;
            }
            _ => {}
        }
        bytes.extend_from_slice(&f);
    }
    let (code, j, err, out) = run_record("damaged", &bytes, &[]);
    assert_eq!(code, 0, "{err}");
    assert_eq!(j["lost_frame_count"], destroyed);
    assert_eq!(j["frames"], 1_000 - destroyed);
    assert_eq!(j["rlg_counts"].as_i64().unwrap(), s.rlg_counts);
    let fog = j["fog_angle_deg"].as_f64().unwrap();
    assert!((fog - s.fog_angle_deg).abs() < 1e-9);
    let lost = j["lost_frames"].as_array().unwrap();
    assert_eq!(lost.len(), 3);
    assert_eq!(lost[2]["frames"], 10);
    assert_eq!(lost[2]["after_seq"], 399);
    assert_eq!(lost[2]["before_seq"], 410);
    // The row after the ten lost frames takes its rate over the whole
    // gap: still the true 10 deg/s, within the noise averaged over 22 ms.
    let t = column(&out.join("fog.csv"), "t_s");
    let rate = column(&out.join("fog.csv"), "rate_dps");
    let k = t.windows(2).position(|w| w[1] - w[0] > 0.02).unwrap() + 1;
    assert!((t[k] - t[k - 1] - 0.022).abs() < 1e-9);
    assert!((rate[k] - 10.0).abs() < 0.05, "{}", rate[k]);
}

/// A rate-table log merged by time with an offset: each row holds the
/// table's mean rate over the row's span.
#[test]
fn reference_log_is_merged_by_time() {
    let s = stream(500);
    let d = dir("reference");
    let log = d.join("table.csv");
    // Table time = board time - 0.5 s: a ramp of 10 deg/s per second.
    let mut text = String::from("# rate table\nt_s,ref_rate_dps\n");
    for k in 0..=200 {
        let t = k as f64 * 0.01;
        text.push_str(&format!("{t},{}\n", 10.0 * t));
    }
    std::fs::write(&log, text).unwrap();
    let (code, _, err, out) = run_record(
        "reference-run",
        &s.bytes,
        &[
            "--reference",
            log.to_str().unwrap(),
            "--reference-offset-s",
            "0.5",
        ],
    );
    assert_eq!(code, 0, "{err}");
    let t = column(&out.join("fog.csv"), "t_s");
    let r = column(&out.join("fog.csv"), "ref_rate_dps");
    for (t, r) in t.iter().zip(&r).skip(1) {
        // Mean over (t - 2 ms, t] in table time t - 0.5, held at 0 before
        // the table starts and at 20 deg/s after it ends.
        let mid = (t - 0.001 - 0.5).clamp(0.0, 2.0);
        if (0.002..1.998).contains(&(t - 0.5)) {
            assert!(
                (r - 10.0 * mid).abs() < 1e-9,
                "t {t}: {r} vs {}",
                10.0 * mid
            );
        }
    }
}

/// Bad input: one line naming the file, exit 2, and what was recorded kept.
#[test]
fn bad_input_is_refused_and_the_record_kept() {
    // A port that does not exist.
    let d = dir("bad-port");
    let (code, _, err) = lab(&[
        "record",
        "--port",
        "/dev/no-such-port",
        "--out",
        d.join("rec").to_str().unwrap(),
    ]);
    assert_eq!(code, 2);
    assert_eq!(err.trim().lines().count(), 1, "{err}");
    assert!(err.contains("/dev/no-such-port"), "{err}");

    // A capture with no frame in it.
    let noise: Vec<u8> = (0..5_000u32)
        .map(|k| (k.wrapping_mul(2_654_435_761) >> 13) as u8)
        .collect();
    let (code, j, err, out) = run_record("no-frame", &noise, &[]);
    assert_eq!(code, 2);
    assert!(err.contains("no frame found"), "{err}");
    assert_eq!(err.trim().lines().count(), 1, "{err}");
    assert_eq!(j["frames"], 0);
    assert_eq!(std::fs::read(out.join("raw.bin")).unwrap(), noise);

    // A frame of another version after good ones: the good ones kept, the
    // error names the byte.
    let s = stream(10);
    let mut bytes = s.bytes.clone();
    let k = 6 * FRAME;
    bytes[k + 2] = 3;
    let crc = gyro_sp::frame::crc16(&bytes[k + 2..k + FRAME - 2]);
    bytes[k + FRAME - 2..k + FRAME].copy_from_slice(&crc.to_le_bytes());
    let (code, j, err, out) = run_record("version", &bytes, &[]);
    assert_eq!(code, 2);
    assert!(
        err.contains(&format!("byte {k}")) && err.contains("version 3"),
        "{err}"
    );
    assert_eq!(j["frames"], 6);
    assert_eq!(column(&out.join("fog.csv"), "t_s").len(), 6);

    // Both a constant reference and a log: refused by the argument parser.
    let (code, _, err) = lab(&[
        "record",
        "--from",
        "x.bin",
        "--out",
        "y",
        "--ref-rate-dps",
        "1",
        "--reference",
        "t.csv",
    ]);
    assert_eq!(code, 2, "{err}");
}
