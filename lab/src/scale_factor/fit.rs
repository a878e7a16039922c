//! Scale factor over temperature from a calibration run (docs/fog.md).
//!
//! Model, per sample: `y - w = w * s(T) + b(T)`, with w the reference rate,
//! y the output (nominal scale factor), s the scale-factor error (relative),
//! b the bias. T is the coil temperature, estimated from the coil sensor by
//! the firmware's own blocks as `T_sensor + lag * dT_sensor/dt`.
//!
//! - Continuous rotation: s is continuous piecewise linear in T with K knees
//!   (`s0 + s1 (T - 20) + sum c_k max(0, T - T_k)`); b is `b0 + b1 (T - 20)`
//!   where the run has both rate signs (or rest), else it cannot be told
//!   from s and is left in it. The knee temperatures and the lag are found
//!   by search (the rest is linear), K = 0..=3 is chosen by BIC, each knee
//!   and the lag get a profile-likelihood 95 % interval. The fit works on
//!   10 s bin means (the temperature moves slowly; the noise of the means is
//!   close to white), weighted by their sample counts; a residual lag-1
//!   correlation inflates the variance (and the BIC's likelihood) by
//!   (1 + rho)/(1 - rho).
//! - Multi-point: each temperature plateau is a least-squares line through
//!   its rate sequence (scale factor, bias, IEEE 952 asymmetry and
//!   nonlinearity), the table interpolates between the plateaus; a knee is
//!   tested on the plateau points (BIC), its interval is where the points
//!   cannot place it.

use crate::numerics::lsq::{wls, LsFit};
use crate::numerics::search::{golden, grid_then_golden, profile_interval, CHI2_1_95};
use gyro_coeffs::fog_scale_factor::{ScaleFactorTable, MAX_NODES};
use gyro_sp::fog::scale_factor::{ScaleFactorComp, ScaleFactorConfig, LEAD_FILTER_TAU_S};
use gyro_sp::fog::{FogConfig, FogParams};

