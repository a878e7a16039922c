//! `allan.csv` of `allan --out` (docs/interfaces.md): the measured Allan
//! deviation per averaging time with its 95 % interval, the equivalent
//! degrees of freedom, the dominant noise type and the fitted model.

use crate::error::LabError;
use crate::report::text::sig;
use std::io::Write;
use std::path::Path;

/// The columns of allan.csv.
pub const COLUMNS: [&str; 7] = [
    "tau_s",
    "adev_dph",
    "adev_lo_dph",
    "adev_hi_dph",
    "edf",
    "noise_type",
    "model_adev_dph",
];

/// One averaging time's row (deviations in deg/h).
pub struct AllanRow<'a> {
    pub tau_s: f64,
    pub adev_dph: f64,
    pub adev_lo_dph: f64,
    pub adev_hi_dph: f64,
    pub edf: f64,
    pub noise_type: &'a str,
    pub model_adev_dph: f64,
}

pub fn write(path: &Path, rows: &[AllanRow]) -> Result<(), LabError> {
    let io = |e: std::io::Error| LabError::io(path, e);
    let mut w = super::atomic::AtomicFile::create(path)?;
    writeln!(w, "{}", COLUMNS.join(",")).map_err(io)?;
    for r in rows {
        writeln!(
            w,
            "{},{:.6e},{:.6e},{:.6e},{:.4},{},{:.6e}",
            sig(r.tau_s),
            r.adev_dph,
            r.adev_lo_dph,
            r.adev_hi_dph,
            r.edf,
            r.noise_type,
            r.model_adev_dph
        )
        .map_err(io)?;
    }
    w.commit()
}
