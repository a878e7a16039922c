//! `gyro-lab record` as it will be used: the firmware under QEMU, its USART
//! bytes on a pseudo-terminal read by the recorder as a USB-serial adapter
//! would be; then the same through a relay that damages the stream, with
//! the damage known; then the lab's analyses on what was recorded.
//!
//! The harness owns the pseudo-terminal. QEMU's USART goes to a Unix
//! socket (`-serial unix:...,server=on,wait=on`: the guest starts only once
//! the harness is connected, after the recorder holds its terminal, seen in
//! /proc); a bridge thread copies the socket to the terminal, damaging the
//! stream by plan in the relay test, and closes the terminal only once the
//! recorder has every byte it was given. QEMU's own pty backend drops what
//! it writes while nobody holds the other side, and the kernel discards
//! what a reader has not yet read when QEMU exits and closes it: a slow
//! reader on a loaded host lost the stream's last frames that way. A socket
//! loses nothing, and a full one blocks the guest (its clock stands still,
//! `-icount ... sleep=off`), as a full adapter would.

use crate::capture::{self, FRAME};
use crate::{qemu_command, root, wait_progressing, QEMU_STALL};
use anyhow::{bail, Context, Result};
use std::collections::BTreeSet;
use std::io::{Read, Write};
use std::os::fd::{AsRawFd, FromRawFd, OwnedFd};
use std::os::unix::net::UnixStream;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

/// How long a reader may take to open its pty, QEMU to make its socket, or
/// the recorder to take the bytes it was given (a loaded host is slow; the
/// guest waits meanwhile).
const READER_WAIT: Duration = Duration::from_secs(60);

/// A QEMU run waiting for its serial socket's client.
struct SocketQemu {
    child: Child,
    socket: PathBuf,
    log: PathBuf,
}

fn start_qemu_on_socket(elf: &Path, dir: &Path) -> Result<SocketQemu> {
    std::fs::create_dir_all(dir)?;
    let socket = dir.join("serial.sock");
    let _ = std::fs::remove_file(&socket);
    let log = dir.join("defmt.bin");
    let child = qemu_command(elf, &format!("unix:{},server=on,wait=on", socket.display()))
        .stdout(std::fs::File::create(&log)?)
        .stderr(Stdio::null())
        .spawn()
        .context("starting qemu-system-arm")?;
    Ok(SocketQemu { child, socket, log })
}

/// Connects to QEMU's serial socket (QEMU makes it at start; the guest
/// runs from the connection on).
fn connect(socket: &Path) -> Result<UnixStream> {
    let start = Instant::now();
    loop {
        match UnixStream::connect(socket) {
            Ok(s) => return Ok(s),
            Err(e) if start.elapsed() > READER_WAIT => {
                bail!("QEMU's serial socket {}: {e}", socket.display())
            }
            Err(_) => std::thread::sleep(Duration::from_millis(20)),
        }
    }
}

/// Waits until process `pid` holds `path` open (a reader on a pty), for at
/// most `limit`. A fixed sleep is not enough: on a loaded host the reader
/// can start later than any guess.
fn wait_open(pid: u32, path: &Path, limit: Duration) -> Result<()> {
    let start = Instant::now();
    let dir = PathBuf::from(format!("/proc/{pid}/fd"));
    loop {
        let holds = std::fs::read_dir(&dir)
            .into_iter()
            .flatten()
            .filter_map(|e| std::fs::read_link(e.ok()?.path()).ok())
            .any(|l| l == path);
        if holds {
            return Ok(());
        }
        if start.elapsed() > limit {
            bail!(
                "process {pid} did not open {} within {} s",
                path.display(),
                limit.as_secs()
            );
        }
        std::thread::sleep(Duration::from_millis(20));
    }
}

/// Runs `gyro-lab record --port <pts>` into `out`; returns the child.
fn start_recorder(lab: &Path, pts: &Path, out: &Path, reference: &Path) -> Result<Child> {
    let _ = std::fs::remove_dir_all(out);
    Command::new(lab)
        .args(["record", "--json", "--port"])
        .arg(pts)
        .arg("--out")
        .arg(out)
        .arg("--reference")
        .arg(reference)
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .context("starting gyro-lab record")
}

/// Waits for the recorder (it ends when the port goes away) and returns
/// its exit status, its JSON line and stderr.
fn finish_recorder(mut child: Child) -> Result<(i32, serde_json::Value, String)> {
    let start = Instant::now();
    loop {
        if child.try_wait()?.is_some() {
            break;
        }
        if start.elapsed() > Duration::from_secs(30) {
            let _ = child.kill();
            bail!("gyro-lab record did not end 30 s after QEMU did");
        }
        std::thread::sleep(Duration::from_millis(100));
    }
    let out = child.wait_with_output()?;
    let stdout = String::from_utf8_lossy(&out.stdout);
    let json = serde_json::from_str(stdout.lines().last().unwrap_or("{}"))
        .context("gyro-lab record's JSON line")?;
    Ok((
        out.status.code().unwrap_or(-1),
        json,
        String::from_utf8_lossy(&out.stderr).into_owned(),
    ))
}