/// Rows with |reference rate| below this are at rest, deg/s.
pub const MIN_RATE_DPS: f64 = 1.0;
/// Smallest temperature span over the rotating rows, degC.
pub const MIN_SPAN_C: f64 = 10.0;
/// Bin length of the continuous fit, s.
pub const BIN_S: f64 = 10.0;
/// Most knees tried.
pub const MAX_KNEES: usize = 3;
/// Knees stay this far from the ends of the data and from each other, degC.
const KNEE_MARGIN_C: f64 = 3.0;
/// Window of the scale-factor residual figure, s.
pub const RESIDUAL_WINDOW_S: f64 = 60.0;

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
fn zero_phase_derivative(t: &[f64], x: &[f64]) -> Vec<f64> {
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

/// Standard deviation of the coil-temperature estimate's noise, degC: the
/// sensor's white noise (from its second differences, robustly: the
/// chamber's own curvature is far below it) through `T_s + lag * D`, whose
/// impulse response is taken from the same filters.
fn coil_estimate_noise(inp: &SfInput, lag: f64) -> f64 {
    let n = inp.t.len();
    if n < 10 {
        return 0.0;
    }
    let mut d2: Vec<f64> = (1..n - 1)
        .map(|k| (inp.ts[k + 1] - 2.0 * inp.ts[k] + inp.ts[k - 1]).abs())
        .collect();
    d2.sort_by(f64::total_cmp);
    let sigma_s = 1.4826 * d2[d2.len() / 2] / 6f64.sqrt();
    let mut h: Vec<f64> = inp.t.windows(2).map(|w| w[1] - w[0]).collect();
    h.sort_by(f64::total_cmp);
    let dt = h[h.len() / 2];
    let m = ((20.0 * LEAD_FILTER_TAU_S / dt) as usize).clamp(50, 20_001) | 1;
    let t: Vec<f64> = (0..m).map(|k| k as f64 * dt).collect();
    let mut x = vec![0.0; m];
    x[m / 2] = 1.0;
    let d = zero_phase_derivative(&t, &x);
    let energy: f64 = (0..m).map(|k| (x[k] + lag * d[k]).powi(2)).sum();
    sigma_s * energy.sqrt()
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

/// Rows of a run that rotate.
pub fn rotating(w: &[f64]) -> Vec<usize> {
    (0..w.len())
        .filter(|&k| w[k].abs() >= MIN_RATE_DPS)
        .collect()
}

/// Plateaus of a multi-point run: the rotating rows split where their
/// sensor temperatures, sorted, leave a gap over 3 degC, if every group
/// spans under 3 degC. None for a continuous run.
pub fn plateaus(inp: &SfInput, rot: &[usize]) -> Option<Vec<Vec<usize>>> {
    let mut idx = rot.to_vec();
    idx.sort_by(|&a, &b| inp.ts[a].total_cmp(&inp.ts[b]));
    let mut groups: Vec<Vec<usize>> = vec![];
    for &k in &idx {
        match groups.last_mut() {
            Some(g) if inp.ts[k] - inp.ts[*g.last().unwrap_or(&k)] <= 3.0 => g.push(k),
            _ => groups.push(vec![k]),
        }
    }
    let narrow = groups.iter().all(|g| {
        let (a, b) = (g[0], g[g.len() - 1]);
        inp.ts[b] - inp.ts[a] < 3.0
    });
    (groups.len() >= 2 && narrow).then(|| {
        groups
            .into_iter()
            .map(|mut g| {
                g.sort_unstable();
                g
            })
            .collect()
    })
}

/// RMS of the scale-factor error over `window_s` means of consecutive
/// rows at one rate: err (deg/s) over the rate, ppm. Returns the RMS, its
/// standard error (sqrt(1/(2m)) relative, m windows) and m.
pub fn window_rms_ppm(t: &[f64], w: &[f64], err: &[f64], window_s: f64) -> (f64, f64, usize) {
    let mut means = Vec::new();
    let mut k = 0;
    while k < t.len() {
        if w[k].abs() < MIN_RATE_DPS {
            k += 1;
            continue;
        }
        let start = k;
        let t0 = if k > 0 {
            t[k - 1]
        } else {
            t[k] - (t.get(1).unwrap_or(&1.0) - t[0])
        };
        let mut sum = 0.0;
        while k < t.len() && w[k] == w[start] && t[k] - t0 <= window_s + 1e-9 {
            sum += err[k];
            k += 1;
        }
        // Whole windows only (a rate change cuts the window short).
        if t[k - 1] - t0 >= window_s - 1e-9 {
            means.push(sum / (k - start) as f64 / w[start] * 1e6);
        }
    }
    let m = means.len();
    if m == 0 {
        return (f64::NAN, f64::NAN, 0);
    }
    let rms = (means.iter().map(|x| x * x).sum::<f64>() / m as f64).sqrt();
    (rms, rms / (2.0 * m as f64).sqrt(), m)
}

/// Bin means of the continuous fit.
struct Bins {
    w: Vec<f64>,
    r: Vec<f64>,
    ts: Vec<f64>,
    d: Vec<f64>,
    n: Vec<f64>,
    /// Bins of one constant-rate stretch share a group number.
    group: Vec<usize>,
}

fn bin(inp: &SfInput, rows: &[usize]) -> Bins {
    let mut b = Bins {
        w: vec![],
        r: vec![],
        ts: vec![],
        d: vec![],
        n: vec![],
        group: vec![],
    };
    let mut group = 0;
    let mut i = 0;
    while i < rows.len() {
        let k0 = rows[i];
        if i > 0 && (rows[i - 1] + 1 != k0 || inp.w[rows[i - 1]] != inp.w[k0]) {
            group += 1;
        }
        let t_end = inp.t[k0] + BIN_S - 1e-9;
        let (mut r, mut ts, mut d, mut n) = (0.0, 0.0, 0.0, 0.0);
        let mut j = i;
        while j < rows.len()
            && inp.t[rows[j]] < t_end
            && inp.w[rows[j]] == inp.w[k0]
            && (j == i || rows[j - 1] + 1 == rows[j])
        {
            let k = rows[j];
            r += inp.y[k] - inp.w[k];
            ts += inp.ts[k];
            d += inp.d[k];
            n += 1.0;
            j += 1;
        }
        b.w.push(inp.w[k0]);
        b.r.push(r / n);
        b.ts.push(ts / n);
        b.d.push(d / n);
        b.n.push(n);
        b.group.push(group);
        i = j;
    }
    b
}

/// The continuous model on the bins, for given lag and knees.
struct Model {
    b: Bins,
    with_bias: bool,
}

impl Model {
    fn tc(&self, lag: f64, i: usize) -> f64 {
        self.b.ts[i] + lag * self.b.d[i]
    }

    fn cols(&self, lag: f64, knees: &[f64]) -> Vec<Vec<f64>> {
        let n = self.b.w.len();
        let tc: Vec<f64> = (0..n).map(|i| self.tc(lag, i)).collect();
        let w = &self.b.w;
        let mut cols = vec![w.clone(), (0..n).map(|i| w[i] * (tc[i] - 20.0)).collect()];
        for &k in knees {
            cols.push((0..n).map(|i| w[i] * (tc[i] - k).max(0.0)).collect());
        }
        if self.with_bias {
            cols.push(vec![1.0; n]);
            cols.push(tc.iter().map(|t| t - 20.0).collect());
        }
        cols
    }

    fn fit(&self, lag: f64, knees: &[f64]) -> Option<LsFit> {
        wls(&self.cols(lag, knees), &self.b.r, Some(&self.b.n))
    }

    fn sse(&self, lag: f64, knees: &[f64]) -> f64 {
        self.fit(lag, knees).map_or(f64::INFINITY, |f| f.sse)
    }

    fn params(&self, k: usize) -> usize {
        2 + k + if self.with_bias { 2 } else { 0 }
    }

    /// Best lag for these knees: a coarse grid over 0..600 s (or a window
    /// around `hint`), then golden section.
    fn best_lag(&self, knees: &[f64], hint: Option<f64>) -> (f64, f64) {
        let f = |l: f64| self.sse(l, knees);
        match hint {
            Some(h) => golden(f, (h - 15.0).max(0.0), h + 15.0, 24),
            None => grid_then_golden(
                f,
                &[
                    0.0, 5.0, 10.0, 20.0, 30.0, 45.0, 60.0, 90.0, 120.0, 180.0, 240.0, 360.0,
                    480.0, 600.0,
                ],
                24,
            ),
        }
    }
}

/// Where knee `j` may go: inside the data margin, away from its neighbours.
fn knee_bounds(knees: &[f64], j: usize, lo: f64, hi: f64) -> (f64, f64) {
    let left = if j > 0 {
        knees[j - 1] + KNEE_MARGIN_C
    } else {
        lo + KNEE_MARGIN_C
    };
    let right = if j + 1 < knees.len() {
        knees[j + 1] - KNEE_MARGIN_C
    } else {
        hi - KNEE_MARGIN_C
    };
    (left, right)
}

/// A knee model: knees (sorted), lag, weighted SSE.
#[derive(Clone, Debug)]
struct Candidate {
    knees: Vec<f64>,
    lag: f64,
    sse: f64,
}

/// Coordinate refinement of every knee (golden within +-0.75 degC), then the lag.
fn refine(m: &Model, c: &mut Candidate, lo: f64, hi: f64) {
    for _ in 0..2 {
        for j in 0..c.knees.len() {
            let (bl, br) = knee_bounds(&c.knees, j, lo, hi);
            let (a, b) = ((c.knees[j] - 0.75).max(bl), (c.knees[j] + 0.75).min(br));
            if a >= b {
                continue;
            }
            let mut k = c.knees.clone();
            let (x, _) = golden(
                |t| {
                    k[j] = t;
                    m.sse(c.lag, &k)
                },
                a,
                b,
                16,
            );
            c.knees[j] = x;
        }
        // The whole lag range: the model with one knee less may have bent
        // the lag far to imitate the knee.
        let (lag, sse) = m.best_lag(&c.knees, None);
        c.lag = lag;
        c.sse = sse;
    }
}

/// The fit of a continuous-rotation run.
pub fn fit_continuous(inp: &SfInput) -> Result<SfFit, SfFitError> {
    let all: Vec<usize> = (0..inp.t.len()).collect();
    let rot = rotating(&inp.w);
    let signs: std::collections::BTreeSet<i8> = inp
        .w
        .iter()
        .map(|&w| {
            if w >= MIN_RATE_DPS {
                1
            } else if w <= -MIN_RATE_DPS {
                -1
            } else {
                0
            }
        })
        .collect();
    let with_bias = signs.len() >= 2;
    let rows: &[usize] = if with_bias { &all } else { &rot };
    let m = Model {
        b: bin(inp, rows),
        with_bias,
    };
    let nb = m.b.w.len();
    // Calibrated range: the coil temperatures of the rotating bins, at the
    // lag fitted without knees (refined below).
    let range_at = |lag: f64| {
        (0..nb)
            .filter(|&i| m.b.w[i].abs() >= MIN_RATE_DPS)
            .map(|i| m.tc(lag, i))
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), t| {
                (a.min(t), b.max(t))
            })
    };
    let (lag0, sse0) = m.best_lag(&[], None);
    let (lo, hi) = range_at(lag0);
    let mut models = vec![Candidate {
        knees: vec![],
        lag: lag0,
        sse: sse0,
    }];
    for _ in 1..=MAX_KNEES {
        let prev = models[models.len() - 1].clone();
        let mut best: Option<(f64, f64)> = None;
        let mut t = lo + KNEE_MARGIN_C;
        while t <= hi - KNEE_MARGIN_C {
            if prev.knees.iter().all(|k| (k - t).abs() >= KNEE_MARGIN_C) {
                let mut k = prev.knees.clone();
                k.push(t);
                k.sort_by(f64::total_cmp);
                let s = m.sse(prev.lag, &k);
                if best.is_none_or(|b| s < b.1) {
                    best = Some((t, s));
                }
            }
            t += 0.5;
        }
        let Some((t, _)) = best else { break };
        let mut c = prev.clone();
        c.knees.push(t);
        c.knees.sort_by(f64::total_cmp);
        refine(&m, &mut c, lo, hi);
        models.push(c);
    }
    // Correlation of the residual of the richest model, within stretches.
    let richest = &models[models.len() - 1];
    let rf = m
        .fit(richest.lag, &richest.knees)
        .ok_or(SfFitError::Singular)?;
    let z: Vec<f64> = (0..nb).map(|i| rf.resid[i] * m.b.n[i].sqrt()).collect();
    let (mut num, mut den) = (0.0, 0.0);
    for i in 0..nb {
        den += z[i] * z[i];
        if i > 0 && m.b.group[i] == m.b.group[i - 1] {
            num += z[i] * z[i - 1];
        }
    }
    let rho = if den > 0.0 {
        (num / den).clamp(0.0, 0.9)
    } else {
        0.0
    };
    let phi = (1.0 + rho) / (1.0 - rho);
    let n = nb as f64;
    let bic: Vec<f64> = models
        .iter()
        .map(|c| {
            n * (c.sse / n).ln() / phi + (m.params(c.knees.len()) + c.knees.len()) as f64 * n.ln()
        })
        .collect();
    let best_k = (0..bic.len())
        .min_by(|&a, &b| bic[a].total_cmp(&bic[b]))
        .unwrap_or(0);
    let c = models[best_k].clone();
    let p = m.params(c.knees.len()) + c.knees.len() + 1;
    let var = c.sse / (n - p as f64).max(1.0);
    let thr = CHI2_1_95 * phi * var;
    let (lo, hi) = range_at(c.lag);

    // Knee intervals: profile over the knee with the lag re-fitted (the
    // rate noise), widened in quadrature by the coil-temperature estimate's
    // own noise: correlated over about a minute, it moves the knee as a
    // whole at each crossing, so it averages only over the crossings.
    let sigma_tc = coil_estimate_noise(inp, c.lag);
    let crossings = |k: f64| {
        let mut side: Option<bool> = None;
        let mut count = 0usize;
        for i in 0..nb {
            let t = m.tc(c.lag, i);
            let s = if t > k + 0.5 {
                Some(true)
            } else if t < k - 0.5 {
                Some(false)
            } else {
                None
            };
            if let (Some(a), Some(b)) = (side, s) {
                if a != b {
                    count += 1;
                }
            }
            if s.is_some() {
                side = s;
            }
        }
        count.max(1)
    };
    let mut knees = vec![];
    for j in 0..c.knees.len() {
        let prof = |t: f64| {
            let mut k = c.knees.clone();
            k[j] = t;
            golden(|l| m.sse(l, &k), (c.lag - 15.0).max(0.0), c.lag + 15.0, 14).1
        };
        let k = c.knees[j];
        let (ci_lo, ci_hi) =
            profile_interval(prof, k, c.sse, thr, 0.01, knee_bounds(&c.knees, j, lo, hi));
        let z = 1.96 * sigma_tc / (crossings(k) as f64).sqrt();
        knees.push(Interval {
            value: k,
            lo: k - (k - ci_lo).hypot(z),
            hi: k + (ci_hi - k).hypot(z),
        });
    }
    // Lag interval, the knees re-fitted locally.
    let prof_lag = |l: f64| {
        let mut cand = Candidate {
            knees: c.knees.clone(),
            lag: l,
            sse: 0.0,
        };
        for j in 0..cand.knees.len() {
            let (bl, br) = knee_bounds(&cand.knees, j, lo, hi);
            let (a, b) = ((cand.knees[j] - 0.5).max(bl), (cand.knees[j] + 0.5).min(br));
            let mut k = cand.knees.clone();
            cand.knees[j] = golden(
                |t| {
                    k[j] = t;
                    m.sse(l, &k)
                },
                a,
                b,
                10,
            )
            .0;
        }
        m.sse(l, &cand.knees)
    };
    let (lag_lo, lag_hi) = profile_interval(prof_lag, c.lag, c.sse, thr, 0.5, (0.0, 1000.0));

    let f = m.fit(c.lag, &c.knees).ok_or(SfFitError::Singular)?;
    let v = phi * var;
    let nk = c.knees.len();
    // s(T) as a . coef.
    let a_sf = |t: f64| {
        let mut a = vec![0.0; f.coef.len()];
        a[0] = 1.0;
        a[1] = t - 20.0;
        for (j, k) in c.knees.iter().enumerate() {
            a[2 + j] = (t - k).max(0.0);
        }
        a
    };
    let dot = |a: &[f64]| a.iter().zip(&f.coef).map(|(x, y)| x * y).sum::<f64>();
    let bias_at = |t: f64| {
        if with_bias {
            f.coef[2 + nk] + f.coef[3 + nk] * (t - 20.0)
        } else {
            0.0
        }
    };
    let mut nodes = vec![lo];
    nodes.extend(c.knees.iter().copied());
    nodes.push(hi);
    let segments = segments_from(
        &nodes,
        |t| {
            let a = a_sf(t);
            (dot(&a), a)
        },
        |a| f.se_of(a, v),
    );
    let sf: Vec<f64> = nodes.iter().map(|&t| dot(&a_sf(t)) * 1e6).collect();
    let bias: Vec<f64> = nodes.iter().map(|&t| bias_at(t) * 3600.0).collect();
    let table = ScaleFactorTable::from_nodes(&nodes, &sf, &bias, c.lag);

    // Residual over 60 s means of the rotating rows.
    let err: Vec<f64> = (0..inp.t.len())
        .map(|k| {
            let tc = inp.ts[k] + c.lag * inp.d[k];
            inp.y[k] - inp.w[k] - inp.w[k] * dot(&a_sf(tc)) - bias_at(tc)
        })
        .collect();
    let (rms, rms_se, _) = window_rms_ppm(&inp.t, &inp.w, &err, RESIDUAL_WINDOW_S);

    let mut notes = vec![];
    if !with_bias {
        notes.push(
            "one rate sign: the bias cannot be told from the scale factor and is left in it \
             (a bias error Omega0 on rate w reads as Omega0/w of scale factor)"
                .to_owned(),
        );
    }
    notes.push(
        "asymmetry and nonlinearity need several rate magnitudes: not measurable on a one-rate \
         run; with both signs at one magnitude |w| the bias carries |w|*asymmetry/2"
            .into(),
    );
    Ok(SfFit {
        method: FitMethod::Continuous,
        knees,
        segments,
        table,
        sensor_lag_s: Some(Interval {
            value: c.lag,
            lo: lag_lo,
            hi: lag_hi,
        }),
        bias: with_bias.then(|| BiasModel {
            at_20c_dph: Est {
                value: f.coef[2 + nk] * 3600.0,
                se: f.se(2 + nk, v) * 3600.0,
            },
            slope_dph_per_c: Est {
                value: f.coef[3 + nk] * 3600.0,
                se: f.se(3 + nk, v) * 3600.0,
            },
        }),
        asymmetry_ppm: None,
        nonlinearity_ppm: None,
        bic,
        noise_inflation: phi,
        residual_ppm: Est {
            value: rms,
            se: rms_se,
        },
        range_c: [lo, hi],
        rows_used: rows.len(),
        notes,
    })
}

