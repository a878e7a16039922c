//! `cargo xtask bench`'s discovery costs: `gyro-lab discover` on FOG table
//! runs (a knee, a temperature slope and a bias hidden from the ideal
//! model) of 1 h at 10 Hz, 6 h, 24 h and 72 h at 1 Hz and 24 h at 10 Hz,
//! each timed wall-clock and its peak memory read from the kernel's
//! accounting of that one child (wait4), each checked to find the three.
//! The same at 6, 24 and 72 h with a fourth effect outside the library (a
//! scale factor following the coil's temperature through a 1 h lag, beside
//! the unlagged one): the search over the grammar's candidates runs, the
//! term must be found, and the keys end `_term`.

use anyhow::{bail, Context, Result};
use std::path::Path;
use std::process::{Command, Stdio};

/// Runs `cmd` to its end: (wall seconds, peak resident MB, stdout).
fn measured(cmd: &mut Command, out: &Path) -> Result<(f64, f64, String)> {
    let file = std::fs::File::create(out)?;
    let t0 = std::time::Instant::now();
    let child = cmd.stdout(file).stderr(Stdio::null()).spawn()?;
    let pid = child.id() as libc::pid_t;
    let mut status = 0;
    // SAFETY: an all-zero rusage is a valid value to be overwritten.
    let mut usage: libc::rusage = unsafe { std::mem::zeroed() };
    // SAFETY: waits for our own child, with pointers to live locals.
    let r = unsafe { libc::wait4(pid, &mut status, 0, &mut usage) };
    let wall = t0.elapsed().as_secs_f64();
    std::mem::forget(child);
    if r != pid || !libc::WIFEXITED(status) || libc::WEXITSTATUS(status) != 0 {
        bail!("{cmd:?} failed (status {status})");
    }
    // ru_maxrss is in kilobytes on Linux.
    Ok((
        wall,
        usage.ru_maxrss as f64 / 1024.0,
        std::fs::read_to_string(out)?,
    ))
}

fn rounded(v: f64, digits: i32) -> f64 {
    let k = 10f64.powi(digits);
    (v * k).round() / k
}

/// The costs as JSON keys.
pub fn costs(lab: &Path, dir: &Path) -> Result<serde_json::Value> {
    std::fs::create_dir_all(dir)?;
    let library = "kind = \"gyro_model\"\nversion = 1\ngyro = \"fog\"\n\
         [[effect]]\nname = \"scale_factor_temperature\"\nppm_per_c = 1.5\n\
         [[effect]]\nname = \"scale_factor_knee\"\nknee_c = 30.0\nslope_change_ppm_per_c = 4.0\n\
         [[effect]]\nname = \"bias\"\nbias_dph = 0.2\n";
    let outside = format!(
        "{library}[[effect]]\nname = \"term\"\n\
         formula = \"k_dph * ref_rate_dps * (lag(temp_c, tau_s) - 20)\"\n\
         k_dph = 0.001\ntau_s = 3600\n"
    );
    let truth = dir.join("bench-truth.toml");
    let truth_term = dir.join("bench-truth-term.toml");
    std::fs::write(&truth, library)?;
    std::fs::write(&truth_term, outside)?;
    let mut j = serde_json::Map::new();
    for (key, dt, hours, with_term) in [
        ("discover_1h_10hz", "0.1", 1, false),
        ("discover_6h_1hz", "1", 6, false),
        ("discover_24h_1hz", "1", 24, false),
        ("discover_24h_10hz", "0.1", 24, false),
        ("discover_72h_1hz", "1", 72, false),
        ("discover_6h_1hz_term", "1", 6, true),
        ("discover_24h_1hz_term", "1", 24, true),
        ("discover_72h_1hz_term", "1", 72, true),
    ] {
        let run_file = dir.join(format!("{key}.csv"));
        let st = Command::new(lab)
            .args([
                "simulate",
                "run",
                "--force",
                "--profile",
                "table",
                "--dt-s",
                dt,
            ])
            .args(["--duration-s", &(hours * 3600).to_string(), "--model"])
            .arg(if with_term { &truth_term } else { &truth })
            .arg("--out")
            .arg(&run_file)
            .stdout(Stdio::null())
            .status()?;
        if !st.success() {
            bail!("gyro-lab simulate run failed for {key}");
        }
        let (wall, mb, text) = measured(
            Command::new(lab)
                .args(["discover", "--gyro", "fog", "--json", "--force", "--data"])
                .arg(&run_file)
                .arg("--out")
                .arg(dir.join("discover-bench")),
            &dir.join("discover-bench.json"),
        )?;
        let v: serde_json::Value =
            serde_json::from_str(text.lines().last().unwrap_or("{}")).context("discover's JSON")?;
        let found = v["found"].as_array().cloned().unwrap_or_default();
        let terms = found.iter().filter(|f| f["effect"] == "term").count();
        if found.len() != 3 + usize::from(with_term) || terms != usize::from(with_term) {
            bail!("discover on {key} did not find the hidden effects: {v}");
        }
        j.insert(format!("{key}_s"), rounded(wall, 3).into());
        j.insert(format!("{key}_peak_mb"), rounded(mb, 1).into());
        let _ = std::fs::remove_file(&run_file);
    }
    let r = j["discover_24h_10hz_s"].as_f64().unwrap_or(f64::NAN)
        / j["discover_24h_1hz_s"].as_f64().unwrap_or(f64::NAN);
    j.insert("discover_24h_10hz_over_1hz".into(), rounded(r, 3).into());
    Ok(serde_json::Value::Object(j))
}
