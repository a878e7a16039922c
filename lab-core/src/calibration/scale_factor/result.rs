//! What a scale-factor fit gives: the model family chosen and the
//! criterion of each, the knees with their intervals, the polynomial, the
//! linear segments of K_SF(T), the table the firmware loads with its
//! tabulation error, the figures that say how well it holds and the
//! warnings.

use super::families::{Family, FamilyBest, Scored};
use super::tabulate::Tabulation;
use crate::calibration::warning::Warning;
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

/// The polynomial part of s(T): `sum_k c_k (T - t_ref)^k`, k = 0..=degree,
/// `c_k` in ppm/degC^k with standard errors (the knees' hinges add to it).
#[derive(Clone, Debug, serde::Serialize)]
pub struct Polynomial {
    pub t_ref_c: f64,
    pub coef_ppm: Vec<Est>,
}

/// The fitted continuous model, for evaluating it (plots, residuals):
/// `s(T) = sum_k coef[k] x^k + sum_j coef[degree + 1 + j] max(0, T - knee_j)`
/// (relative), x = T - t_ref; bias `b0 + b1 x` deg/s where fitted.
#[derive(Clone, Debug)]
pub struct SfCurve {
    pub degree: usize,
    pub knees: Vec<f64>,
    pub t_ref_c: f64,
    pub coef: Vec<f64>,
    pub bias: Option<(f64, f64)>,
}

impl SfCurve {
    /// Scale-factor error at `t_c`, ppm.
    pub fn sf_ppm(&self, t_c: f64) -> f64 {
        let x = t_c - self.t_ref_c;
        let mut s = 0.0;
        for k in (0..=self.degree).rev() {
            s = s * x + self.coef.get(k).copied().unwrap_or(0.0);
        }
        for (j, kn) in self.knees.iter().enumerate() {
            s += self.coef.get(self.degree + 1 + j).copied().unwrap_or(0.0) * (t_c - kn).max(0.0);
        }
        s * 1e6
    }

    /// Bias at `t_c`, deg/s (0 where the run could not separate it).
    pub fn bias_dps(&self, t_c: f64) -> f64 {
        self.bias
            .map_or(0.0, |(b0, b1)| b0 + b1 * (t_c - self.t_ref_c))
    }
}

#[derive(Clone, Debug, serde::Serialize)]
pub struct SfFit {
    pub method: FitMethod,
    /// The family chosen by the criterion, and its polynomial degree
    /// (0 for knees on straight lines).
    pub model: Family,
    pub degree: usize,
    pub knees: Vec<Interval>,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub polynomial: Option<Polynomial>,
    pub segments: Vec<Segment>,
    #[serde(skip)]
    pub table: ScaleFactorTable,
    /// Coil sensor lag behind the coil, s (continuous runs).
    pub sensor_lag_s: Option<Interval>,
    pub bias: Option<BiasModel>,
    /// IEEE 952 terms where the run has the rates for them, ppm.
    pub asymmetry_ppm: Option<Est>,
    pub nonlinearity_ppm: Option<Est>,
    /// BIC for 0, 1, ... knees at the chosen polynomial degree (1 for
    /// the knees family; lower is better).
    pub bic: Vec<f64>,
    /// The criterion of every model tried (family, degree, knee count).
    pub criteria: Vec<Scored>,
    /// The best model of each family, and by how much the chosen one beat
    /// the best of the others (BIC difference, positive).
    pub families: Vec<FamilyBest>,
    pub criterion_margin: f64,
    /// Residual variance inflation for correlated noise (1 = white).
    pub noise_inflation: f64,
    /// RMS of the fit's scale-factor residual over 60 s means, ppm, and
    /// its standard error (in the JSON as `residual_ppm` and
    /// `residual_ppm_se`, numbers, by the command).
    #[serde(skip)]
    pub residual_ppm: Est,
    /// What white rate noise alone leaves in 60 s means, ppm (from the
    /// scatter of consecutive 10 s means of the residual).
    pub noise_floor_ppm: Est,
    /// The table as the firmware holds it against the fitted model.
    pub tabulation: Tabulation,
    /// Calibrated coil-temperature range, degC.
    pub range_c: [f64; 2],
    pub rows_used: usize,
    /// Run length, s.
    pub duration_s: f64,
    pub notes: Vec<String>,
    pub warnings: Vec<Warning>,
    #[serde(skip)]
    pub curve: Option<SfCurve>,
}
