//! The IEEE 952 noise terms (docs/noise.md) fitted to a whole Allan-variance
//! curve: `AVAR(tau) = 3Q^2/tau^2 + N^2/tau + (2 ln2/pi) B^2 + K^2 tau/3 +
//! R^2 tau^2/2`, linear in c = (Q^2, N^2, B^2, K^2, R^2) >= 0.
//!
//! - Weighted least squares with non-negative coefficients (the best of all
//!   subsets whose solution is non-negative), iteratively reweighted: the
//!   variance of an AVAR estimate is 2 AVAR^2/edf, taken at the model (not
//!   at the noisy point, which would pull the fit down), with each
//!   averaging time's degrees of freedom from the noise types the model
//!   holds there (Greenhall's per type, combined by their shares).
//! - A term is reported only where the curve shows it: it must carry at
//!   least half of the model at some measured averaging time, and its
//!   interval must exclude zero. Otherwise it is absent (null), and the
//!   rest is refitted without it.
//! - Interval: the fit's sandwich covariance `(X'WX)^-1 X'W S W X
//!   (X'WX)^-1`, S the covariance of the Allan-variance estimates: variance
//!   2 AVAR^2/edf each, and correlated between averaging times (overlapping
//!   estimates share samples). Per noise type the correlation of the
//!   estimates at tau1 < tau2 (Monte Carlo on the project's generators)
//!   falls as (tau1/tau2)^beta, beta 1.1 for white rate noise, 0.7 for
//!   flicker, 0.35 for random walk, and is about 0.3 at any ratio for white
//!   angle noise; a mixture's estimates correlate as the share-weighted sum
//!   of these. Normal 95 % interval, conditional on the terms the fit
//!   selected.

use super::edf::edf_oavar;
use nalgebra::DMatrix;

pub const COUNT: usize = 5;
/// JSON names (docs/interfaces.md).
pub const NAMES: [&str; COUNT] = [
    "quantization",
    "angle_random_walk_dpsh",
    "bias_instability_dph",
    "rate_random_walk",
    "rate_ramp",
];
/// Units of the reported values.
pub const UNITS: [&str; COUNT] = ["arcsec", "deg/sqrt(h)", "deg/h", "deg/h/sqrt(h)", "deg/h^2"];
/// Slopes of each term on the log-log Allan deviation.
pub const SLOPES: [&str; COUNT] = ["-1", "-1/2", "0", "+1/2", "+1"];
/// PSD exponent of the rate for the degrees of freedom.
const ALPHA: [i32; COUNT] = [2, 0, -1, -2, -2];
/// Confidence of every interval.
pub const CONF: f64 = 0.95;

/// AVAR of term j at tau for a unit coefficient (rate in deg/s, tau in s).
pub fn basis(j: usize, tau: f64) -> f64 {
    match j {
        0 => 3.0 / (tau * tau),
        1 => 1.0 / tau,
        2 => 2.0 * std::f64::consts::LN_2 / std::f64::consts::PI,
        3 => tau / 3.0,
        _ => tau * tau / 2.0,
    }
}

/// A coefficient c_j (deg^2, deg^2/s, (deg/s)^2, (deg/s)^2/s, (deg/s^2)^2)
/// in the reported unit.
pub fn to_units(j: usize, c: f64) -> f64 {
    let f = match j {
        0 => 3600.0,
        1 => 60.0,
        2 => 3600.0,
        3 => 3600.0 * 60.0,
        _ => 3600.0 * 3600.0,
    };
    c.max(0.0).sqrt() * f
}

/// The inverse of [`to_units`].
pub fn from_units(j: usize, v: f64) -> f64 {
    (v / to_units(j, 1.0)).powi(2)
}

#[derive(Clone, Debug)]
pub struct TermFit {
    pub c: [f64; COUNT],
    pub present: [bool; COUNT],
    /// Interval of each present term, in c units.
    pub lo: [f64; COUNT],
    pub hi: [f64; COUNT],
    /// Per averaging time: the model's AVAR, the noise type dominating it
    /// (index into the terms) and the degrees of freedom used.
    pub model: Vec<f64>,
    pub dominant: Vec<usize>,
    pub edf: Vec<f64>,
}