/// A pty pair in raw mode: (master, slave path).
fn open_pty() -> Result<(OwnedFd, PathBuf)> {
    let (mut master, mut slave) = (0, 0);
    let mut name = [0 as libc::c_char; 128];
    // SAFETY: openpty writes two fds and the slave's name into the buffers.
    let r = unsafe {
        libc::openpty(
            &mut master,
            &mut slave,
            name.as_mut_ptr(),
            std::ptr::null(),
            std::ptr::null(),
        )
    };
    if r != 0 {
        bail!("openpty: {}", std::io::Error::last_os_error());
    }
    // Not inherited by the processes started later (the recorder): a
    // master fd left open in the recorder would hide the hang-up it must see.
    for fd in [master, slave] {
        // SAFETY: fcntl on fds just opened.
        unsafe { libc::fcntl(fd, libc::F_SETFD, libc::FD_CLOEXEC) };
    }
    // SAFETY: fresh fds from openpty, owned here.
    let (master, slave) = unsafe { (OwnedFd::from_raw_fd(master), OwnedFd::from_raw_fd(slave)) };
    raw_mode(slave.as_raw_fd())?;
    // SAFETY: openpty wrote a NUL-terminated name.
    let path = unsafe { std::ffi::CStr::from_ptr(name.as_ptr()) }
        .to_string_lossy()
        .into_owned();
    // The slave stays open until the relay ends, so the master never sees
    // a hang-up while the recorder reopens it.
    std::mem::forget(slave);
    Ok((master, PathBuf::from(path)))
}

fn raw_mode(fd: i32) -> Result<()> {
    // SAFETY: termios calls on an open terminal fd.
    unsafe {
        let mut t: libc::termios = std::mem::zeroed();
        if libc::tcgetattr(fd, &mut t) != 0 {
            bail!("tcgetattr: {}", std::io::Error::last_os_error());
        }
        libc::cfmakeraw(&mut t);
        if libc::tcsetattr(fd, libc::TCSANOW, &t) != 0 {
            bail!("tcsetattr: {}", std::io::Error::last_os_error());
        }
    }
    Ok(())
}

/// What the relay did to the stream: the frames it destroyed.
#[derive(Default)]
struct Damage {
    frames_destroyed: Vec<usize>,
    bit_flips: usize,
    dropped_bytes: usize,
    inserted_bytes: usize,
    dropped_frames: usize,
    stall_s: f64,
}

/// The relay's plan, by frame index of the clean stream.
fn damage_frame(k: usize, frame: &mut Vec<u8>, out: &mut Vec<u8>, d: &mut Damage) -> bool {
    match k {
        // Flipped bits: the frame fails its CRC.
        150 | 640 => {
            frame[30] ^= 0x04;
            d.bit_flips += 1;
            d.frames_destroyed.push(k);
        }
        // A dropped byte.
        300 => {
            frame.remove(40);
            d.dropped_bytes += 1;
            d.frames_destroyed.push(k);
        }
        // Inserted bytes between frames, with sync patterns among them.
        450 => {
            let junk = [0xA5, 0x5A, 0x04, 0x52, 0x00, 0xA5, 0x5A, 0x13, 0x37];
            out.extend_from_slice(&junk);
            d.inserted_bytes += junk.len();
        }
        // Three whole frames gone.
        800..=802 => {
            d.dropped_frames += 1;
            d.frames_destroyed.push(k);
            return false;
        }
        // A burst of garbage (a noisy cable) inside a frame.
        1000 => {
            let mut x = 0x2545_F491u32;
            let burst: Vec<u8> = (0..300)
                .map(|_| {
                    x ^= x << 13;
                    x ^= x >> 17;
                    x ^= x << 5;
                    x as u8
                })
                .collect();
            frame.splice(20..20, burst.iter().copied());
            d.inserted_bytes += burst.len();
            d.frames_destroyed.push(k);
        }
        _ => {}
    }
    true
}

