//! The figures a scale-factor report plots, from a run and its fit: the
//! measured scale factor binned by coil temperature with standard errors,
//! the residual's 60 s means over time and temperature, the sensor lag's
//! profile, the coil temperature against its sensor. Computed only when a
//! report is written.

use super::bins::{bin, Bins};
use super::input::{rotating, SfInput, MIN_RATE_DPS};
use super::residual::{window_means, WindowMean, RESIDUAL_WINDOW_S};
use super::result::{SfCurve, SfFit};
use crate::numerics::lsq::wls;

/// Width of the temperature bins, degC.
pub const TEMP_BIN_C: f64 = 1.0;
/// At most this many points in a time series.
const MAX_POINTS: usize = 2000;

/// One temperature bin of a measured quantity, ppm.
#[derive(Clone, Copy, Debug)]
pub struct TempBin {
    pub t_c: f64,
    pub ppm: f64,
    /// Standard error of the mean (NaN with one 10 s bin).
    pub se: f64,
    pub count: usize,
}

pub struct SfDiagnostics {
    /// Measured scale-factor error by coil temperature.
    pub sf_bins: Vec<TempBin>,
    /// The same about the fitted model (measured - model).
    pub resid_bins: Vec<TempBin>,
    /// 60 s means of the residual (`extra`: the coil temperature).
    pub residual: Vec<WindowMean>,
    /// Profile of the criterion over the lag, the model's shape held:
    /// (lag s, chi-square above the minimum).
    pub lag_profile: Vec<(f64, f64)>,
    /// (t s, sensor degC, coil estimate degC), thinned.
    pub temps: Vec<(f64, f64, f64)>,
}

/// Means by `TEMP_BIN_C` bins of `(t, v)` pairs, `model(t)` added to each
/// bin's mean at its mean temperature.
pub fn by_temperature(pts: &[(f64, f64)], model: impl Fn(f64) -> f64) -> Vec<TempBin> {
    // Keyed by bin number.
    let mut groups: std::collections::BTreeMap<i64, Vec<(f64, f64)>> = Default::default();
    for &(t, v) in pts {
        if t.is_finite() && v.is_finite() {
            groups
                .entry((t / TEMP_BIN_C).floor() as i64)
                .or_default()
                .push((t, v));
        }
    }
    groups
        .values()
        .map(|g| {
            let n = g.len() as f64;
            let t = g.iter().map(|p| p.0).sum::<f64>() / n;
            let m = g.iter().map(|p| p.1).sum::<f64>() / n;
            let sd = (g.iter().map(|p| (p.1 - m).powi(2)).sum::<f64>() / (n - 1.0)).sqrt();
            TempBin {
                t_c: t,
                ppm: model(t) + m,
                se: if g.len() > 1 { sd / n.sqrt() } else { f64::NAN },
                count: g.len(),
            }
        })
        .collect()
}

/// Every `step`-th of `n` indices, at most `MAX_POINTS`.
fn thinned(n: usize) -> impl Iterator<Item = usize> {
    (0..n).step_by(n.div_ceil(MAX_POINTS).max(1))
}

fn profile(
    b: &Bins,
    c: &SfCurve,
    with_bias: bool,
    phi: f64,
    (centre, width): (f64, f64),
) -> Vec<(f64, f64)> {
    let sse = |lag: f64| {
        let n = b.w.len();
        let tc: Vec<f64> = (0..n).map(|i| b.ts[i] + lag * b.d[i]).collect();
        let x: Vec<f64> = tc.iter().map(|t| t - c.t_ref_c).collect();
        let mut cols: Vec<Vec<f64>> = (0..=c.degree)
            .map(|p| (0..n).map(|i| b.w[i] * x[i].powi(p as i32)).collect())
            .collect();
        for &k in &c.knees {
            cols.push((0..n).map(|i| b.w[i] * (tc[i] - k).max(0.0)).collect());
        }
        if with_bias {
            cols.push(vec![1.0; n]);
            cols.push(x.clone());
        }
        wls(&cols, &b.r, Some(&b.n)).map(|f| (f.sse, cols.len()))
    };
    let Some((s0, p)) = sse(centre) else {
        return vec![];
    };
    let var = s0 / (b.w.len() as f64 - p as f64).max(1.0) * phi.max(1.0);
    (0..=40)
        .map(|i| {
            let lag = (centre + width * (i as f64 / 20.0 - 1.0)).max(0.0);
            (lag, sse(lag).map_or(f64::NAN, |(s, _)| (s - s0) / var))
        })
        .collect()
}

/// The report's figures of a fit: about its continuous model, or (a
/// multi-point fit) about its table, which has no lag.
pub fn diagnostics(inp: &SfInput, fit: &SfFit) -> SfDiagnostics {
    let c = fit.curve.as_ref();
    let lag = fit.sensor_lag_s.map_or(0.0, |l| l.value);
    // The profile over one and a half times the interval's width each way.
    let width = 1.5 * fit.sensor_lag_s.map_or(1.0, |l| (l.hi - l.lo).max(0.5));
    let sf = |t: f64| c.map_or_else(|| fit.table.eval(t).0, |c| c.sf_ppm(t));
    let bias = |t: f64| c.map_or_else(|| fit.table.eval(t).1 / 3600.0, |c| c.bias_dps(t));
    let with_bias = c.is_none_or(|c| c.bias.is_some());
    let rows: Vec<usize> = if with_bias {
        (0..inp.t.len()).collect()
    } else {
        rotating(&inp.w)
    };
    let b = bin(inp, &rows);
    let tc = |ts: f64, d: f64| ts + lag * d;
    // Each 10 s bin's scale-factor error about the model; binned by
    // temperature and the model put back at each bin's mean temperature.
    let pts: Vec<(f64, f64)> = (0..b.w.len())
        .filter(|&i| b.w[i].abs() >= MIN_RATE_DPS)
        .map(|i| {
            let t = tc(b.ts[i], b.d[i]);
            let s = (b.r[i] - bias(t)) / b.w[i] * 1e6;
            (t, s - sf(t))
        })
        .collect();
    let sf_bins = by_temperature(&pts, sf);
    let resid_bins = by_temperature(&pts, |_| 0.0);
    let coil: Vec<f64> = (0..inp.t.len()).map(|k| tc(inp.ts[k], inp.d[k])).collect();
    let err: Vec<f64> = (0..inp.t.len())
        .map(|k| {
            let t = coil[k];
            inp.y[k] - inp.w[k] - inp.w[k] * sf(t) * 1e-6 - bias(t)
        })
        .collect();
    let residual = window_means(&inp.t, &inp.w, &err, &coil, RESIDUAL_WINDOW_S);
    let temps = thinned(inp.t.len())
        .map(|k| (inp.t[k], inp.ts[k], coil[k]))
        .collect();
    SfDiagnostics {
        sf_bins,
        resid_bins,
        residual,
        lag_profile: c.map_or_else(Vec::new, |c| {
            profile(&b, c, with_bias, fit.noise_inflation, (lag, width))
        }),
        temps,
    }
}
