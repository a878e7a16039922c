//! A thermal calibration and a compensation judged as docs/rlg.md does:
//! the scatter of 100 s means of the drift before and after, against the
//! run's own noise floor, each with its standard error.

use super::figures::{noise_floor_100s, std_of_means, std_se};
use super::fit::{coefficient_se, fit_thermal, CubicModel, ThermalData};
use super::warnings;
use crate::calibration::scale_factor::validation::{flag_spans, FlagSpan};
use crate::calibration::warning::Warning;
use gyro_coeffs::rlg_thermal::COEFF_LIMIT;
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
    /// Rows and run length, s; the ranges of the monoblock sensor A and
    /// the case sensor, degC.
    pub rows: usize,
    pub duration_s: f64,
    pub mono_a_range_c: [f64; 2],
    pub case_range_c: [f64; 2],
    pub warnings: Vec<Warning>,
    /// The improved model's residual and the cubic's, per row, deg/h.
    #[serde(skip)]
    pub residual_dph: Vec<f64>,
    #[serde(skip)]
    pub cubic_residual_dph: Vec<f64>,
}

/// Why a chamber run gives no coefficients the firmware takes.
#[derive(Debug)]
pub enum ThermalFitError {
    Singular,
    /// The run is too short for the model's time terms (the warm-up's
    /// time constants start at 30 s): its length and the temperature spans
    /// it saw.
    TooShort {
        duration_s: f64,
        span_mono_c: f64,
        span_case_c: f64,
    },
    OutOfRange(CoeffError, ThermalCoeffs),
    Cubic,
}

/// What a user can do about a run that does not determine the model.
const WHAT_TO_DO: &str = "fit on a chamber run that sweeps the temperature over \
                          hours and tens of degC (e.g. `gyro-lab simulate chamber --profile cycle`)";

/// The shortest run a fit is tried on: twenty times the shortest warm-up
/// time constant searched. (A long run at one temperature is fitted, and
/// its report says which terms it could not resolve.)
const MIN_DURATION_S: f64 = 600.0;

impl std::fmt::Display for ThermalFitError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            ThermalFitError::Singular => write!(
                f,
                "the thermal model could not be fitted: its terms are collinear on this run; {WHAT_TO_DO}"
            ),
            ThermalFitError::TooShort {
                duration_s,
                span_mono_c,
                span_case_c,
            } => write!(
                f,
                "too short to fit: {duration_s:.1} s (at least {MIN_DURATION_S:.0} s), with the \
                 monoblock over {span_mono_c:.2} degC and the case over {span_case_c:.2} degC; {WHAT_TO_DO}"
            ),
            ThermalFitError::OutOfRange(_, c) => {
                let names = ThermalCoeffs::NAMES;
                let v = c.values();
                let worst = (0..6)
                    .max_by(|&i, &j| v[i].abs().total_cmp(&v[j].abs()))
                    .unwrap_or(0);
                write!(
                    f,
                    "the fitted coefficients are outside what the firmware holds ({} = {:.3e}, \
                     limit +-{COEFF_LIMIT:.0e}): this run does not determine the thermal model; {WHAT_TO_DO}",
                    names[worst], v[worst]
                )
            }
            ThermalFitError::Cubic => {
                write!(f, "the classic cubic could not be fitted on this run; {WHAT_TO_DO}")
            }
        }
    }
}

/// Smallest and largest of `v`.
pub fn range(v: &[f64]) -> [f64; 2] {
    v.iter()
        .fold([f64::INFINITY, f64::NEG_INFINITY], |[a, b], x| {
            [a.min(*x), b.max(*x)]
        })
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
    let span = |v: &[f64]| {
        let [lo, hi] = range(v);
        hi - lo
    };
    let duration_s = d.t.last().copied().unwrap_or(0.0) - d.t.first().copied().unwrap_or(0.0);
    let (span_mono_c, span_case_c) = (span(&d.a).max(span(&d.b)), span(&d.case));
    if duration_s < MIN_DURATION_S {
        return Err(ThermalFitError::TooShort {
            duration_s,
            span_mono_c,
            span_case_c,
        });
    }
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
    let se = coefficient_se(d, &c);
    let std_se_v = stds.map(|x| std_se(x, &d.t, WINDOW_S));
    let mut warns = se
        .as_ref()
        .map_or_else(Vec::new, |e| warnings::unresolved_terms(d, &c, e));
    warns.extend(warnings::residual(
        stds[1],
        std_se_v[1],
        stds[3],
        std_se_v[3],
    ));
    Ok(FitSummary {
        coefficients: c,
        coefficient_se: se,
        raw_std_100s_dph: stds[0],
        residual_std_100s_dph: stds[1],
        cubic_std_100s_dph: stds[2],
        noise_floor_100s_dph: stds[3],
        std_100s_se_dph: std_se_v,
        cubic,
        rows: d.t.len(),
        mono_a_range_c: range(&d.a),
        case_range_c: range(&d.case),
        duration_s: d.t.last().copied().unwrap_or(0.0) - d.t.first().copied().unwrap_or(0.0),
        warnings: warns,
        residual_dph: resid,
        cubic_residual_dph: cubic_res,
    })
}

