//! What a scale-factor fit gives: the knees with their intervals, the
//! linear segments of K_SF(T), the table the firmware loads, and the
//! figures that say how well it holds.

use gyro_coeffs::fog_scale_factor::{ScaleFactorTable, MAX_NODES};

/// A value with its 95 % interval.
#[derive(Clone, Copy, Debug, serde::Serialize)]
pub struct Interval {
    pub value: f64,
    pub lo: f64,
    pub hi: f64,
}

/// A value with its standard error.
#[derive(Clone, Copy, Debug, serde::Serialize)]
pub struct Est {
    pub value: f64,
    pub se: f64,
}

/// One linear piece of the scale factor: `K_SF(T) = k0 + k_t*T` (relative
/// to nominal, so 1 is the nominal scale factor) from `from_c` to `to_c`.
#[derive(Clone, Copy, Debug, serde::Serialize)]
pub struct Segment {
    pub from_c: f64,
    pub to_c: f64,
    pub k0: f64,
    pub k_t: f64,
    pub k0_se: f64,
    pub k_t_se: f64,
    /// The same in ppm: k0 - 1 and k_t, with standard errors.
    pub k0_ppm: f64,
    pub k_t_ppm_per_c: f64,
}

#[derive(Clone, Copy, Debug, serde::Serialize)]
pub struct BiasModel {
    /// Bias at 20 degC, deg/h, and its temperature slope, deg/h/degC.
    pub at_20c_dph: Est,
    pub slope_dph_per_c: Est,
}

/// Which calibration a run is: it decides the fit.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
pub enum FitMethod {
    /// Constant rates while the chamber sweeps.
    #[serde(rename = "continuous")]
    Continuous,
    /// Temperature plateaus, each with a rate sequence.
    #[serde(rename = "multi-point")]
    MultiPoint,
}

impl FitMethod {
    pub fn name(self) -> &'static str {
        match self {
            FitMethod::Continuous => "continuous",
            FitMethod::MultiPoint => "multi-point",
        }
    }
}

impl std::fmt::Display for FitMethod {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// Why a run could not be fitted.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum SfFitError {
    /// More temperature plateaus than the table has nodes.
    TooManyPlateaus(usize),
    /// A plateau's rate sequence could not be fitted.
    Plateau,
    /// The continuous model is singular on this run.
    Singular,
}

impl std::fmt::Display for SfFitError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            SfFitError::TooManyPlateaus(n) => write!(
                f,
                "{n} temperature plateaus: the table holds at most {MAX_NODES}"
            ),
            SfFitError::Plateau => f.write_str("a plateau's rate sequence could not be fitted"),
            SfFitError::Singular => {
                f.write_str("the scale-factor model could not be fitted (singular data)")
            }
        }
    }
}

#[derive(Clone, Debug, serde::Serialize)]
pub struct SfFit {
    pub method: FitMethod,
    pub knees: Vec<Interval>,
    pub segments: Vec<Segment>,
    #[serde(skip)]
    pub table: ScaleFactorTable,
    /// Coil sensor lag behind the coil, s (continuous runs).
    pub sensor_lag_s: Option<Interval>,
    pub bias: Option<BiasModel>,
    /// IEEE 952 terms where the run has the rates for them, ppm.
    pub asymmetry_ppm: Option<Est>,
    pub nonlinearity_ppm: Option<Est>,
    /// BIC for 0, 1, ... knees (lower is better).
    pub bic: Vec<f64>,
    /// Residual variance inflation for correlated noise (1 = white).
    pub noise_inflation: f64,
    /// RMS of the fit's scale-factor residual over 60 s means, ppm, and
    /// its standard error.
    pub residual_ppm: Est,
    /// Calibrated coil-temperature range, degC.
    pub range_c: [f64; 2],
    pub rows_used: usize,
    pub notes: Vec<String>,
}