impl TermFit {
    pub fn model_at(&self, tau: f64) -> f64 {
        (0..COUNT).map(|j| self.c[j] * basis(j, tau)).sum()
    }
}

/// Non-negative weighted fit over the terms in `active`: the subset with
/// the least weighted residual among those whose solution is non-negative.
fn nnls(taus: &[f64], avar: &[f64], w: &[f64], active: &[bool; COUNT]) -> [f64; COUNT] {
    let idx: Vec<usize> = (0..COUNT).filter(|&j| active[j]).collect();
    let mut best = ([0.0; COUNT], f64::INFINITY);
    for mask in 1u32..(1 << idx.len()) {
        let sub: Vec<usize> = (0..idx.len())
            .filter(|b| mask & (1 << b) != 0)
            .map(|b| idx[b])
            .collect();
        if sub.len() > taus.len() {
            continue;
        }
        let cols: Vec<Vec<f64>> = sub
            .iter()
            .map(|&j| taus.iter().map(|&t| basis(j, t)).collect())
            .collect();
        let Some(f) = crate::numerics::lsq::wls(&cols, avar, Some(w)) else {
            continue;
        };
        if f.coef.iter().any(|&c| c < 0.0) {
            continue;
        }
        if f.sse < best.1 {
            let mut c = [0.0; COUNT];
            for (k, &j) in sub.iter().enumerate() {
                c[j] = f.coef[k];
            }
            best = (c, f.sse);
        }
    }
    best.0
}

/// Fits the terms to `avar` (deg/s)^2 at `taus` (averaging factors `ms`,
/// `n_phase` angle points).
pub fn fit(taus: &[f64], avar: &[f64], ms: &[usize], n_phase: usize) -> TermFit {
    let n = taus.len();
    let mut active = [true; COUNT];
    let mut edf: Vec<f64> = ms.iter().map(|&m| edf_oavar(0, m, n_phase)).collect();
    let mut c = [0.0; COUNT];
    let mut model = avar.to_vec();
    let mut dominant = vec![1usize; n];
    for _round in 0..COUNT {
        for it in 0..15 {
            let v: &[f64] = if it == 0 { avar } else { &model };
            let w: Vec<f64> = (0..n)
                .map(|i| edf[i] / (2.0 * v[i].max(f64::MIN_POSITIVE).powi(2)))
                .collect();
            let nc = nnls(taus, avar, &w, &active);
            let change = (0..COUNT)
                .map(|j| (nc[j] - c[j]).abs() / nc[j].abs().max(c[j].abs()).max(f64::MIN_POSITIVE))
                .fold(0.0, f64::max);
            c = nc;
            for i in 0..n {
                let parts: Vec<f64> = (0..COUNT).map(|j| c[j] * basis(j, taus[i])).collect();
                model[i] = parts.iter().sum::<f64>().max(f64::MIN_POSITIVE);
                dominant[i] = (0..COUNT)
                    .max_by(|&a, &b| parts[a].total_cmp(&parts[b]))
                    .unwrap_or(1);
                edf[i] = mixture_edf(&parts, model[i], ms[i], n_phase);
            }
            if it > 0 && change < 1e-9 {
                break;
            }
        }
        // Which terms the curve shows.
        let (present, lo, hi) = check(taus, &c, &model, &edf);
        let mut next = active;
        for j in 0..COUNT {
            if active[j] && !present[j] {
                next[j] = false;
            }
        }
        if next == active {
            return TermFit {
                c,
                present,
                lo,
                hi,
                model,
                dominant,
                edf,
            };
        }
        active = next;
        if !active.iter().any(|&a| a) {
            break;
        }
    }
    let (present, lo, hi) = check(taus, &c, &model, &edf);
    TermFit {
        c,
        present,
        lo,
        hi,
        model,
        dominant,
        edf,
    }
}