/// Segments between consecutive nodes of a piecewise-linear s(T) given as
/// `s_at(t) = (value, a)` with value = a . coef; `se(a)` the standard error
/// of a . coef. The slope of a segment is the difference of s over it.
fn segments_from(
    nodes: &[f64],
    s_at: impl Fn(f64) -> (f64, Vec<f64>),
    se: impl Fn(&[f64]) -> f64,
) -> Vec<Segment> {
    nodes
        .windows(2)
        .map(|w| {
            let (s0, a0) = s_at(w[0]);
            let (s1, a1) = s_at(w[1]);
            let h = w[1] - w[0];
            let k_t = (s1 - s0) / h;
            let a_t: Vec<f64> = a0.iter().zip(&a1).map(|(x, y)| (y - x) / h).collect();
            // k0 = 1 + s(T0) - k_t*T0.
            let a_k0: Vec<f64> = a0.iter().zip(&a_t).map(|(x, y)| x - y * w[0]).collect();
            let k0m1 = s0 - k_t * w[0];
            Segment {
                from_c: w[0],
                to_c: w[1],
                k0: 1.0 + k0m1,
                k_t,
                k0_se: se(&a_k0),
                k_t_se: se(&a_t),
                k0_ppm: k0m1 * 1e6,
                k_t_ppm_per_c: k_t * 1e6,
            }
        })
        .collect()
}

