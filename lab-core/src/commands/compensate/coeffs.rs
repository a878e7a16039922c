//! The coefficient sets `compensate` applies, read from a file's text.

use crate::calibration::thermal::summary::CalibratedRange;
use crate::commands::model_file::{model_from_text, ModelFile};
use crate::error::LabError;
use crate::model::gyro_kind::GyroKind;
use gyro_coeffs::file::Coeffs;
use gyro_coeffs::ScaleFactorTable;
use gyro_sp::rlg::ThermalCoeffs;

/// The kinds of file `compensate` applies.
pub const KINDS: &str =
    "rlg_thermal or fog_scale_factor (from gyro-lab fit), gyro_model (from gyro-lab discover)";

/// A coefficient set, by its kind.
pub enum CoeffSet {
    /// RLG thermal coefficients, with the temperatures the fit saw.
    RlgThermal(ThermalCoeffs, Option<CalibratedRange>),
    FogScaleFactor(Box<ScaleFactorTable>),
    /// A model from `discover`.
    Model(Box<ModelFile>, GyroKind),
}

/// Reads a coefficient set from its file's text; `name` (a path, or what
/// the caller calls the text) places its errors.
pub fn read_coeffs(text: &str, name: &str) -> Result<CoeffSet, LabError> {
    if kind_of(text).as_deref() == Some("gyro_model") {
        let gyro = toml::from_str::<toml::Table>(text)
            .ok()
            .and_then(|t| t.get("gyro")?.as_str().and_then(GyroKind::from_name))
            .ok_or_else(|| {
                LabError::input(name, "a gyro_model needs `gyro = \"fog\"|\"rlg\"|\"mems\"`")
            })?;
        let m = model_from_text(text.to_owned(), name, gyro)?;
        return Ok(CoeffSet::Model(Box::new(m), gyro));
    }
    let (file, coeffs) = gyro_coeffs::file::parse(text, name).map_err(|e| {
        let e = if e.contains("unknown coefficient kind") {
            format!("{e}: compensate applies {KINDS}")
        } else {
            e
        };
        LabError::coeffs_input(name, &e)
    })?;
    Ok(match coeffs {
        Coeffs::RlgThermal(c) => CoeffSet::RlgThermal(c, file.fit.as_ref().and_then(thermal_range)),
        Coeffs::FogScaleFactor(t) => CoeffSet::FogScaleFactor(Box::new(t)),
    })
}

/// The `kind` a TOML file declares, if it reads as TOML and has one.
fn kind_of(text: &str) -> Option<String> {
    let t: toml::Table = toml::from_str(text).ok()?;
    t.get("kind")?.as_str().map(str::to_owned)
}

/// The temperatures a thermal fit saw, from its file's `[fit]` table
/// (files written before they were kept there have none).
fn thermal_range(fit: &toml::Table) -> Option<CalibratedRange> {
    let pair = |k: &str| -> Option<[f64; 2]> {
        let v = fit.get(k)?.as_array()?;
        let f = |i: usize| {
            v.get(i)
                .and_then(|x| x.as_float().or(x.as_integer().map(|n| n as f64)))
        };
        Some([f(0)?, f(1)?])
    };
    Some(CalibratedRange {
        mono_a_c: pair("mono_a_range_c")?,
        case_c: pair("case_range_c")?,
    })
}
