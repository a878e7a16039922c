//! Build script:
//! - puts memory.x where cortex-m-rt's link.x finds it (MCU builds);
//! - firmware builds: turns the RLG thermal coefficient file (`RLG_COEFFS`,
//!   default config/rlg_thermal.toml, as `gyro-lab fit thermal` writes it)
//!   into the CRC-protected record the firmware loads at start
//!   (src/rlg/coeffs.rs, compiled here too so both sides share one encoder).
use std::{env, fs, path::PathBuf};

#[path = "src/rlg/coeffs.rs"]
#[allow(dead_code)]
mod coeffs;

fn main() {
    let out = PathBuf::from(env::var_os("OUT_DIR").unwrap());
    fs::copy("memory.x", out.join("memory.x")).unwrap();
    println!("cargo:rustc-link-search={}", out.display());
    println!("cargo:rerun-if-changed=memory.x");
    println!("cargo:rerun-if-changed=build.rs");
    println!("cargo:rerun-if-changed=src/rlg/coeffs.rs");
    println!("cargo:rerun-if-env-changed=RLG_COEFFS");
    if env::var_os("CARGO_FEATURE_FIRMWARE").is_none() {
        return;
    }
    let path = env::var_os("RLG_COEFFS")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from("config/rlg_thermal.toml"));
    println!("cargo:rerun-if-changed={}", path.display());
    let f = coeff_file::read(&path).unwrap_or_else(|e| panic!("RLG coefficients: {e}"));
    let c = f
        .rlg_thermal
        .unwrap_or_else(|| panic!("{}: no [rlg_thermal]", path.display()));
    let record = coeffs::ThermalCoeffs::from_values(c.values()).to_record();
    fs::write(out.join("rlg_coeffs.bin"), record).unwrap();
}