/// Copies QEMU's serial socket to `master`, damaging it by plan when
/// `damage` (with a stall of a few seconds in the middle); what it read
/// goes to `seen` too. At the socket's end (QEMU exited) it waits until the
/// recorder's capture `taken` holds every byte written, then returns,
/// closing the terminal: the recorder then sees the port go away.
fn relay(
    mut input: UnixStream,
    master: OwnedFd,
    seen: PathBuf,
    damage: bool,
    taken: PathBuf,
) -> Result<Damage> {
    let mut output = std::fs::File::from(master);
    let mut seen = std::fs::File::create(&seen)?;
    let mut d = Damage::default();
    let (mut pending, mut k, mut written) = (Vec::new(), 0usize, 0u64);
    let mut buf = [0u8; 4096];
    loop {
        let n = match input.read(&mut buf) {
            Ok(0) => break,
            Ok(n) => n,
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => continue,
            Err(_) => break,
        };
        seen.write_all(&buf[..n])?;
        if !damage {
            output.write_all(&buf[..n])?;
            written += n as u64;
            continue;
        }
        pending.extend_from_slice(&buf[..n]);
        let mut out = Vec::new();
        while pending.len() >= FRAME {
            let mut frame: Vec<u8> = pending.drain(..FRAME).collect();
            if damage_frame(k, &mut frame, &mut out, &mut d) {
                out.extend_from_slice(&frame);
            }
            if k == 600 {
                // A stall: the cable hangs for three seconds.
                output.write_all(&out)?;
                written += out.len() as u64;
                out.clear();
                std::thread::sleep(Duration::from_secs(3));
                d.stall_s = 3.0;
            }
            k += 1;
        }
        output.write_all(&out)?;
        written += out.len() as u64;
    }
    output.write_all(&pending)?;
    written += pending.len() as u64;
    let start = Instant::now();
    while std::fs::metadata(&taken).map_or(0, |m| m.len()) < written {
        if start.elapsed() > READER_WAIT {
            bail!(
                "the recorder took {} of the {written} bytes given in {} s",
                std::fs::metadata(&taken).map_or(0, |m| m.len()),
                READER_WAIT.as_secs()
            );
        }
        std::thread::sleep(Duration::from_millis(20));
    }
    Ok(d)
}

/// One record through the bridge: QEMU on its socket, the harness's pty,
/// the recorder on it (holding it before the guest starts), the relay
/// between them. Returns what the relay did and the recorder's exit
/// status, JSON line and stderr.
fn record_through(
    elf: &Path,
    lab: &Path,
    dir: &Path,
    reference: &Path,
    damage: bool,
) -> Result<(Damage, i32, serde_json::Value, String)> {
    let q = start_qemu_on_socket(elf, dir)?;
    let (master, pts) = open_pty()?;
    let out = dir.join("record");
    let rec = start_recorder(lab, &pts, &out, reference)?;
    wait_open(rec.id(), &pts, READER_WAIT)?;
    let input = connect(&q.socket)?;
    let (seen, taken) = (dir.join("relay-in.bin"), out.join("raw.bin"));
    let relay = std::thread::spawn(move || relay(input, master, seen, damage, taken));
    let mut child = q.child;
    wait_progressing(&mut child, &[&out.join("raw.bin"), &q.log], QEMU_STALL)?;
    let d = relay
        .join()
        .map_err(|_| anyhow::anyhow!("the relay panicked"))??;
    let (code, json, stderr) = finish_recorder(rec)?;
    if !out.join("fog.csv").exists() {
        bail!("gyro-lab record wrote nothing (exit {code}): {stderr}");
    }
    Ok((d, code, json, stderr))
}

/// Frames of the clean stream that `path` (bytes a harness stage passed
/// on) lacks, by index: the harness's own losses.
fn harness_lost(clean_bin: &Path, path: &Path) -> Result<Vec<usize>> {
    let clean = std::fs::read(clean_bin)?;
    let frames = capture::frames(&clean)?;
    let ok = capture::intact(&frames, &std::fs::read(path)?);
    Ok((0..ok.len()).filter(|&k| !ok[k]).collect())
}