/// Degrees of freedom of an estimate whose model is a mixture: each
/// type's share s_t with its own (Greenhall) degrees of freedom, combined
/// as if fully correlated, `1/sqrt(edf) = sum s_t / sqrt(edf_t)` (a
/// mixture's estimate is no steadier than its noisiest part: next to a
/// white-angle term, whose estimates have about N degrees of freedom at
/// every tau, the white rate noise's N/m would otherwise be overlooked).
fn mixture_edf(parts: &[f64], model: f64, m: usize, n_phase: usize) -> f64 {
    let mut s = 0.0;
    for (t, &p) in parts.iter().enumerate() {
        if p > 0.0 {
            s += p / model / edf_oavar(ALPHA[t], m, n_phase).sqrt();
        }
    }
    if s > 0.0 {
        (1.0 / (s * s)).max(1.0)
    } else {
        edf_oavar(0, m, n_phase)
    }
}

type Check = ([bool; COUNT], [f64; COUNT], [f64; COUNT]);

/// Correlation of two Allan-variance estimates of one noise type at taus
/// with ratio `r` >= 1 (Monte Carlo on the project's generators): a decay
/// exp(-beta |ln(tau1/tau2)|) (a valid covariance kernel in ln tau), or a
/// constant for white angle noise, whose estimates all share its one
/// sample variance.
fn type_correlation(t: usize, r: f64) -> f64 {
    if r == 1.0 {
        return 1.0;
    }
    match t {
        0 => 0.3,
        1 => r.powf(-1.1),
        2 => r.powf(-0.7),
        _ => r.powf(-0.35),
    }
}

fn check(taus: &[f64], c: &[f64; COUNT], model: &[f64], edf: &[f64]) -> Check {
    let mut present = [false; COUNT];
    let (mut lo, mut hi) = ([0.0; COUNT], [0.0; COUNT]);
    let idx: Vec<usize> = (0..COUNT).filter(|&j| c[j] > 0.0).collect();
    let (n, p) = (taus.len(), idx.len());
    if p == 0 || n < p {
        return (present, lo, hi);
    }
    // Scale the columns (AVARs span decades) for the inversion.
    let x = DMatrix::from_fn(n, p, |i, k| basis(idx[k], taus[i]));
    let scale: Vec<f64> = (0..p)
        .map(|k| x.column(k).norm().max(f64::MIN_POSITIVE))
        .collect();
    let xs = DMatrix::from_fn(n, p, |i, k| x[(i, k)] / scale[k]);
    let sd: Vec<f64> = (0..n).map(|i| model[i] * (2.0 / edf[i]).sqrt()).collect();
    let w: Vec<f64> = sd.iter().map(|s| 1.0 / (s * s)).collect();
    let wx = DMatrix::from_fn(n, p, |i, k| w[i] * xs[(i, k)]);
    let Some(bread) = (xs.transpose() * &wx).try_inverse() else {
        return (present, lo, hi);
    };
    // Each estimate's variance shared out over the noise types in
    // proportion to their part of the model; the covariance is the sum of
    // the types' kernels (positive semi-definite by construction).
    let share: Vec<[f64; COUNT]> = (0..n)
        .map(|i| {
            let mut s = [0.0; COUNT];
            for (t, v) in s.iter_mut().enumerate() {
                *v = (c[t] * basis(t, taus[i]) / model[i]).max(0.0);
            }
            s
        })
        .collect();
    let sigma = DMatrix::from_fn(n, n, |i, j| {
        let r = taus[i].max(taus[j]) / taus[i].min(taus[j]);
        let rho: f64 = (0..COUNT)
            .map(|t| (share[i][t] * share[j][t]).sqrt() * type_correlation(t, r))
            .sum();
        rho * sd[i] * sd[j]
    });
    let meat = wx.transpose() * sigma * &wx;
    let cov = &bread * meat * &bread;
    let z = crate::numerics::stats::normal_quantile(0.5 + CONF / 2.0);
    for (k, &j) in idx.iter().enumerate() {
        let se = cov[(k, k)].max(0.0).sqrt() / scale[k];
        lo[j] = c[j] - z * se;
        hi[j] = c[j] + z * se;
        let shows = (0..n).any(|i| c[j] * basis(j, taus[i]) >= 0.5 * model[i]);
        present[j] = shows && lo[j] > 0.0;
    }
    (present, lo, hi)
}
