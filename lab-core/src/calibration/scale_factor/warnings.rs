//! What a scale-factor fit warns about: a knee near the edge of the
//! calibrated range, a rate set or temperature span too narrow for a term,
//! a residual above the run's noise floor, a table that could not hold the
//! model to its tolerance.

use super::input::SfInput;
use super::result::Est;
use crate::calibration::warning::Warning;

/// A knee closer than this to an end of the calibrated range is warned
/// about: the segment beyond it is short, so its slope change rests on few
/// degrees (and curvature at the end can pass for a knee), degC.
pub const KNEE_EDGE_C: f64 = 6.0;
/// A residual this many times the noise floor (beyond twice its standard
/// error) is warned about.
pub const RESIDUAL_OVER_FLOOR: f64 = 2.0;
/// Smallest calibrated span for the curvature terms and knees, degC.
pub const MIN_SHAPE_SPAN_C: f64 = 30.0;

/// A knee near an end of `range`.
pub fn knee_near_edge(knee: f64, range: [f64; 2]) -> Option<Warning> {
    let d = (knee - range[0]).min(range[1] - knee);
    (d < KNEE_EDGE_C).then(|| {
        Warning::new(
            "knee_near_edge",
            format!(
                "the knee at {knee:.2} degC is {d:.1} degC from the end of the calibrated range \
                 ({:.1} .. {:.1} degC): its slope change rests on a short segment, and curvature \
                 at the end of the range can pass for a knee; extend the sweep past it",
                range[0], range[1]
            ),
        )
    })
}

/// The table rates' signs and magnitudes: one sign leaves the bias in the
/// scale factor.
pub fn rate_set(inp: &SfInput, with_bias: bool) -> Option<Warning> {
    if with_bias {
        return None;
    }
    let w = inp
        .w
        .iter()
        .copied()
        .filter(|w| w.abs() >= super::input::MIN_RATE_DPS)
        .fold(0.0f64, |a, w| a.max(w.abs()));
    Some(Warning::new(
        "rate_set_one_sign",
        format!(
            "the table turned one way only ({w:.0} deg/s): the bias term cannot be told from the \
             scale factor, so the table's scale factor carries bias/rate (0.1 deg/h is {:.2} ppm \
             at this rate); reverse the table during the sweep",
            0.1 / 3600.0 / w.max(1e-9) * 1e6
        ),
    ))
}

/// The coil temperature's rate of change takes one sign only: the sensor
/// lag cannot be told from an offset of the curve in temperature.
pub fn temperature_rate_set(d: &[f64], lag_ci_width_s: f64) -> Option<Warning> {
    let up = d.iter().filter(|&&x| x > 1e-3).count();
    let down = d.iter().filter(|&&x| x < -1e-3).count();
    let n = d.len().max(1);
    let one_way = up.min(down) * 20 < n;
    (one_way || lag_ci_width_s > 60.0).then(|| {
        Warning::new(
            "temperature_rate_one_sign",
            format!(
                "the chamber ramped {} only: the coil sensor's lag (95 % interval {lag_ci_width_s:.0} s \
                 wide) is barely told from a shift of the curve in temperature; sweep both ways",
                if up >= down { "up" } else { "down" }
            ),
        )
    })
}

/// A span too short for the curve's shape.
pub fn span(range: [f64; 2]) -> Option<Warning> {
    let s = range[1] - range[0];
    (s < MIN_SHAPE_SPAN_C).then(|| {
        Warning::new(
            "span_narrow",
            format!(
                "the calibrated span is {s:.1} degC: curvature and knees need at least \
                 {MIN_SHAPE_SPAN_C} degC to be told apart; outside it the table holds its end values"
            ),
        )
    })
}

/// The residual above the noise floor: the model misses something.
pub fn residual(res: Est, floor: Est) -> Option<Warning> {
    let excess = res.value - RESIDUAL_OVER_FLOOR * floor.value;
    (excess > 2.0 * res.se.hypot(RESIDUAL_OVER_FLOOR * floor.se)).then(|| {
        Warning::new(
            "residual_above_noise",
            format!(
                "the residual ({:.3} ppm) is {:.1} times the noise floor ({:.3} ppm): the model \
                 misses part of the scale factor's temperature dependence (more knees than {}, \
                 hysteresis, or a coil-sensor lag that is not first order)",
                res.value,
                res.value / floor.value,
                floor.value,
                super::continuous_model::MAX_KNEES,
            ),
        )
    })
}

/// A table that could not hold the model within its tolerance.
pub fn tabulation(max_error_ppm: f64, limit_ppm: f64) -> Option<Warning> {
    (max_error_ppm > limit_ppm).then(|| {
        Warning::new(
            "tabulation_error",
            format!(
                "the firmware's table departs from the model by up to {max_error_ppm:.3} ppm \
                 (more than {limit_ppm} ppm): the model's curvature needs more nodes than the \
                 table holds"
            ),
        )
    })
}

/// The criterion fell at the most knees tried: the model may lack more.
pub fn knee_cap(knees: usize) -> Option<Warning> {
    (knees >= super::continuous_model::MAX_KNEES).then(|| {
        Warning::new(
            "knee_count_at_cap",
            format!(
                "the criterion chose the most knees tried ({knees}): the curve may hold more \
                 structure than the families express"
            ),
        )
    })
}
