//! The Python package (python/): built into a virtual environment under
//! target/ with pip (maturin, as a user installs it), then its pytest
//! suite and its benchmark against allantools.

use crate::{root, run};
use anyhow::{bail, Context, Result};
use std::path::PathBuf;
use std::process::Command;

/// The virtual environment the package is tested in.
fn venv() -> PathBuf {
    root().join("target/py-venv")
}

fn python() -> PathBuf {
    venv().join("bin/python")
}

/// A python3 with venv and pip (Debian's python3-venv where it lacks them).
fn system_python() -> Result<String> {
    let ok = |py: &str| {
        Command::new(py)
            .args(["-c", "import venv, ensurepip"])
            .status()
            .is_ok_and(|s| s.success())
    };
    for py in ["python3", "python"] {
        if ok(py) {
            return Ok(py.into());
        }
    }
    crate::setup::apt_install("python3-venv python3-pip")?;
    if ok("python3") {
        return Ok("python3".into());
    }
    bail!("no python3 with venv and pip: the Python package needs one (pip install ./python)")
}

/// `pip install ./python[test]` into target/py-venv: the package exactly
/// as the README installs it, and what its tests use.
pub fn install() -> Result<()> {
    if !python().exists() {
        let py = system_python()?;
        run(Command::new(py).arg("-m").arg("venv").arg(venv()))?;
        run(Command::new(python()).args(["-m", "pip", "install", "-q", "--upgrade", "pip"]))?;
    }
    run(Command::new(python())
        .args(["-m", "pip", "install", "-q"])
        .arg(format!("{}[test]", root().join("python").display()))
        .current_dir(root()))
    .context("pip install ./python[test]")
}

/// The suite against the command line at `gyro_lab` (the release
/// binary): every comparison required, none skipped for want of it.
pub fn test(gyro_lab: &std::path::Path) -> Result<()> {
    install()?;
    run(Command::new(python())
        .args([
            "-m",
            "pytest",
            "-q",
            "-rs",
            "-p",
            "no:cacheprovider",
            "python/tests",
        ])
        .env("GYRO_LAB", gyro_lab)
        .env("GYROLAB_REQUIRE_CLI", "1")
        .current_dir(root()))
}

/// A Python script of the repository run in the package's venv with
/// `args`: its output printed, and the JSON of its last line.
fn json_of_script(script: &str, args: &[&std::ffi::OsStr]) -> Result<serde_json::Value> {
    install()?;
    let out = Command::new(python())
        .arg(root().join(script))
        .args(args)
        .current_dir(root())
        .output()?;
    if !out.status.success() {
        bail!("{script} failed: {}", String::from_utf8_lossy(&out.stderr));
    }
    let text = String::from_utf8_lossy(&out.stdout);
    for l in text.lines() {
        println!("{l}");
    }
    Ok(serde_json::from_str(text.lines().last().unwrap_or("{}"))?)
}

/// gyrolab.allan against allantools' oadev on 2e6 samples: the JSON of
/// the benchmark's last line.
pub fn bench_allan() -> Result<serde_json::Value> {
    json_of_script("python/benchmarks/allan_speed.py", &[])
}

/// The curvature bound (instruments/d2t_bound/bound.py) beside what
/// `discover` reaches on the same chamber runs: one key per case.
pub fn bench_d2t(lab: &std::path::Path) -> Result<serde_json::Value> {
    let work = root().join("runs/d2t");
    let mut v = json_of_script(
        "instruments/d2t_bound/bound.py",
        &[
            "--lab".as_ref(),
            lab.as_os_str(),
            "--work".as_ref(),
            work.as_os_str(),
            "--json".as_ref(),
        ],
    )?;
    if let Some(o) = v.as_object_mut() {
        o.remove("d2t_rows");
    }
    Ok(v)
}
