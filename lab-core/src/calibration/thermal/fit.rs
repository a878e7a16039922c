//! Least-squares fit of the RLG thermal bias model (docs/rlg.md) on a
//! chamber run, next to the classic one-sensor cubic.
//!
//! The regressors are those the firmware computes (thermal.rs), in f64 with
//! the same discrete filters: dT = T_a - T_b clamped to +-32 degC; grad(dT)
//! from the first-order filtered differentiator (tau 20 s, first slope 0,
//! slope clamped to +-8 degC/s); T_K; F = 1 - exp(-t/tau_warm). The model is
//! linear in its coefficients once tau_warm is fixed; tau_warm is searched
//! (log grid, then golden section) for the least residual.

use super::figures::window_means;
use crate::numerics::lsq::wls;
use crate::numerics::search::grid_then_golden;
use crate::numerics::thermal_difference::dt_and_gradient;
use gyro_sp::rlg::ThermalCoeffs;

/// Inputs of a fit, one row per sample.
pub struct ThermalData {
    pub t: Vec<f64>,
    pub a: Vec<f64>,
    pub b: Vec<f64>,
    pub case: Vec<f64>,
    /// Drift to explain: rate minus reference, deg/h.
    pub drift_dph: Vec<f64>,
}

impl ThermalData {
    /// A chamber run's time, monoblock and case sensors, and its drift
    /// from the output and reference rates (deg/s).
    pub fn new(
        t: Vec<f64>,
        (a, b): (Vec<f64>, Vec<f64>),
        case: Vec<f64>,
        rate_dps: &[f64],
        ref_rate_dps: &[f64],
    ) -> Self {
        let drift_dph = rate_dps
            .iter()
            .zip(ref_rate_dps)
            .map(|(r, w)| (r - w) * 3600.0)
            .collect();
        Self {
            t,
            a,
            b,
            case,
            drift_dph,
        }
    }
}

/// Least squares: the coefficients and the residual.
fn lstsq(cols: &[Vec<f64>], y: &[f64]) -> Option<(Vec<f64>, Vec<f64>)> {
    wls(cols, y, None).map(|f| (f.coef, f.resid))
}

fn sse(r: &[f64]) -> f64 {
    r.iter().map(|v| v * v).sum()
}

/// The improved model's regressors at warm-up time constant `tau`:
/// 1, dT, grad(dT), dT^2, T_K, 1 - exp(-t/tau).
fn columns(d: &ThermalData, tau: f64) -> Vec<Vec<f64>> {
    let (dts, grads) = dt_and_gradient(&d.t, &d.a, &d.b);
    let dt2: Vec<f64> = dts.iter().map(|v| v * v).collect();
    let warm: Vec<f64> = d.t.iter().map(|t| 1.0 - (-t / tau).exp()).collect();
    vec![vec![1.0; d.t.len()], dts, grads, dt2, d.case.clone(), warm]
}

/// The improved model's fit: coefficients and residual (deg/h).
pub fn fit_thermal(d: &ThermalData) -> Option<(ThermalCoeffs, Vec<f64>)> {
    let solve = |tau: f64| lstsq(&columns(d, tau), &d.drift_dph);
    let cost = |lt: f64| solve(lt.exp()).map_or(f64::INFINITY, |(_, r)| sse(&r));
    // Log grid 30 s .. 30 000 s, then golden section around the best.
    let (lo, hi) = (30f64.ln(), 30_000f64.ln());
    let grid: Vec<f64> = (0..=24).map(|i| lo + (hi - lo) * i as f64 / 24.0).collect();
    let (best, _) = grid_then_golden(cost, &grid, 40);
    let tau = best.exp();
    let (c, r) = solve(tau)?;
    Some((
        ThermalCoeffs {
            bias0_dph: c[0],
            k1_dph_per_c: c[1],
            k2_dph_per_c_per_s: c[2],
            k3_dph_per_c2: c[3],
            k4_dph_per_c: c[4],
            k5_dph: c[5],
            tau_warm_s: tau,
        },
        r,
    ))
}

/// Standard errors of the fitted coefficients (same units, same order; in
/// `tau_warm_s` the warm-up time constant's). The least-squares covariance
/// with the residual's variance, inflated for its correlation by batch
/// means (the variance of 100 s means over what white noise would give);
/// tau_warm from the curvature of the residual sum in ln(tau).
pub fn coefficient_se(d: &ThermalData, c: &ThermalCoeffs) -> Option<ThermalCoeffs> {
    let f = wls(&columns(d, c.tau_warm_s), &d.drift_dph, None)?;
    let n = d.t.len() as f64;
    let var = f.sse / (n - 7.0).max(1.0);
    let dt = (d.t[d.t.len() - 1] - d.t[0]) / (n - 1.0).max(1.0);
    let per = (100.0 / dt).round().max(1.0);
    let means = window_means(&d.t, &f.resid, 100.0);
    let m = means.len() as f64;
    let mv = means.iter().sum::<f64>() / m.max(1.0);
    let var_means = means.iter().map(|x| (x - mv).powi(2)).sum::<f64>() / (m - 1.0).max(1.0);
    let inflation = (var_means * per / var).max(1.0);
    let v = var * inflation;
    let sse_at =
        |lt: f64| wls(&columns(d, lt.exp()), &d.drift_dph, None).map_or(f64::NAN, |f| f.sse);
    let (l0, h) = (c.tau_warm_s.ln(), 0.05);
    let curv = (sse_at(l0 + h) - 2.0 * f.sse + sse_at(l0 - h)) / (h * h);
    let se_ln_tau = if curv > 0.0 {
        (2.0 * v / curv).sqrt()
    } else {
        f64::INFINITY
    };
    Some(ThermalCoeffs {
        bias0_dph: f.se(0, v),
        k1_dph_per_c: f.se(1, v),
        k2_dph_per_c_per_s: f.se(2, v),
        k3_dph_per_c2: f.se(3, v),
        k4_dph_per_c: f.se(4, v),
        k5_dph: f.se(5, v),
        tau_warm_s: c.tau_warm_s * se_ln_tau,
    })
}

/// Classic model: `B = c0 + K3*T + K2*T^2 + K1*T^3` from one sensor.
#[derive(Clone, Debug, serde::Serialize, serde::Deserialize)]
pub struct CubicModel {
    /// c0, K3, K2, K1 (deg/h, per degC, per degC^2, per degC^3).
    pub c: [f64; 4],
}

impl CubicModel {
    pub fn fit(temp: &[f64], drift: &[f64]) -> Option<Self> {
        let cols: Vec<Vec<f64>> = (0..4)
            .map(|p| temp.iter().map(|t| t.powi(p)).collect())
            .collect();
        let (c, _) = lstsq(&cols, drift)?;
        Some(Self {
            c: [c[0], c[1], c[2], c[3]],
        })
    }

    pub fn eval(&self, t: f64) -> f64 {
        self.c[0] + t * (self.c[1] + t * (self.c[2] + t * self.c[3]))
    }
}
