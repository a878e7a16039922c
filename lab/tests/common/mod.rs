//! What the end-to-end tests share: running the built `gyro-lab`, a scratch
//! directory, the JSON line. (Each test crate uses its own subset.)
#![allow(dead_code)]

use std::path::PathBuf;
use std::process::Command;

/// Runs gyro-lab: (exit status, stdout, stderr).
pub fn lab(args: &[&str]) -> (i32, String, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_gyro-lab"))
        .args(args)
        .output()
        .expect("run gyro-lab");
    (
        out.status.code().unwrap_or(-1),
        String::from_utf8_lossy(&out.stdout).into_owned(),
        String::from_utf8_lossy(&out.stderr).into_owned(),
    )
}

/// Runs gyro-lab, which must succeed (else the test fails with its
/// stderr): its stdout.
pub fn lab_ok(args: &[&str]) -> String {
    let (code, stdout, err) = lab(args);
    assert_eq!(code, 0, "{args:?}: {err}");
    stdout
}

/// A scratch directory of this test process, `gyro-lab-<name>-<pid>`.
pub fn dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("gyro-lab-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// The JSON object on the last line of stdout.
pub fn json(stdout: &str) -> serde_json::Value {
    serde_json::from_str(stdout.lines().last().unwrap()).unwrap()
}
