//! Installs what the firmware build, the QEMU runs and the ISR proof need,
//! once.

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
    // Debian's packages: the emulator, and the disassembler the ISR proof
    // reads the image with.
    for (cmd, package) in [
        ("qemu-system-arm", "qemu-system-arm"),
        ("arm-none-eabi-objdump", "binutils-arm-none-eabi"),
    ] {
        if !have(cmd) {
            apt_install(package)?;
        }
    }
    for tool in ["flip-link", "defmt-print"] {
        if !have(tool) {
            run(Command::new("cargo").args(["install", "--locked", tool]))?;
        }
    }
    Ok(())
}

pub fn apt_install(package: &str) -> Result<()> {
    let sudo = if have("sudo") && !is_root() {
        "sudo "
    } else {
        ""
    };
    run(Command::new("sh").args([
        "-c",
        &format!("{sudo}apt-get update -q && {sudo}env DEBIAN_FRONTEND=noninteractive apt-get install -y -q {package}"),
    ]))
}

fn is_root() -> bool {
    Command::new("id")
        .arg("-u")
        .output()
        .is_ok_and(|o| o.stdout.starts_with(b"0"))
}
