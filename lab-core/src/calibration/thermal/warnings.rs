//! What an RLG thermal fit warns about: a term the run cannot resolve
//! because its regressor's span (or rate) is too narrow, a residual above
//! the run's noise floor.

use super::fit::ThermalData;
use crate::calibration::warning::Warning;
use crate::numerics::thermal_difference::dt_and_gradient;
use gyro_sp::rlg::ThermalCoeffs;

/// A residual this many times the noise floor (beyond twice the standard
/// error of the difference) is warned about.
pub const RESIDUAL_OVER_FLOOR: f64 = 1.5;

fn span(v: &[f64]) -> f64 {
    let (lo, hi) = v
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| {
            (a.min(*x), b.max(*x))
        });
    hi - lo
}

/// Each term whose 95 % interval holds 0: the run does not resolve it, and
/// says why (its regressor's span on this run).
pub fn unresolved_terms(d: &ThermalData, c: &ThermalCoeffs, se: &ThermalCoeffs) -> Vec<Warning> {
    let (dts, grads) = dt_and_gradient(&d.t, &d.a, &d.b);
    let dt2: Vec<f64> = dts.iter().map(|x| x * x).collect();
    let run_s = d.t.last().copied().unwrap_or(0.0) - d.t.first().copied().unwrap_or(0.0);
    let terms = [
        (
            "K1 (dT)",
            c.k1_dph_per_c,
            se.k1_dph_per_c,
            span(&dts),
            "dT = T_a - T_b spans only {s} degC",
        ),
        (
            "K2 (grad dT)",
            c.k2_dph_per_c_per_s,
            se.k2_dph_per_c_per_s,
            span(&grads),
            "grad(dT) spans only {s} degC/s: the chamber's rate set is too narrow",
        ),
        (
            "K3 (dT^2)",
            c.k3_dph_per_c2,
            se.k3_dph_per_c2,
            span(&dt2),
            "dT^2 spans only {s} degC^2",
        ),
        (
            "K4 (case temperature T_K, degC)",
            c.k4_dph_per_c,
            se.k4_dph_per_c,
            span(&d.case),
            "the case temperature spans only {s} degC",
        ),
        (
            "K5 (warm-up)",
            c.k5_dph,
            se.k5_dph,
            run_s / c.tau_warm_s.max(1.0),
            "the run covers {s} warm-up time constants",
        ),
    ];
    terms
        .iter()
        // Not resolved: the interval holds 0, or the figures are not numbers.
        .filter(|t| t.1.abs().partial_cmp(&(1.96 * t.2)) != Some(std::cmp::Ordering::Greater))
        .map(|&(name, v, e, s, why)| {
            let s = if s.abs() >= 1e-3 && s.abs() < 1e4 {
                format!("{s:.3}")
            } else {
                format!("{s:.2e}")
            };
            Warning::new(
                "term_not_resolved",
                format!(
                    "{name} is not resolved: {v:.4} +- {:.4} (95 %) holds 0, because {}; its value \
                     is a guess outside what this run saw",
                    1.96 * e,
                    why.replace("{s}", &s)
                ),
            )
        })
        .collect()
}

/// The residual above the noise floor: the model misses a thermal effect.
pub fn residual(res: f64, res_se: f64, floor: f64, floor_se: f64) -> Option<Warning> {
    let excess = res - RESIDUAL_OVER_FLOOR * floor;
    (excess > 2.0 * res_se.hypot(RESIDUAL_OVER_FLOOR * floor_se)).then(|| {
        Warning::new(
            "residual_above_noise",
            format!(
                "the residual drift ({res:.4} deg/h, std of 100 s means) is {:.1} times the noise floor \
                 ({floor:.4} deg/h): the model misses part of the thermal drift",
                res / floor
            ),
        )
    })
}
