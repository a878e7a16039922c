//! Coefficient files: what `gyro-lab fit` writes, `gyro-lab compensate`
//! applies and the firmware build embeds as a record.
//!
//! ```toml
//! kind = "rlg_thermal"          # or "fog_scale_factor"
//! version = 1
//! [rlg_thermal]                 # B = bias0 + k1*dT + k2*grad(dT) + k3*dT^2 + k4*T_K + k5*(1 - exp(-t/tau_warm))
//! bias0_dph = 0.05
//! ...
//! [fog_scale_factor]            # output = (1 + sf(T))*rate + bias(T), linear between nodes
//! temps_c = [-40.0, 48.0, 60.0]
//! sf_ppm = [60.0, 192.0, 282.0]
//! bias_dph = [0.1, 0.2, 0.21]
//! sensor_lag_s = 30.0
//! [range]                       # the temperatures the set was fitted over, degC
//! temp_c = [-40.2, 50.1]
//! [fit]                         # optional, informative: where the set came from
//! ```
//!
//! A set whose `[range]` leaves the sensors' -55..+150 degC (a fit on
//! kelvin read as degC) is refused here, so neither the lab nor the
//! build takes it.

use crate::{ScaleFactorTable, ThermalCoeffs};
use serde::{Deserialize, Serialize};
use std::path::Path;

pub const VERSION: u16 = 1;

/// The `[fog_scale_factor]` table as written in the file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ScaleFactorFile {
    pub temps_c: Vec<f64>,
    pub sf_ppm: Vec<f64>,
    pub bias_dph: Vec<f64>,
    pub sensor_lag_s: f64,
}

impl ScaleFactorFile {
    pub fn table(&self) -> ScaleFactorTable {
        ScaleFactorTable::from_nodes(
            &self.temps_c,
            &self.sf_ppm,
            &self.bias_dph,
            self.sensor_lag_s,
        )
    }

    pub fn from_table(t: &ScaleFactorTable) -> Self {
        let n = t.n.min(t.temps_c.len());
        Self {
            temps_c: t.temps_c[..n].to_vec(),
            sf_ppm: t.sf_ppm[..n].to_vec(),
            bias_dph: t.bias_dph[..n].to_vec(),
            sensor_lag_s: t.sensor_lag_s,
        }
    }
}

/// The temperatures a set was fitted over, degC (every sensor it reads).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FittedRange {
    pub temp_c: [f64; 2],
}

/// The range the firmware's temperature sensors read, degC
/// (dsp/src/sensor.rs refuses a reading outside it).
pub const SENSOR_RANGE_C: (f64, f64) = (-55.0, 150.0);

#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct CoeffFile {
    pub kind: String,
    pub version: u16,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub range: Option<FittedRange>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub rlg_thermal: Option<ThermalCoeffs>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub fog_scale_factor: Option<ScaleFactorFile>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub fit: Option<toml::Table>,
}

/// One checked coefficient set.
// The 64-node table makes one variant large; a set is read once per file on
// the host (the firmware holds only the record), so it stays by value.
#[allow(clippy::large_enum_variant)]
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Coeffs {
    RlgThermal(ThermalCoeffs),
    FogScaleFactor(ScaleFactorTable),
}

impl CoeffFile {
    pub fn rlg_thermal(c: ThermalCoeffs, fit: toml::Table) -> Self {
        Self {
            kind: "rlg_thermal".into(),
            version: VERSION,
            range: None,
            rlg_thermal: Some(c),
            fog_scale_factor: None,
            fit: Some(fit),
        }
    }

    pub fn fog_scale_factor(t: &ScaleFactorTable, fit: toml::Table) -> Self {
        Self {
            kind: "fog_scale_factor".into(),
            version: VERSION,
            range: None,
            rlg_thermal: None,
            fog_scale_factor: Some(ScaleFactorFile::from_table(t)),
            fit: Some(fit),
        }
    }
}

/// A coefficient file's text, `comment` as `#` lines before it.
pub fn to_text(f: &CoeffFile, comment: &str) -> Result<String, String> {
    let body = toml::to_string(f).map_err(|e| e.to_string())?;
    let head: String = comment.lines().map(|l| format!("# {l}\n")).collect();
    Ok(format!("{head}{body}"))
}

/// Reads and checks a coefficient file; errors are one line,
/// `file:line:column: message` where the parser knows the place. The
/// values are checked as the firmware checks its record.
pub fn read(path: &Path) -> Result<(CoeffFile, Coeffs), String> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| format!("{}: cannot read: {e}", path.display()))?;
    parse(&text, &path.display().to_string())
}

