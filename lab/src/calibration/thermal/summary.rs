//! A thermal calibration and a compensation judged as docs/rlg.md does:
//! the scatter of 100 s means of the drift before and after, against the
//! run's own noise floor, each with its standard error.

use super::figures::{noise_floor_100s, std_of_means, std_se};
use super::fit::{coefficient_se, fit_thermal, CubicModel, ThermalData};
use gyro_sp::rlg::{CoeffError, ThermalCoeffs};

/// The averaging of the drift figures, s.
pub const WINDOW_S: f64 = 100.0;

#[derive(Debug, serde::Serialize)]
pub struct FitSummary {
    pub coefficients: ThermalCoeffs,
    /// Their standard errors (residual correlation included; see fit.rs).
    pub coefficient_se: Option<ThermalCoeffs>,
    /// Standard deviation of 100 s means, deg/h: raw drift, after the
    /// improved model (float fit), after the classic one-sensor cubic.
    pub raw_std_100s_dph: f64,
    pub residual_std_100s_dph: f64,
    pub cubic_std_100s_dph: f64,
    pub noise_floor_100s_dph: f64,
    /// Standard error of each standard deviation above (same order).
    pub std_100s_se_dph: [f64; 4],
    pub cubic: CubicModel,
}

/// Why a chamber run gives no coefficients the firmware takes.
#[derive(Debug)]
pub enum ThermalFitError {
    Singular,
    OutOfRange(CoeffError, ThermalCoeffs),
    Cubic,
}

impl std::fmt::Display for ThermalFitError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            ThermalFitError::Singular => {
                f.write_str("the thermal model could not be fitted (singular data)")
            }
            ThermalFitError::OutOfRange(e, c) => write!(
                f,
                "fitted coefficients out of the firmware's range ({e:?}): {c:?}"
            ),
            ThermalFitError::Cubic => f.write_str("cubic fit failed"),
        }
    }
}

/// The drift of a run after the classic cubic `m` on the sensor A.
pub fn cubic_residual(m: &CubicModel, d: &ThermalData) -> Vec<f64> {
    d.drift_dph
        .iter()
        .zip(&d.a)
        .map(|(y, t)| y - m.eval(*t))
        .collect()
}

/// The improved model fitted on a chamber run, checked against the
/// firmware's ranges, next to the classic cubic.
pub fn calibrate(d: &ThermalData) -> Result<FitSummary, ThermalFitError> {
    let (c, resid) = fit_thermal(d).ok_or(ThermalFitError::Singular)?;
    c.check().map_err(|e| ThermalFitError::OutOfRange(e, c))?;
    let cubic = CubicModel::fit(&d.a, &d.drift_dph).ok_or(ThermalFitError::Cubic)?;
    let cubic_res = cubic_residual(&cubic, d);
    let stds = [
        std_of_means(&d.t, &d.drift_dph, WINDOW_S),
        std_of_means(&d.t, &resid, WINDOW_S),
        std_of_means(&d.t, &cubic_res, WINDOW_S),
        noise_floor_100s(&d.t, &d.drift_dph),
    ];
    Ok(FitSummary {
        coefficients: c,
        coefficient_se: coefficient_se(d, &c),
        raw_std_100s_dph: stds[0],
        residual_std_100s_dph: stds[1],
        cubic_std_100s_dph: stds[2],
        noise_floor_100s_dph: stds[3],
        std_100s_se_dph: stds.map(|x| std_se(x, &d.t, WINDOW_S)),
        cubic,
    })
}

#[derive(Debug, serde::Serialize)]
pub struct CompensateSummary {
    pub raw_std_100s_dph: f64,
    pub comp_std_100s_dph: f64,
    pub noise_floor_100s_dph: f64,
    /// Standard errors of the three figures above.
    pub raw_std_100s_se_dph: f64,
    pub comp_std_100s_se_dph: f64,
    pub noise_floor_100s_se_dph: f64,
    /// comp / noise floor.
    pub comp_over_floor: f64,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub cubic_std_100s_dph: Option<f64>,
    pub coeffs_refused: bool,
    pub sensor_flags_seen: u8,
}

/// The figures of a compensated run: `comp` its compensated rate (deg/s),
/// `flags` the sensor flags of each row, `cubic` a classic cubic fitted on
/// another run (for comparison only).
pub fn compensation_summary(
    c: &ThermalCoeffs,
    d: &ThermalData,
    ref_rate_dps: &[f64],
    (comp, flags): (&[f64], &[u8]),
    cubic: Option<&CubicModel>,
) -> CompensateSummary {
    let comp_drift: Vec<f64> = comp
        .iter()
        .zip(ref_rate_dps)
        .map(|(r, w)| (r - w) * 3600.0)
        .collect();
    let floor = noise_floor_100s(&d.t, &d.drift_dph);
    let comp_std = std_of_means(&d.t, &comp_drift, WINDOW_S);
    let cubic_std = cubic.map(|m| std_of_means(&d.t, &cubic_residual(m, d), WINDOW_S));
    let raw_std = std_of_means(&d.t, &d.drift_dph, WINDOW_S);
    CompensateSummary {
        raw_std_100s_dph: raw_std,
        comp_std_100s_dph: comp_std,
        noise_floor_100s_dph: floor,
        raw_std_100s_se_dph: std_se(raw_std, &d.t, WINDOW_S),
        comp_std_100s_se_dph: std_se(comp_std, &d.t, WINDOW_S),
        noise_floor_100s_se_dph: std_se(floor, &d.t, WINDOW_S),
        comp_over_floor: comp_std / floor,
        cubic_std_100s_dph: cubic_std,
        coeffs_refused: c.check().is_err(),
        sensor_flags_seen: flags.iter().fold(0, |x, f| x | f),
    }
}