/// The temperatures a thermal fit saw (its coefficient file's `[fit]`
/// table keeps them): monoblock sensor A and the case sensor, degC.
#[derive(Clone, Copy, Debug, serde::Serialize)]
pub struct CalibratedRange {
    pub mono_a_c: [f64; 2],
    pub case_c: [f64; 2],
}

/// A run this far outside the calibrated range is warned about, degC.
pub const OUT_OF_RANGE_MARGIN_C: f64 = 0.5;

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
    pub rows: usize,
    pub duration_s: f64,
    /// The fit's temperatures (null when the coefficient file does not
    /// state them) and the spans of this run outside them by more than
    /// [`OUT_OF_RANGE_MARGIN_C`] (`min_c`, `max_c`: monoblock sensor A).
    pub calibrated_range: Option<CalibratedRange>,
    pub out_of_range_spans: Vec<FlagSpan>,
    pub warnings: Vec<Warning>,
    /// The compensated drift per row, deg/h.
    #[serde(skip)]
    pub comp_drift_dph: Vec<f64>,
}

/// The rows' spans outside `r` (by more than the margin) on either sensor.
fn outside(d: &ThermalData, r: &CalibratedRange) -> Vec<FlagSpan> {
    let out = |x: f64, [lo, hi]: [f64; 2]| {
        x < lo - OUT_OF_RANGE_MARGIN_C || x > hi + OUT_OF_RANGE_MARGIN_C
    };
    let flags: Vec<u8> =
        d.a.iter()
            .zip(&d.case)
            .map(|(&a, &k)| u8::from(out(a, r.mono_a_c) || out(k, r.case_c)))
            .collect();
    flag_spans(&d.t, &flags, 1, &d.a)
}

fn outside_warning(spans: &[FlagSpan], r: &CalibratedRange) -> Option<Warning> {
    if spans.is_empty() {
        return None;
    }
    let secs: f64 = spans.iter().map(|s| s.to_s - s.from_s).sum();
    let (lo, hi) = spans
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), s| {
            (a.min(s.min_c), b.max(s.max_c))
        });
    Some(Warning::new(
        "outside_calibrated_range",
        format!(
            "{secs:.0} s of the run in {} span(s) lay outside the temperatures the fit saw \
             (monoblock A {:.1} .. {:.1} degC, case {:.1} .. {:.1} degC; here monoblock A {lo:.1} .. \
             {hi:.1} degC): the model is extrapolated there",
            spans.len(),
            r.mono_a_c[0],
            r.mono_a_c[1],
            r.case_c[0],
            r.case_c[1]
        ),
    ))
}

/// The figures of a compensated run: `comp` its compensated rate (deg/s),
/// `flags` the sensor flags of each row, `cubic` a classic cubic fitted on
/// another run (for comparison only), `range` the temperatures the fit saw.
pub fn compensation_summary(
    c: &ThermalCoeffs,
    d: &ThermalData,
    ref_rate_dps: &[f64],
    (comp, flags): (&[f64], &[u8]),
    cubic: Option<&CubicModel>,
    range: Option<CalibratedRange>,
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
    let (comp_se, floor_se) = (
        std_se(comp_std, &d.t, WINDOW_S),
        std_se(floor, &d.t, WINDOW_S),
    );
    let refused = c.check().is_err();
    let flags_seen = flags.iter().fold(0, |x, f| x | f);
    let mut warns: Vec<Warning> = warnings::residual(comp_std, comp_se, floor, floor_se)
        .into_iter()
        .collect();
    if refused {
        warns.push(Warning::new(
            "coeffs_refused",
            "the firmware's check refused the coefficients: the run was not compensated".into(),
        ));
    }
    let spans = range.as_ref().map_or_else(Vec::new, |r| outside(d, r));
    if let Some(r) = &range {
        warns.extend(outside_warning(&spans, r));
    }
    if flags_seen != 0 {
        warns.push(Warning::new(
            "sensor_flagged",
            format!(
                "temperature sensor flags {flags_seen:#04x} were raised: a flagged sensor's last good \
                 value was held"
            ),
        ));
    }
    CompensateSummary {
        raw_std_100s_dph: raw_std,
        comp_std_100s_dph: comp_std,
        noise_floor_100s_dph: floor,
        raw_std_100s_se_dph: std_se(raw_std, &d.t, WINDOW_S),
        comp_std_100s_se_dph: comp_se,
        noise_floor_100s_se_dph: floor_se,
        comp_over_floor: comp_std / floor,
        cubic_std_100s_dph: cubic_std,
        coeffs_refused: refused,
        sensor_flags_seen: flags_seen,
        rows: d.t.len(),
        duration_s: d.t.last().copied().unwrap_or(0.0) - d.t.first().copied().unwrap_or(0.0),
        calibrated_range: range,
        out_of_range_spans: spans,
        warnings: warns,
        comp_drift_dph: comp_drift,
    }
}