/// One plateau of a multi-point run.
#[derive(Clone, Debug, serde::Serialize)]
pub struct Plateau {
    pub temp_c: f64,
    pub sf_ppm: Est,
    pub bias_dph: Est,
    pub asymmetry_ppm: Option<Est>,
    pub nonlinearity_ppm: Option<Est>,
}

fn plateau_fit(inp: &SfInput, rows: &[usize]) -> Option<Plateau> {
    let w: Vec<f64> = rows.iter().map(|&k| inp.w[k]).collect();
    let y: Vec<f64> = rows.iter().map(|&k| inp.y[k]).collect();
    let n = rows.len() as f64;
    let both = w.iter().any(|&x| x > 0.0) && w.iter().any(|&x| x < 0.0);
    // y = b + K w (the bias only with both signs).
    let mut cols = vec![w.clone()];
    if both {
        cols.push(vec![1.0; w.len()]);
    }
    let f = wls(&cols, &y, None)?;
    let var = f.sse / (n - cols.len() as f64).max(1.0);
    let k = f.coef[0];
    let mags: std::collections::BTreeSet<u64> =
        w.iter().map(|x| (x.abs() * 1e3).round() as u64).collect();
    // Asymmetry: y = b + K+ w+ + K- w-, with two magnitudes or more.
    let two_slope = if both && mags.len() >= 2 {
        let cols = vec![
            w.iter().map(|&x| x.max(0.0)).collect(),
            w.iter().map(|&x| x.min(0.0)).collect(),
            vec![1.0; w.len()],
        ];
        wls(&cols, &y, None)
    } else {
        None
    };
    let asymmetry_ppm = two_slope.as_ref().map(|g| {
        let var = g.sse / (n - 3.0).max(1.0);
        let mean = 0.5 * (g.coef[0] + g.coef[1]);
        Est {
            value: (g.coef[0] - g.coef[1]) / mean * 1e6,
            se: g.se_of(&[1.0, -1.0, 0.0], var) / mean * 1e6,
        }
    });
    // Nonlinearity (IEEE 952): the largest deviation of a rate point's mean
    // output from the least-squares line (the two-slope one where the
    // asymmetry is measured, so it is not counted twice), over the
    // full-scale output. Noise makes the largest deviation read high by
    // about its standard error.
    let nonlinearity_ppm = (mags.len() >= 3).then(|| {
        let (resid, var) = match &two_slope {
            Some(g) => (&g.resid, g.sse / (n - 3.0).max(1.0)),
            None => (&f.resid, var),
        };
        let mut pts: std::collections::BTreeMap<i64, (f64, f64)> = Default::default();
        for (i, &x) in w.iter().enumerate() {
            let e = pts.entry((x * 1e3).round() as i64).or_default();
            e.0 += resid[i];
            e.1 += 1.0;
        }
        let fs = w.iter().fold(0.0f64, |a, x| a.max(x.abs())) * k;
        let (dev, cnt) = pts
            .values()
            .map(|(s, c)| (s / c, *c))
            .max_by(|a, b| a.0.abs().total_cmp(&b.0.abs()))
            .unwrap_or((0.0, 1.0));
        Est {
            value: dev.abs() / fs * 1e6,
            se: (var / cnt).sqrt() / fs * 1e6,
        }
    });
    let temp_c = rows.iter().map(|&k| inp.ts[k]).sum::<f64>() / n;
    Some(Plateau {
        temp_c,
        sf_ppm: Est {
            value: (k - 1.0) * 1e6,
            se: f.se(0, var) * 1e6,
        },
        bias_dph: if both {
            Est {
                value: f.coef[1] * 3600.0,
                se: f.se(1, var) * 3600.0,
            }
        } else {
            Est {
                value: 0.0,
                se: 0.0,
            }
        },
        asymmetry_ppm,
        nonlinearity_ppm,
    })
}

