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

/// gyrolab.allan against allantools' oadev on 2e6 samples: the JSON of
/// the benchmark's last line.
pub fn bench_allan() -> Result<serde_json::Value> {
    install()?;
    let out = Command::new(python())
        .arg(root().join("python/benchmarks/allan_speed.py"))
        .current_dir(root())
        .output()?;
    if !out.status.success() {
        bail!(
            "python/benchmarks/allan_speed.py failed: {}",
            String::from_utf8_lossy(&out.stderr)
        );
    }
    let text = String::from_utf8_lossy(&out.stdout);
    for l in text.lines() {
        println!("{l}");
    }
    Ok(serde_json::from_str(text.lines().last().unwrap_or("{}"))?)
}

/// The curvature bound (instruments/d2t_bound/bound.py) beside what
/// `discover` reaches on the same chamber runs: one key per case.
pub fn bench_d2t(lab: &std::path::Path) -> Result<serde_json::Value> {
    install()?;
    let work = root().join("runs/d2t");
    let out = Command::new(python())
        .arg(root().join("instruments/d2t_bound/bound.py"))
        .arg("--lab")
        .arg(lab)
        .arg("--work")
        .arg(&work)
        .arg("--json")
        .current_dir(root())
        .output()?;
    if !out.status.success() {
        bail!(
            "instruments/d2t_bound/bound.py failed: {}",
            String::from_utf8_lossy(&out.stderr)
        );
    }
    let text = String::from_utf8_lossy(&out.stdout);
    let mut v: serde_json::Value = serde_json::from_str(text.lines().last().unwrap_or("{}"))?;
    if let Some(o) = v.as_object_mut() {
        o.remove("d2t_rows");
    }
    Ok(v)
}