/// The pty test and the fault-injection test: (name, passed, detail).
///
/// Each record is judged against the bytes it received (`raw.bin`), found
/// frame by frame in the clean capture (`capture.rs`): the recorder must
/// report exactly the frames that did not arrive whole, and write every
/// row the clean capture's rows are. So a pty that drops bytes under load
/// (the harness's fault) is told apart from a recorder that miscounts: the
/// first is named in the detail, the second fails. The frames themselves
/// must be the file path's, word for word: the emulator run is a function
/// of its inputs, whatever the host's load or the reader's speed.
pub fn run(
    elf: &Path,
    clean: &Path,
    clean_bin: &Path,
    reference: &Path,
) -> Result<Vec<(&'static str, bool, String)>> {
    let lab = root().join("target/release/gyro-lab");
    let mut checks = vec![];

    // 1. QEMU's USART on a pty, read by `gyro-lab record --port`.
    let dir = root().join("runs/pty");
    let out = dir.join("record");
    let (_, code, json, stderr) = record_through(elf, &lab, &dir, reference, false)?;
    let v = capture::judge(clean_bin, clean, &out, &json)?;
    let identical = std::fs::read(out.join("raw.bin"))? == std::fs::read(clean_bin)?;
    let went_away = code == 2 && stderr.contains("the port went away");
    checks.push((
        "record_from_pty_equals_the_file_path",
        v.exact && went_away,
        format!(
            "{} frames, {}; {}; exit {code} ({})",
            json["frames"],
            if identical {
                "bytes identical to the file path's".to_string()
            } else {
                format!(
                    "the harness delivered {} frames short (its loss, reported exactly: {})",
                    v.not_received.len(),
                    v.exact
                )
            },
            v.first_difference.as_deref().map_or(
                "every frame's words and rows as the file path's".into(),
                |d| { format!("DIFFERENT: {d}") }
            ),
            stderr.lines().last().unwrap_or("").trim()
        ),
    ));

    // 2. The same through a relay that damages the stream.
    let dir = root().join("runs/relay");
    let out = dir.join("record");
    let (damage, code, json, stderr) = record_through(elf, &lab, &dir, reference, true)?;
    let seen = dir.join("relay-in.bin");
    let v = capture::judge(clean_bin, clean, &out, &json)?;
    let upstream = harness_lost(clean_bin, &seen)?;
    let lost = json["lost_frame_count"].as_u64().unwrap_or(u64::MAX);
    // Every frame the plan destroyed must be missing (the relay did what
    // it meant to); the rest missing were lost between QEMU and the relay.
    let planned: BTreeSet<u64> = damage.frames_destroyed.iter().map(|&k| k as u64).collect();
    let missing: BTreeSet<u64> = v.not_received.iter().copied().collect();
    let plan_done = planned.is_subset(&missing) || !upstream.is_empty();
    checks.push((
        "record_through_a_damaging_relay",
        v.exact && plan_done && code == 2 && !stderr.contains("panicked"),
        format!(
            "{} bit flips, {} dropped bytes, {} inserted bytes, {} dropped frames, {:.0} s stall: \
             {} frames destroyed{}, {lost} reported lost; {} frames kept, {} CRC errors, {} resyncs; \
             {} (FOG {} deg, RLG {} counts)",
            damage.bit_flips,
            damage.dropped_bytes,
            damage.inserted_bytes,
            damage.dropped_frames,
            damage.stall_s,
            planned.len(),
            if upstream.is_empty() {
                String::new()
            } else {
                format!(
                    " and {} lost before the relay (harness loss, frames {:?})",
                    upstream.len(),
                    upstream
                )
            },
            json["frames"],
            json["crc_errors"],
            json["resyncs"],
            v.first_difference
                .as_deref()
                .map_or("every kept frame's rows and every angle as the file path's".into(), |d| {
                    format!("DIFFERENT: {d}")
                }),
            json["fog_angle_deg"],
            json["rlg_counts"]
        ),
    ));

    // 3. The lab's analyses on the damaged record: board to lab, end to end.
    let fog = out.join("fog.csv");
    let allan = Command::new(&lab)
        .args(["allan", "--json", "--force", "--data"])
        .arg(&fog)
        .arg("--out")
        .arg(dir.join("allan"))
        .output()?;
    let a: serde_json::Value = serde_json::from_str(
        String::from_utf8_lossy(&allan.stdout)
            .lines()
            .last()
            .unwrap_or("{}"),
    )
    .unwrap_or_default();
    checks.push((
        "allan_on_the_recorded_file",
        // One frame per row: every lost frame is one filled sample.
        allan.status.success()
            && a["taus_s"].as_array().is_some_and(|t| !t.is_empty())
            && a["gaps"]["filled_samples"].as_u64() == Some(lost),
        format!(
            "exit {}, {} averaging times, {} samples filled where {lost} frames were lost",
            allan.status,
            a["taus_s"].as_array().map_or(0, |t| t.len()),
            a["gaps"]["filled_samples"]
        ),
    ));
    let disc = Command::new(&lab)
        .args(["discover", "--gyro", "fog", "--json", "--force", "--data"])
        .arg(&fog)
        .arg("--out")
        .arg(dir.join("discover"))
        .output()?;
    let v: serde_json::Value = serde_json::from_str(
        String::from_utf8_lossy(&disc.stdout)
            .lines()
            .last()
            .unwrap_or("{}"),
    )
    .unwrap_or_default();
    let (before, after) = (
        v["gap_before_dph"].as_f64().unwrap_or(f64::NAN),
        v["gap_after_dph"].as_f64().unwrap_or(f64::NAN),
    );
    checks.push((
        "discover_on_the_recorded_file",
        disc.status.success() && after <= before,
        format!(
            "exit {}, gap {before:.3} -> {after:.3} deg/h, found {}",
            disc.status, v["found"]
        ),
    ));
    Ok(checks)
}
