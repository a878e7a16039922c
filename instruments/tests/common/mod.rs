//! Running the built `gyro-instruments`, a scratch directory, the JSON line.
#![allow(dead_code)]

use std::path::PathBuf;
use std::process::Command;

/// Runs gyro-instruments, which must succeed (else the test fails with
/// its stderr): its stdout.
pub fn instruments_ok(args: &[&str]) -> String {
    let out = Command::new(env!("CARGO_BIN_EXE_gyro-instruments"))
        .args(args)
        .output()
        .expect("run gyro-instruments");
    assert!(
        out.status.success(),
        "{args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
    String::from_utf8_lossy(&out.stdout).into_owned()
}

/// A scratch directory of this test process.
pub fn dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("gyro-instruments-{name}-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// The JSON object on the last line of stdout.
pub fn json(stdout: &str) -> serde_json::Value {
    serde_json::from_str(stdout.lines().last().unwrap()).unwrap()
}
