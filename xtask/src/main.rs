//! `cargo xtask qemu | test | bench`: developer entry points. Each first installs
//! what it needs (thumbv7em target, qemu-system-arm, flip-link, defmt-print).

mod bench_discover;
mod capture;
mod frames;
mod panic_paths;
mod python;
mod record_test;
mod setup;

use anyhow::{bail, Context, Result};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

pub const TARGET: &str = "thumbv7em-none-eabihf";

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let r = match args.first().map(String::as_str) {
        Some("qemu") => qemu_cmd(),
        Some("test") => test_cmd(),
        Some("bench") => bench_cmd(),
        // The board-to-lab tests alone (part of `test`).
        Some("record-test") => record_test_cmd(),
        // The interrupt handlers' freedom from panics (part of `test`).
        Some("isr-proof") => isr_proof_cmd(),
        // The README's lab walkthrough, top to bottom (part of `test`).
        Some("readme") => readme_cmd(),
        // The Python package's pytest suite (part of `test`).
        Some("python-test") => python_test_cmd(),
        _ => {
            eprintln!(
                "usage: cargo xtask <qemu|test|bench|record-test|isr-proof|readme|python-test>"
            );
            std::process::exit(2);
        }
    };
    if let Err(e) = r {
        eprintln!("xtask: {e:#}");
        std::process::exit(1);
    }
}

pub fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .map(Path::to_path_buf)
        .unwrap_or_default()
}

pub fn run(cmd: &mut Command) -> Result<()> {
    eprintln!("$ {:?}", cmd);
    let st = cmd
        .current_dir(root())
        .status()
        .with_context(|| format!("running {cmd:?}"))?;
    if !st.success() {
        bail!("{cmd:?} failed: {st}");
    }
    Ok(())
}

fn cargo() -> Command {
    Command::new(std::env::var("CARGO").unwrap_or_else(|_| "cargo".into()))
}

/// Both boards' firmware binaries, built in one go (their features only add
/// each board's crates).
const FIRMWARE: [&str; 8] = [
    "--release",
    "--target",
    TARGET,
    "--package",
    "gyro-fw",
    "--features",
    "qemu,hw",
    "--bins",
];

/// Builds the firmware and returns the ELF path of a board's binary.
pub fn build_firmware(board: &str) -> Result<PathBuf> {
    run(cargo().arg("build").args(FIRMWARE))?;
    Ok(root()
        .join("target")
        .join(TARGET)
        .join("release")
        .join(format!("gyro-fw-{board}")))
}

/// QEMU's clock: instruction-counted, never the host's (see [`qemu_command`]).
pub const QEMU_ICOUNT: &str = "shift=0,sleep=off";

/// Output of one QEMU run.
pub struct QemuRun {
    pub log: String,
    pub frames_path: PathBuf,
    pub elf: PathBuf,
}

/// A QEMU run that has written nothing (frames or log) for this long, in
/// wall-clock time, is hung: it is stopped with an error. A normal run
/// writes frames every few milliseconds of its own time.
pub const QEMU_STALL: std::time::Duration = std::time::Duration::from_secs(60);
/// And no run takes longer than this at all.
pub const QEMU_LIMIT: std::time::Duration = std::time::Duration::from_secs(20 * 60);

/// qemu-system-arm on the `qemu` firmware, deterministic; `serial`: QEMU's
/// -serial argument (a file, or `pty`). Every QEMU run is made here.
///
/// `-icount shift=0`: one instruction is 1 ns of virtual time, so SysTick and
/// TIM2 count instructions. `sleep=off`: while the guest sleeps in WFI the
/// virtual clock jumps to the next timer deadline. With icount's default
/// (`sleep=on`) it runs on the host's real time there, so how late the next
/// interrupt lands, and every frame after it, would depend on the host's
/// speed and load. A guest blocked on a full serial backend (a slow reader
/// on the pty) executes nothing, so its clock stands still there too.
pub fn qemu_command(elf: &Path, serial: &str) -> Command {
    let mut c = Command::new("qemu-system-arm");
    c.args([
        "-machine",
        "netduinoplus2",
        "-cpu",
        "cortex-m4",
        "-nographic",
        "-monitor",
        "none",
    ])
    .args([
        "-semihosting-config",
        "enable=on,target=native",
        "-icount",
        QEMU_ICOUNT,
    ])
    .arg("-serial")
    .arg(serial)
    .arg("-kernel")
    .arg(elf)
    .stdin(Stdio::null());
    c
}

