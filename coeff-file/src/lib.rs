//! Coefficient files: what `gyro-lab fit` writes, `gyro-lab compensate`
//! applies and the firmware build embeds (as a CRC-protected record).
//!
//! ```toml
//! kind = "rlg_thermal"
//! version = 1
//! [rlg_thermal]            # B = bias0 + k1*dT + k2*grad(dT) + k3*dT^2 + k4*T_K + k5*(1 - exp(-t/tau_warm))
//! bias0_dph = 0.05
//! k1_dph_per_c = 0.08
//! k2_dph_per_c_per_s = 4.0
//! k3_dph_per_c2 = 0.012
//! k4_dph_per_c = 0.004
//! k5_dph = 0.12
//! tau_warm_s = 800.0
//! [fit]                    # optional, informative: where the set came from
//! ```

use serde::{Deserialize, Serialize};
use std::path::Path;

pub const VERSION: u16 = 1;

#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RlgThermal {
    pub bias0_dph: f64,
    pub k1_dph_per_c: f64,
    pub k2_dph_per_c_per_s: f64,
    pub k3_dph_per_c2: f64,
    pub k4_dph_per_c: f64,
    pub k5_dph: f64,
    pub tau_warm_s: f64,
}

impl RlgThermal {
    /// The values in the firmware record's order: bias0, k1..k5, tau_warm.
    pub fn values(&self) -> [f64; 7] {
        [
            self.bias0_dph,
            self.k1_dph_per_c,
            self.k2_dph_per_c_per_s,
            self.k3_dph_per_c2,
            self.k4_dph_per_c,
            self.k5_dph,
            self.tau_warm_s,
        ]
    }

    /// From values in record order.
    pub fn from_values(v: [f64; 7]) -> Self {
        Self {
            bias0_dph: v[0],
            k1_dph_per_c: v[1],
            k2_dph_per_c_per_s: v[2],
            k3_dph_per_c2: v[3],
            k4_dph_per_c: v[4],
            k5_dph: v[5],
            tau_warm_s: v[6],
        }
    }
}

#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct CoeffFile {
    pub kind: String,
    pub version: u16,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub rlg_thermal: Option<RlgThermal>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub fit: Option<toml::Table>,
}

/// Reads and checks a coefficient file; errors are one line,
/// `file:line:column: message` where the parser knows the place.
pub fn read(path: &Path) -> Result<CoeffFile, String> {
    let name = path.display();
    let text = std::fs::read_to_string(path).map_err(|e| format!("{name}: cannot read: {e}"))?;
    let f: CoeffFile = toml::from_str(&text).map_err(|e| {
        let msg = e.message().replace('\n', " ");
        match e.span() {
            Some(s) => {
                let before = &text[..s.start.min(text.len())];
                let line = before.matches('\n').count() + 1;
                let col = before.len() - before.rfind('\n').map_or(0, |i| i + 1) + 1;
                format!("{name}:{line}:{col}: {msg}")
            }
            None => format!("{name}: {msg}"),
        }
    })?;
    if f.version != VERSION {
        return Err(format!(
            "{name}: version {} (this tool reads version {VERSION})",
            f.version
        ));
    }
    match (f.kind.as_str(), &f.rlg_thermal) {
        ("rlg_thermal", Some(c)) => {
            if c.values().iter().any(|x| !x.is_finite()) {
                return Err(format!(
                    "{name}: [rlg_thermal] holds a value that is not finite"
                ));
            }
            Ok(f)
        }
        ("rlg_thermal", None) => Err(format!("{name}: kind rlg_thermal without [rlg_thermal]")),
        (k, _) => Err(format!("{name}: unknown coefficient kind `{k}`")),
    }
}

/// Writes a coefficient file with a comment header.
pub fn write(path: &Path, f: &CoeffFile, comment: &str) -> Result<(), String> {
    let body = toml::to_string(f).map_err(|e| e.to_string())?;
    let head: String = comment.lines().map(|l| format!("# {l}\n")).collect();
    std::fs::write(path, format!("{head}{body}")).map_err(|e| format!("{}: {e}", path.display()))
}
