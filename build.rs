//! Build script:
//! - puts memory.x where cortex-m-rt's link.x finds it (MCU builds);
//! - turns the coefficient files into the CRC-protected
//!   records the firmware checks at start (gyro-coeffs defines both sides):
//!   `RLG_COEFFS` (default config/rlg_thermal.toml, from `gyro-lab fit
//!   thermal`) and `FOG_SF_COEFFS` (default config/fog_scale_factor.toml,
//!   from `gyro-lab fit scale-factor`).
use gyro_coeffs::file::{read, Coeffs};
use std::{env, fs, path::PathBuf};

fn main() {
    let out = PathBuf::from(env::var_os("OUT_DIR").unwrap());
    fs::copy("memory.x", out.join("memory.x")).unwrap();
    println!("cargo:rustc-link-search={}", out.display());
    println!("cargo:rerun-if-changed=memory.x");
    println!("cargo:rerun-if-changed=build.rs");
    for (var, default, bin) in [
        ("RLG_COEFFS", "config/rlg_thermal.toml", "rlg_coeffs.bin"),
        (
            "FOG_SF_COEFFS",
            "config/fog_scale_factor.toml",
            "fog_sf_coeffs.bin",
        ),
    ] {
        println!("cargo:rerun-if-env-changed={var}");
        let path = env::var_os(var)
            .map(PathBuf::from)
            .unwrap_or_else(|| PathBuf::from(default));
        println!("cargo:rerun-if-changed={}", path.display());
        let (_, c) = read(&path).unwrap_or_else(|e| panic!("{var}: {e}"));
        let record = match (var, c) {
            ("RLG_COEFFS", Coeffs::RlgThermal(c)) => c.to_record().to_vec(),
            ("FOG_SF_COEFFS", Coeffs::FogScaleFactor(t)) => t.to_record().to_vec(),
            _ => panic!(
                "{var}: {} holds the other kind of coefficients",
                path.display()
            ),
        };
        fs::write(out.join(bin), record).unwrap();
    }
}