/// Waits for QEMU, stopping it when none of `outputs` has grown for
/// `stall` ([`QEMU_STALL`]) or the run passes [`QEMU_LIMIT`].
pub fn wait_progressing(
    child: &mut std::process::Child,
    outputs: &[&Path],
    stall: std::time::Duration,
) -> Result<std::process::ExitStatus> {
    let size = |p: &Path| std::fs::metadata(p).map(|m| m.len()).unwrap_or(0);
    let start = std::time::Instant::now();
    let mut last_change = start;
    let mut sizes: Vec<u64> = outputs.iter().map(|p| size(p)).collect();
    loop {
        if let Some(st) = child.try_wait()? {
            return Ok(st);
        }
        std::thread::sleep(std::time::Duration::from_millis(200));
        let now: Vec<u64> = outputs.iter().map(|p| size(p)).collect();
        if now != sizes {
            sizes = now;
            last_change = std::time::Instant::now();
        }
        let stalled = last_change.elapsed() > stall;
        if stalled || start.elapsed() > QEMU_LIMIT {
            let _ = child.kill();
            let _ = child.wait();
            bail!(
                "QEMU stopped: {} (frames and log at {:?} bytes); the firmware is hung or looping",
                if stalled {
                    format!("no output for {} s", stall.as_secs())
                } else {
                    format!("still running after {} s", QEMU_LIMIT.as_secs())
                },
                sizes
            );
        }
    }
}

/// Runs the `qemu` firmware deterministically ([`QEMU_ICOUNT`]) and decodes defmt.
pub fn run_qemu() -> Result<QemuRun> {
    let elf = build_firmware("qemu")?;
    let dir = root().join("runs");
    std::fs::create_dir_all(&dir)?;
    let frames_path = dir.join("qemu-frames.bin");
    let raw_log = dir.join("qemu-defmt.bin");
    let out = std::fs::File::create(&raw_log)?;
    eprintln!(
        "$ qemu-system-arm -machine netduinoplus2 ... -kernel {}",
        elf.display()
    );
    let mut child = qemu_command(&elf, &format!("file:{}", frames_path.display()))
        .stdout(out)
        .spawn()
        .context("starting qemu-system-arm")?;
    let st = wait_progressing(&mut child, &[&frames_path, &raw_log], QEMU_STALL)?;
    let decoded = Command::new("defmt-print")
        .arg("-e")
        .arg(&elf)
        .stdin(std::fs::File::open(&raw_log)?)
        .output()
        .context("running defmt-print")?;
    let log = String::from_utf8_lossy(&decoded.stdout).into_owned();
    print!("{log}");
    if !st.success() {
        bail!("firmware under QEMU exited with {st}");
    }
    Ok(QemuRun {
        log,
        frames_path,
        elf,
    })
}

fn qemu_cmd() -> Result<()> {
    setup::ensure_all()?;
    let run = run_qemu()?;
    let report = frames::analyse(&run.frames_path)?;
    let dir = record_qemu_run(&run)?;
    frames::print_summary(&report);
    print_coefficients();
    println!("run file: {}", dir.join("fog.csv").display());
    println!("RLG run file: {}", dir.join("rlg.csv").display());
    Ok(())
}

/// The coefficient files build.rs embedded (the same environment
/// variables and defaults), each with its record's CRC: which calibration
/// the run was made with.
pub fn print_coefficients() {
    for (var, default) in [
        ("RLG_COEFFS", "config/rlg_thermal.toml"),
        ("FOG_SF_COEFFS", "config/fog_scale_factor.toml"),
    ] {
        let (path, how) = match std::env::var_os(var) {
            Some(p) => (PathBuf::from(p), "from the environment"),
            None => (root().join(default), "the default"),
        };
        let crc = match gyro_coeffs::file::read(&path) {
            Ok((_, gyro_coeffs::file::Coeffs::RlgThermal(c))) => {
                gyro_coeffs::record::crc_of(&c.to_record())
            }
            Ok((_, gyro_coeffs::file::Coeffs::FogScaleFactor(t))) => {
                gyro_coeffs::record::crc_of(&t.to_record())
            }
            Err(_) => 0,
        };
        println!(
            "coefficients built in: {var} = {} ({how}), record CRC 0x{crc:08x}",
            path.display()
        );
    }
}

/// The QEMU run's capture through the recorder into runs/qemu/, against
/// the built-in profile (runs/qemu-reference.csv); the clean angles in
/// runs/qemu/angles.json.
fn record_qemu_run(run: &QemuRun) -> Result<PathBuf> {
    let runs = root().join("runs");
    let reference = frames::write_reference(&runs.join("qemu-reference.csv"))?;
    let dir = runs.join("qemu");
    let (_, (fog_deg, rlg_counts)) = frames::record_capture(&run.frames_path, &dir, reference)?;
    std::fs::write(
        dir.join("angles.json"),
        serde_json::json!({ "fog_angle_deg": fog_deg, "rlg_counts": rlg_counts }).to_string(),
    )?;
    Ok(dir)
}

