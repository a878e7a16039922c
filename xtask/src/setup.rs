//! Installs what the firmware build and the QEMU runs need, once.

use crate::{run, TARGET};
use anyhow::Result;
use std::process::Command;

fn have(cmd: &str) -> bool {
    Command::new("sh")
        .args(["-c", &format!("command -v {cmd} >/dev/null 2>&1")])
        .status()
        .is_ok_and(|s| s.success())
}

pub fn ensure_all() -> Result<()> {
    let installed = Command::new("rustup")
        .args(["target", "list", "--installed"])
        .output()?;
    if !String::from_utf8_lossy(&installed.stdout).contains(TARGET) {
        run(Command::new("rustup").args(["target", "add", TARGET]))?;
    }
    if !have("qemu-system-arm") {
        let sudo = if have("sudo") && !is_root() {
            "sudo "
        } else {
            ""
        };
        run(Command::new("sh").args([
            "-c",
            &format!("{sudo}apt-get update -q && {sudo}env DEBIAN_FRONTEND=noninteractive apt-get install -y -q qemu-system-arm"),
        ]))?;
    }
    for tool in ["flip-link", "defmt-print"] {
        if !have(tool) {
            run(Command::new("cargo").args(["install", "--locked", tool]))?;
        }
    }
    Ok(())
}

fn is_root() -> bool {
    Command::new("id")
        .arg("-u")
        .output()
        .is_ok_and(|o| o.stdout.starts_with(b"0"))
}