/// Chi-square of a hinge (or line, `knee` None) fit to plateau points.
fn plateau_chi2(pts: &[Plateau], knee: Option<f64>) -> f64 {
    let mut cols = vec![
        vec![1.0; pts.len()],
        pts.iter().map(|p| p.temp_c - 20.0).collect::<Vec<f64>>(),
    ];
    if let Some(k) = knee {
        cols.push(pts.iter().map(|p| (p.temp_c - k).max(0.0)).collect());
    }
    let y: Vec<f64> = pts.iter().map(|p| p.sf_ppm.value).collect();
    let wts: Vec<f64> = pts
        .iter()
        .map(|p| 1.0 / p.sf_ppm.se.max(1e-6).powi(2))
        .collect();
    wls(&cols, &y, Some(&wts)).map_or(f64::INFINITY, |f| f.sse)
}

/// The fit of a multi-point run (plateaus from [`plateaus`]).
pub fn fit_multipoint(
    inp: &SfInput,
    groups: &[Vec<usize>],
) -> Result<(SfFit, Vec<Plateau>), SfFitError> {
    if groups.len() > MAX_NODES {
        return Err(SfFitError::TooManyPlateaus(groups.len()));
    }
    let mut pts: Vec<Plateau> = vec![];
    for g in groups {
        pts.push(plateau_fit(inp, g).ok_or(SfFitError::Plateau)?);
    }
    pts.sort_by(|a, b| a.temp_c.total_cmp(&b.temp_c));
    let np = pts.len();
    // Knee test on the plateau points: line vs hinge, BIC with the known
    // standard errors (chi-square); the hinge needs a spare point.
    let n = np as f64;
    let chi0 = plateau_chi2(&pts, None);
    let mut bic = vec![chi0 + 2.0 * n.ln()];
    let mut knees = vec![];
    if np >= 5 {
        let (lo, hi) = (pts[0].temp_c, pts[np - 1].temp_c);
        let grid: Vec<f64> = (0..=((hi - lo) / 0.1) as usize)
            .map(|i| lo + 0.5 + 0.1 * i as f64)
            .filter(|t| *t < hi - 0.5)
            .collect();
        let chis: Vec<f64> = grid.iter().map(|&t| plateau_chi2(&pts, Some(t))).collect();
        if let Some(i) = (0..grid.len()).min_by(|&a, &b| chis[a].total_cmp(&chis[b])) {
            bic.push(chis[i] + 4.0 * n.ln());
            if bic[1] < bic[0] {
                let inside: Vec<f64> = grid
                    .iter()
                    .zip(&chis)
                    .filter(|(_, c)| **c - chis[i] <= CHI2_1_95)
                    .map(|(t, _)| *t)
                    .collect();
                let (a, b) = (inside[0], inside[inside.len() - 1]);
                knees.push(Interval {
                    value: 0.5 * (a + b),
                    lo: a,
                    hi: b,
                });
            }
        }
    }
    let nodes: Vec<f64> = pts.iter().map(|p| p.temp_c).collect();
    let sf: Vec<f64> = pts.iter().map(|p| p.sf_ppm.value).collect();
    let bias: Vec<f64> = pts.iter().map(|p| p.bias_dph.value).collect();
    let table = ScaleFactorTable::from_nodes(&nodes, &sf, &bias, 0.0);
    // Segments between plateaus: independent points, so the standard
    // errors add in quadrature.
    let segments = pts
        .windows(2)
        .map(|w| {
            let h = w[1].temp_c - w[0].temp_c;
            let k_t = (w[1].sf_ppm.value - w[0].sf_ppm.value) * 1e-6 / h;
            let se_t = w[0].sf_ppm.se.hypot(w[1].sf_ppm.se) * 1e-6 / h;
            let k0m1 = w[0].sf_ppm.value * 1e-6 - k_t * w[0].temp_c;
            let t0 = w[0].temp_c;
            let se0 = ((w[0].sf_ppm.se * 1e-6 * (1.0 + t0 / h)).powi(2)
                + (w[1].sf_ppm.se * 1e-6 * t0 / h).powi(2))
            .sqrt();
            Segment {
                from_c: w[0].temp_c,
                to_c: w[1].temp_c,
                k0: 1.0 + k0m1,
                k_t,
                k0_se: se0,
                k_t_se: se_t,
                k0_ppm: k0m1 * 1e6,
                k_t_ppm_per_c: k_t * 1e6,
            }
        })
        .collect();
    // Residual over 60 s means: each plateau's own line.
    let mut err = vec![0.0; inp.t.len()];
    let mut used = 0;
    for (g, p) in groups
        .iter()
        .zip(groups.iter().map(|g| plateau_fit(inp, g)))
    {
        let Some(p) = p else { continue };
        for &k in g {
            err[k] =
                inp.y[k] - inp.w[k] * (1.0 + p.sf_ppm.value * 1e-6) - p.bias_dph.value / 3600.0;
            used += 1;
        }
    }
    let mut w_rot = inp.w.clone();
    for (k, w) in w_rot.iter_mut().enumerate() {
        if !groups.iter().any(|g| g.binary_search(&k).is_ok()) {
            *w = 0.0;
        }
    }
    let (rms, rms_se, _) = window_rms_ppm(&inp.t, &w_rot, &err, RESIDUAL_WINDOW_S);
    let pooled = |f: fn(&Plateau) -> Option<Est>| {
        let v: Vec<Est> = pts.iter().filter_map(f).collect();
        (!v.is_empty()).then(|| {
            // Inverse-variance mean over the plateaus.
            let wsum: f64 = v.iter().map(|e| 1.0 / e.se.max(1e-9).powi(2)).sum();
            Est {
                value: v
                    .iter()
                    .map(|e| e.value / e.se.max(1e-9).powi(2))
                    .sum::<f64>()
                    / wsum,
                se: wsum.sqrt().recip(),
            }
        })
    };
    let asymmetry_ppm = pooled(|p| p.asymmetry_ppm);
    // Nonlinearity: the worst plateau.
    let nonlinearity_ppm = pts
        .iter()
        .filter_map(|p| p.nonlinearity_ppm)
        .max_by(|a, b| a.value.total_cmp(&b.value));
    let notes = vec![
        "multi-point: the table interpolates linearly between the plateaus; a knee between two \
         plateaus is only bracketed"
            .to_owned(),
        "sensor lag not measurable on soaked plateaus: the table uses 0".to_owned(),
    ];
    Ok((
        SfFit {
            method: FitMethod::MultiPoint,
            knees,
            segments,
            table,
            sensor_lag_s: None,
            bias: None,
            asymmetry_ppm,
            nonlinearity_ppm,
            bic,
            noise_inflation: 1.0,
            residual_ppm: Est {
                value: rms,
                se: rms_se,
            },
            range_c: [nodes[0], nodes[np - 1]],
            rows_used: used,
            notes,
        },
        pts,
    ))
}