fn test_cmd() -> Result<()> {
    setup::ensure_all()?;
    run(cargo().args(["fmt", "--all", "--check"]))?;
    run(cargo().args([
        "clippy",
        "--workspace",
        "--release",
        "--all-targets",
        "--",
        "-D",
        "warnings",
    ]))?;
    run(cargo()
        .arg("clippy")
        .args(FIRMWARE)
        .args(["--lib", "--", "-D", "warnings"]))?;
    run(cargo().args(["test", "--workspace", "--profile", "host-test"]))?;
    isr_proof(&build_firmware("hw")?)?;
    // Tests of the firmware under QEMU.
    let qrun = run_qemu()?;
    let report = frames::analyse(&qrun.frames_path)?;
    frames::print_summary(&report);
    print_coefficients();
    let checks = frames::qemu_checks(&report, &qrun.log);
    let failed = checks.iter().filter(|c| !c.1).count();
    for (name, ok, detail) in &checks {
        println!(
            "qemu test {name} ... {} ({detail})",
            if *ok { "ok" } else { "FAILED" }
        );
    }
    println!("qemu: {} passed, {} failed", checks.len() - failed, failed);
    if failed > 0 {
        bail!("{failed} firmware test(s) under QEMU failed");
    }
    record_tests(&qrun)?;
    // The Python package over the same code, against the command line
    // (record_tests built it) and the QEMU run's capture.
    python::test(&root().join("target/release/gyro-lab"))?;
    readme_cmd()
}

/// `cargo xtask python-test`: the Python package's suite alone.
fn python_test_cmd() -> Result<()> {
    run(cargo().args(["build", "--release", "-p", "gyro-lab"]))?;
    python::test(&root().join("target/release/gyro-lab"))
}

/// `cargo xtask readme`: the README's "The lab, step by step", every
/// command as written, in a scratch folder (scripts/readme-walkthrough.sh).
fn readme_cmd() -> Result<()> {
    run(Command::new("sh").arg(root().join("scripts/readme-walkthrough.sh")))
}

/// The interrupts that must exist in the hw image: the FOG closure (ADC
/// DMA) and the RLG update (TIM5).
const HW_HANDLERS: [&str; 2] = ["DMA2_STREAM0", "TIM5"];

/// No interrupt handler of the hw release image reaches a panic
/// (`panic_paths.rs`): each handler in its vector table is checked.
fn isr_proof(elf: &Path) -> Result<()> {
    let proof = panic_paths::check(elf)?;
    let verdicts = &proof.handlers;
    for h in HW_HANDLERS {
        if !verdicts.iter().any(|(name, _)| name == h) {
            bail!("the hw image's vector table has no {h} handler");
        }
    }
    if let Some(p) = &proof.entry {
        println!("isr proof: start-up may panic (a reset, docs/panics.md), e.g. {p}");
    }
    match &proof.idle {
        Some(None) => println!("isr proof: the idle loop has no path to a panic"),
        Some(Some(p)) => println!("isr proof: the idle loop may panic (a reset), e.g. {p}"),
        None => {}
    }
    let mut failed = 0;
    for (name, path) in verdicts {
        match path {
            None => println!("isr proof {name} ... ok (no path to a panic)"),
            Some(p) => {
                failed += 1;
                println!("isr proof {name} ... FAILED: {p}");
            }
        }
    }
    if failed > 0 {
        bail!(
            "{failed} interrupt handler(s) of {} can panic",
            elf.display()
        );
    }
    Ok(())
}

/// `cargo xtask isr-proof`: the proof alone, on a fresh hw build.
fn isr_proof_cmd() -> Result<()> {
    setup::ensure_all()?;
    isr_proof(&build_firmware("hw")?)
}

/// `cargo xtask record-test`: the QEMU run and the board-to-lab tests.
fn record_test_cmd() -> Result<()> {
    setup::ensure_all()?;
    let qrun = run_qemu()?;
    record_tests(&qrun)
}

/// The board-to-lab path: QEMU's USART on a pty read by `gyro-lab record`,
/// then through a relay that damages the stream.
fn record_tests(qrun: &QemuRun) -> Result<()> {
    let clean = record_qemu_run(qrun)?;
    run(cargo().args(["build", "--release", "-p", "gyro-lab"]))?;
    let checks = record_test::run(
        &qrun.elf,
        &clean,
        &qrun.frames_path,
        &root().join("runs/qemu-reference.csv"),
    )?;
    let failed = checks.iter().filter(|c| !c.1).count();
    for (name, ok, detail) in &checks {
        println!(
            "record test {name} ... {} ({detail})",
            if *ok { "ok" } else { "FAILED" }
        );
    }
    if failed > 0 {
        bail!("{failed} record test(s) failed");
    }
    Ok(())
}