/// [`read`] of a coefficient file's text; `name` (a path, or what the
/// caller calls the text) starts its errors.
pub fn parse(text: &str, name: &str) -> Result<(CoeffFile, Coeffs), String> {
    let f: CoeffFile = toml::from_str(text).map_err(|e| {
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
    if let Some(r) = &f.range {
        let [lo, hi] = r.temp_c;
        let (min, max) = SENSOR_RANGE_C;
        if !(lo.is_finite() && hi.is_finite() && lo <= hi) {
            return Err(format!(
                "{name}: [range] temp_c = [{lo}, {hi}] is not a range"
            ));
        }
        if lo < min || hi > max {
            let kelvin = if lo - 273.15 >= min && hi - 273.15 <= max {
                format!(
                    " ({:.1}..{:.1} degC if the fit read kelvin as degC: refit with --temp-unit K)",
                    lo - 273.15,
                    hi - 273.15
                )
            } else {
                String::new()
            };
            return Err(format!(
                "{name}: fitted over {lo:.1}..{hi:.1} degC ([range] temp_c), outside the {min}..+{max} degC the firmware's sensors read{kelvin}"
            ));
        }
    }
    let c = match (f.kind.as_str(), &f.rlg_thermal, &f.fog_scale_factor) {
        ("rlg_thermal", Some(c), None) => {
            c.check().map_err(|e| {
                format!("{name}: [rlg_thermal] out of the firmware's range ({e:?}): {c:?}")
            })?;
            Coeffs::RlgThermal(*c)
        }
        ("fog_scale_factor", None, Some(s)) => {
            let n = s.temps_c.len();
            if s.sf_ppm.len() != n || s.bias_dph.len() != n {
                return Err(format!(
                    "{name}: [fog_scale_factor] temps_c, sf_ppm and bias_dph must have the same length ({n}, {}, {})",
                    s.sf_ppm.len(),
                    s.bias_dph.len()
                ));
            }
            let t = s.table();
            t.check().map_err(|e| {
                format!(
                    "{name}: [fog_scale_factor] out of the firmware's range ({e:?}): 1..={} nodes, temperatures increasing by >= {} degC within {}..{} degC, |sf| <= {} ppm, |bias| <= {} deg/h, lag 0..{} s",
                    crate::fog_scale_factor::MAX_NODES,
                    crate::fog_scale_factor::MIN_NODE_GAP_C,
                    crate::fog_scale_factor::T_MIN_C,
                    crate::fog_scale_factor::T_MAX_C,
                    crate::fog_scale_factor::SF_LIMIT_PPM,
                    crate::fog_scale_factor::BIAS_LIMIT_DPH,
                    crate::fog_scale_factor::LAG_LIMIT_S,
                )
            })?;
            Coeffs::FogScaleFactor(t)
        }
        ("rlg_thermal" | "fog_scale_factor", _, _) => {
            return Err(format!(
                "{name}: kind `{}` needs exactly its own table [{}]",
                f.kind, f.kind
            ))
        }
        (k, _, _) => return Err(format!("{name}: unknown coefficient kind `{k}`")),
    };
    Ok((f, c))
}

/// Writes a coefficient file with a comment header, atomically (a
/// temporary file beside it, renamed into place once complete: a crash
/// leaves the old file whole).
pub fn write(path: &Path, f: &CoeffFile, comment: &str) -> Result<(), String> {
    use std::io::Write;
    let text = to_text(f, comment)?;
    let err = |e: std::io::Error| format!("{}: {e}", path.display());
    let name = path
        .file_name()
        .map_or_else(|| "coeffs".into(), |n| n.to_string_lossy().into_owned());
    let tmp = path.with_file_name(format!(".{name}.{}.tmp", std::process::id()));
    let written = (|| {
        let mut file = std::fs::File::create(&tmp)?;
        file.write_all(text.as_bytes())?;
        file.sync_all()?;
        std::fs::rename(&tmp, path)
    })();
    if written.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    written.map_err(err)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn with_range(lo: f64, hi: f64) -> String {
        let dir = std::env::temp_dir().join(format!("gyro-coeffs-range-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let p = dir.join(format!("c-{lo}-{hi}.toml"));
        let mut f = CoeffFile::rlg_thermal(ThermalCoeffs::SAFE, toml::Table::new());
        f.range = Some(FittedRange { temp_c: [lo, hi] });
        write(&p, &f, "test").unwrap();
        match read(&p) {
            Ok(_) => String::new(),
            Err(e) => e,
        }
    }

    /// A set fitted on kelvin read as degC is refused, with the hint; one
    /// inside the sensors' range is taken.
    #[test]
    fn a_set_fitted_outside_the_sensors_range_is_refused() {
        assert_eq!(with_range(-40.0, 50.0), "");
        let e = with_range(241.0, 330.0);
        assert!(
            e.contains("outside the -55..+150 degC") && e.contains("--temp-unit K"),
            "{e}"
        );
        assert!(!with_range(-80.0, 20.0).is_empty());
    }
}
