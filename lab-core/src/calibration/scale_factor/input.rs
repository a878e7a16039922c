//! A run as the scale-factor fits take it: the reference and output rates
//! with the coil temperature estimated from the coil sensor by the
//! firmware's own blocks (its sensor hold), differentiated for the fit.

use gyro_coeffs::fog_scale_factor::ScaleFactorTable;
use gyro_sp::fog::scale_factor::{ScaleFactorComp, ScaleFactorConfig, LEAD_FILTER_TAU_S};
use gyro_sp::fog::{FogConfig, FogParams};

/// Rows with |reference rate| below this are at rest, deg/s.
pub const MIN_RATE_DPS: f64 = 1.0;
/// Smallest temperature span over the rotating rows, degC.
pub const MIN_SPAN_C: f64 = 10.0;

/// The run's inputs, the coil sensor taken through the firmware's blocks.
pub struct SfInput {
    pub t: Vec<f64>,
    pub w: Vec<f64>,
    pub y: Vec<f64>,
    /// Coil sensor value in use (held while bad), degC.
    pub ts: Vec<f64>,
    /// Its filtered derivative, degC/s.
    pub d: Vec<f64>,
}

/// Runs the coil sensor of a run through the firmware's sensor hold (as
/// `ScaleFactorComp` does at each sensor update) and differentiates it for
/// the fit. The fit, unlike the firmware, may look ahead: the derivative is
/// the slope smoothed forward and backward by first-order filters of
/// `LEAD_FILTER_TAU_S` (zero phase), so the coil temperature it forms has no
/// error from the filter's own lag (the firmware's causal filter leaves
/// about lag * tau * d2T/dt2, 0.05 degC where the chamber turns, which
/// shifted the knee by as much).
pub fn prepare(t: &[f64], w: &[f64], y: &[f64], temp_c: &[f64]) -> SfInput {
    let fog = FogConfig::new(FogParams::default()).expect("reference FOG configuration");
    let mut comp = ScaleFactorComp::default();
    let mut ts = Vec::with_capacity(t.len());
    each_sensor_update(t, &fog, &ScaleFactorTable::SAFE, |k, cfg| {
        comp.update_temperature(cfg, Some((temp_c[k] * 256.0).round() as i32));
        ts.push(comp.lead_inputs().0 as f64 / 256.0);
    });
    let d = zero_phase_derivative(t, &ts);
    SfInput {
        t: t.to_vec(),
        w: w.to_vec(),
        y: y.to_vec(),
        ts,
        d,
    }
}

/// The slope of `x` smoothed forward and backward by first-order filters of
/// `LEAD_FILTER_TAU_S`, per unit time.
pub fn zero_phase_derivative(t: &[f64], x: &[f64]) -> Vec<f64> {
    let n = t.len();
    let slope: Vec<f64> = (0..n)
        .map(|k| {
            if k > 0 {
                (x[k] - x[k - 1]) / (t[k] - t[k - 1])
            } else {
                0.0
            }
        })
        .collect();
    let tau = LEAD_FILTER_TAU_S;
    let mut fwd = vec![0.0; n];
    for k in 1..n {
        let a = (t[k] - t[k - 1]) / (tau + t[k] - t[k - 1]);
        fwd[k] = fwd[k - 1] + a * (slope[k] - fwd[k - 1]);
    }
    let mut d = fwd.clone();
    for k in (0..n.saturating_sub(1)).rev() {
        let a = (t[k + 1] - t[k]) / (tau + t[k + 1] - t[k]);
        d[k] = d[k + 1] + a * (fwd[k] - d[k + 1]);
    }
    d
}

/// Calls `f(row, config)` for every row with the firmware configuration of
/// `table` for that row's sensor period (t[k] - t[k-1]; the first row takes
/// the second's), rebuilt only when the period changes.
pub fn each_sensor_update(
    t: &[f64],
    fog: &FogConfig,
    table: &ScaleFactorTable,
    mut f: impl FnMut(usize, &ScaleFactorConfig),
) {
    let first = if t.len() > 1 { t[1] - t[0] } else { 1.0 };
    let mut cfg_dt = first;
    let mut cfg = ScaleFactorConfig::new(table, fog, first);
    for k in 0..t.len() {
        let h = if k > 0 { t[k] - t[k - 1] } else { first };
        if (h - cfg_dt).abs() > 1e-9 * cfg_dt {
            cfg = ScaleFactorConfig::new(table, fog, h);
            cfg_dt = h;
        }
        f(k, &cfg);
    }
}

/// Rows of a run that rotate.
pub fn rotating(w: &[f64]) -> Vec<usize> {
    (0..w.len())
        .filter(|&k| w[k].abs() >= MIN_RATE_DPS)
        .collect()
}