fn bench_cmd() -> Result<()> {
    setup::ensure_all()?;
    let qrun = run_qemu()?;
    // key=value words of the firmware's `bench:` log lines.
    let figures: std::collections::HashMap<&str, u64> = qrun
        .log
        .lines()
        .filter(|l| l.contains("bench:"))
        .flat_map(|l| l.split_whitespace())
        .filter_map(|w| {
            let (k, v) = w.split_once('=')?;
            Some((k, v.trim().parse().ok()?))
        })
        .collect();
    let grab = |key: &str| {
        figures
            .get(key)
            .copied()
            .with_context(|| format!("no {key} in the firmware's bench lines"))
    };
    let instr = grab("fog_closure_instructions")?;
    let stack = grab("stack_bytes")?;
    let rlg_instr = grab("rlg_update_instructions")?;
    let (flash, ram) = frames::elf_sizes(&qrun.elf)?;
    // Real-time factor of the host simulator (release build, default options).
    run(cargo().args(["build", "--release", "-p", "gyro-lab"]))?;
    let lab = root().join("target/release/gyro-lab");
    let out = Command::new(&lab)
        .args(["simulate", "fog", "--duration-s", "20", "--json"])
        .output()?;
    let text = String::from_utf8_lossy(&out.stdout);
    let v: serde_json::Value = serde_json::from_str(text.lines().last().unwrap_or("{}"))?;
    let rtf = v["realtime_factor"]
        .as_f64()
        .context("no realtime_factor from gyro-lab")?;
    // Allan analysis of 10^7 samples (28 h at 100 Hz), the CSV read of that
    // record apart, against the O(N m) definition on 10^5.
    let out = Command::new(&lab)
        .args(["bench", "allan-speed", "--json"])
        .output()?;
    let text = String::from_utf8_lossy(&out.stdout);
    let allan: serde_json::Value = serde_json::from_str(text.lines().last().unwrap_or("{}"))?;
    let af = |k: &str| {
        allan[k]
            .as_f64()
            .with_context(|| format!("no {k} from gyro-lab bench allan-speed"))
    };
    let discover = bench_discover::costs(&lab, &root().join("runs"))?;
    let py = python::bench_allan()?;
    let d2t = python::bench_d2t(&lab)?;
    let j = serde_json::json!({
        "fog_closure_instructions": instr,
        "fog_closure_instructions_max": grab("max")?,
        "rlg_update_instructions": rlg_instr,
        "rlg_latch_instructions": grab("rlg_latch_instructions")?,
        "rlg_latch_instructions_max": grab("rlg_latch_max")?,
        "rlg_frames_late": grab("rlg_frames_late")?,
        "closure_latency_instructions_max": grab("closure_latency_max")?,
        "closure_latency_under_rlg_instructions_max": grab("closure_latency_under_rlg_max")?,
        "closures_under_rlg": grab("closures_under_rlg")?,
        "fog_sf_frame_instructions": grab("fog_sf_frame_instructions")?,
        "fog_sf_frame_instructions_max": grab("sf_frame_max")?,
        "fog_sf_sensor_instructions": grab("fog_sf_sensor_instructions")?,
        "sim_fog_realtime_factor": (rtf * 10.0).round() / 10.0,
        "allan_1e7_s": af("allan_1e7_s")?,
        "allan_read_1e7_s": af("allan_read_1e7_s")?,
        "allan_reference_1e5_s": af("allan_reference_1e5_s")?,
        "allan_1e7_vs_reference_1e5": af("allan_1e7_vs_reference_1e5")?,
        "flash_bytes": flash,
        "ram_bytes": ram,
        "stack_bytes": stack,
    });
    let mut j = j;
    if let (Some(o), Some(d)) = (j.as_object_mut(), discover.as_object()) {
        o.extend(d.clone());
    }
    for extra in [&py, &d2t] {
        if let (Some(o), Some(p)) = (j.as_object_mut(), extra.as_object()) {
            o.extend(p.clone());
        }
    }
    println!("{j}");
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A child that writes nothing is stopped after the stall time with an
    /// error that says so; one that finishes is waited for.
    #[test]
    fn a_stalled_run_is_stopped() {
        let dir = std::env::temp_dir().join(format!("xtask-stall-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let out = dir.join("out.bin");
        std::fs::write(&out, b"x").unwrap();
        let mut child = Command::new("sleep").arg("30").spawn().unwrap();
        let t0 = std::time::Instant::now();
        let e = wait_progressing(&mut child, &[&out], std::time::Duration::from_secs(1))
            .unwrap_err()
            .to_string();
        assert!(e.contains("no output for 1 s"), "{e}");
        assert!(t0.elapsed() < std::time::Duration::from_secs(10));
        assert!(child.try_wait().unwrap().is_some(), "child left running");
        let mut child = Command::new("true").spawn().unwrap();
        let st = wait_progressing(&mut child, &[&out], std::time::Duration::from_secs(5)).unwrap();
        assert!(st.success());
        let _ = std::fs::remove_dir_all(&dir);
    }
}
