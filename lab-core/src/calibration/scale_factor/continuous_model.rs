//! The continuous-rotation model on the bins, for a given coil-sensor lag,
//! polynomial degree and knee temperatures: `r = w s(T) + b(T)` with
//! `s(T) = s0 + s1 x + s2 x^2 + s3 x^3 + sum c_k max(0, T - T_k)`,
//! x = T - 20 degC, up to the degree (1..=3), in the coil temperature
//! T = T_sensor + lag dT_sensor/dt; b linear where the run can tell it
//! from s. Linear once the lag and the knees are fixed; these are the
//! pieces the searches over them are made of.

use super::bins::Bins;
use super::input::MIN_RATE_DPS;
use crate::numerics::lsq::{wls, LsFit};
use crate::numerics::search::{golden, grid_then_golden};

/// Most knees tried.
pub const MAX_KNEES: usize = 3;
/// Highest polynomial degree tried.
pub const MAX_DEGREE: usize = 3;
/// Reference temperature of the polynomial, degC.
pub const T_REF_C: f64 = 20.0;
/// Knees stay this far from the ends of the data and from each other, degC.
pub const KNEE_MARGIN_C: f64 = 3.0;

/// The continuous model on the bins, for given lag and knees.
pub struct Model {
    pub b: Bins,
    /// Whether the bias is fitted (the run has both rate signs, or rest).
    pub with_bias: bool,
}

impl Model {
    /// The coil temperature of bin `i` at sensor lag `lag`.
    pub fn tc(&self, lag: f64, i: usize) -> f64 {
        self.b.ts[i] + lag * self.b.d[i]
    }

    pub fn cols(&self, lag: f64, degree: usize, knees: &[f64]) -> Vec<Vec<f64>> {
        let n = self.b.w.len();
        let tc: Vec<f64> = (0..n).map(|i| self.tc(lag, i)).collect();
        let w = &self.b.w;
        let mut cols = vec![w.clone()];
        for p in 1..=degree.clamp(1, MAX_DEGREE) {
            cols.push(
                (0..n)
                    .map(|i| w[i] * (tc[i] - T_REF_C).powi(p as i32))
                    .collect(),
            );
        }
        for &k in knees {
            cols.push((0..n).map(|i| w[i] * (tc[i] - k).max(0.0)).collect());
        }
        if self.with_bias {
            cols.push(vec![1.0; n]);
            cols.push(tc.iter().map(|t| t - T_REF_C).collect());
        }
        cols
    }

    pub fn fit(&self, lag: f64, degree: usize, knees: &[f64]) -> Option<LsFit> {
        wls(&self.cols(lag, degree, knees), &self.b.r, Some(&self.b.n))
    }

    pub fn sse(&self, lag: f64, degree: usize, knees: &[f64]) -> f64 {
        self.fit(lag, degree, knees)
            .map_or(f64::INFINITY, |f| f.sse)
    }

    /// The coil-temperature range of the rotating bins at `lag`: the
    /// calibrated range.
    pub fn coil_range(&self, lag: f64) -> (f64, f64) {
        (0..self.b.w.len())
            .filter(|&i| self.b.w[i].abs() >= MIN_RATE_DPS)
            .map(|i| self.tc(lag, i))
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), t| {
                (a.min(t), b.max(t))
            })
    }

    /// Linear parameters of the model of `degree` with `k` knees (the knee
    /// temperatures not counted).
    pub fn params(&self, degree: usize, k: usize) -> usize {
        1 + degree.clamp(1, MAX_DEGREE) + k + if self.with_bias { 2 } else { 0 }
    }

    /// Best lag for this degree and these knees: a coarse grid over
    /// 0..600 s (or a window around `hint`), then golden section.
    pub fn best_lag(&self, degree: usize, knees: &[f64], hint: Option<f64>) -> (f64, f64) {
        let f = |l: f64| self.sse(l, degree, knees);
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
pub fn knee_bounds(knees: &[f64], j: usize, lo: f64, hi: f64) -> (f64, f64) {
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

/// A model: polynomial degree (1 is the straight line), knees (sorted),
/// lag, weighted SSE.
#[derive(Clone, Debug)]
pub struct Candidate {
    pub degree: usize,
    pub knees: Vec<f64>,
    pub lag: f64,
    pub sse: f64,
}

/// Coordinate refinement of every knee (golden within +-0.75 degC), then the lag.
pub fn refine(m: &Model, c: &mut Candidate, lo: f64, hi: f64) {
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
                    m.sse(c.lag, c.degree, &k)
                },
                a,
                b,
                16,
            );
            c.knees[j] = x;
        }
        // The whole lag range: the model with one knee less may have bent
        // the lag far to imitate the knee.
        let (lag, sse) = m.best_lag(c.degree, &c.knees, None);
        c.lag = lag;
        c.sse = sse;
    }
}
