//! Profile-likelihood intervals of the two terms whose parameters enter
//! the curve nonlinearly (docs/noise.md): the sinusoid (frequency and
//! amplitude) and the Markov term (correlation time and sigma).
//!
//! The linearised (sandwich) interval of a searched parameter sees one
//! minimum of the cost. The sinusoid's cost over its frequency is a comb
//! of minima about 1/tau_max apart (fit.rs, `refine_frequency`): the noise
//! can put the best tooth one away from the truth's, and the amplitude
//! moves with the frequency. So each searched parameter p is profiled: the
//! weighted cost of the best non-negative model at each p on a fine grid,
//! the other shapes refitted; the interval holds the p whose cost rises
//! less than `z^2 v_sandwich / v_naive` above the minimum (the rise a
//! linear model's z-sigma point gives, `v_naive` = (J'WJ)^-1 the cost's
//! inverse curvature: for the correlated estimates the cost's rise is not
//! itself a chi-square, the sandwich calibrates it). The size (amplitude,
//! sigma) is profiled the same way, minimised over the parameter's
//! profile set: the frequency's uncertainty carries into the amplitude.
//! Where the cost is a parabola the intervals are the sandwich's.

use super::model::{Curve, Fitted};
use super::nnls::nnls;
use super::terms::{ALL, MARKOV, SIN};

/// The term profiled.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Which {
    Sin,
    Markov,
}

impl Which {
    fn shape(self) -> usize {
        match self {
            Which::Sin => SIN,
            Which::Markov => MARKOV,
        }
    }
    /// The coefficient for a size g (amplitude deg/s, sigma deg/s) at the
    /// parameter p (Hz, s).
    fn coef(self, g: f64, p: f64) -> f64 {
        match self {
            Which::Sin => g * g,
            Which::Markov => 2.0 * g * g / p,
        }
    }
    fn size(self, coef: f64, p: f64) -> f64 {
        match self {
            Which::Sin => coef.max(0.0).sqrt(),
            Which::Markov => (coef.max(0.0) * p / 2.0).sqrt(),
        }
    }
}

/// The variances of a quantity, sandwich and naive, and its variance
/// inflation for the misfit.
#[derive(Clone, Copy, Debug)]
pub struct Spread {
    pub sandwich: f64,
    pub naive: f64,
    pub inflation: f64,
}

impl Spread {
    fn sd(&self) -> f64 {
        (self.sandwich * self.inflation).max(0.0).sqrt()
    }
    /// The cost's rise that bounds the interval.
    fn threshold(&self, z: f64) -> f64 {
        z * z * self.inflation * self.sandwich / self.naive.max(f64::MIN_POSITIVE)
    }
}

/// The 95 % profile intervals: the parameter (Hz or s) and the size (deg/s).
#[derive(Clone, Copy, Debug)]
pub struct Profile {
    pub param: (f64, f64),
    pub size: (f64, f64),
}

/// The weighted cost of the best model with `which`'s parameter at
/// `exp(lp)` and, if `size` is given, its size fixed there.
fn cost(c: &Curve, fit: &Fitted, w: &[f64], which: Which, lp: f64, size: Option<f64>) -> f64 {
    let mut sh = fit.shapes;
    let p = lp.exp();
    match which {
        Which::Sin => sh.f = p,
        Which::Markov => sh.t = p,
    }
    let j0 = which.shape();
    let mut y = c.avar.to_vec();
    if let Some(g) = size {
        let cj = which.coef(g, p);
        for (i, v) in y.iter_mut().enumerate() {
            *v -= cj * sh.unit(j0, c.taus[i]);
        }
    }
    let cols: Vec<Vec<f64>> = (0..ALL)
        .filter(|&j| fit.has(j) && !(size.is_some() && j == j0))
        .map(|j| c.taus.iter().map(|&tau| sh.unit(j, tau)).collect())
        .collect();
    if cols.is_empty() {
        return (0..y.len()).map(|i| w[i] * y[i] * y[i]).sum();
    }
    nnls(&cols, &y, w).sse
}

/// The interval of the grid points `xs` whose rise `d` stays under `thr`
/// (their hull), its ends where the rise crosses `thr` between a point in
/// and its neighbour out, linearly.
fn hull(xs: &[f64], d: &[f64], thr: f64) -> Option<(f64, f64)> {
    let a = d.iter().position(|&v| v <= thr)?;
    let b = d.iter().rposition(|&v| v <= thr)?;
    let cross = |i: usize, o: usize| {
        let t = ((thr - d[i]) / (d[o] - d[i])).clamp(0.0, 1.0);
        xs[i] + t * (xs[o] - xs[i])
    };
    let lo = if a > 0 { cross(a, a - 1) } else { xs[0] };
    let hi = if b + 1 < xs.len() {
        cross(b, b + 1)
    } else {
        xs[b]
    };
    Some((lo, hi))
}

/// The profile intervals of `which` in `fit`: `param` the spread of the
/// log parameter, `size` that of the log size; `z` the normal quantile.
pub fn profile(
    c: &Curve,
    fit: &Fitted,
    which: Which,
    param: Spread,
    size: Spread,
    z: f64,
) -> Option<Profile> {
    let j0 = which.shape();
    if !(fit.has(j0) && param.sd() > 0.0 && size.sd() > 0.0) {
        return None;
    }
    let w: Vec<f64> = fit
        .model
        .iter()
        .zip(&fit.edf)
        .map(|(m, e)| e / (2.0 * m.max(f64::MIN_POSITIVE).powi(2)))
        .collect();
    let p0 = match which {
        Which::Sin => fit.shapes.f,
        Which::Markov => fit.shapes.t,
    };
    let lp0 = p0.ln();
    // The parameter's grid: six sandwich sigmas, and for the sinusoid at
    // least three teeth of the comb each side, a tooth in 16 steps.
    let mut half = 6.0 * param.sd();
    let mut step = param.sd() / 4.0;
    if which == Which::Sin {
        let tooth = 1.0 / (c.taus[c.n() - 1] * p0);
        half = half.max(3.0 * tooth);
        step = step.min(tooth / 16.0);
    }
    let k = ((half / step).ceil() as usize).clamp(8, 400);
    let lps: Vec<f64> = (0..=2 * k)
        .map(|i| lp0 - half + half * i as f64 / k as f64)
        .collect();
    let costs: Vec<f64> = lps
        .iter()
        .map(|&lp| cost(c, fit, &w, which, lp, None))
        .collect();
    let best = costs
        .iter()
        .copied()
        .fold(cost(c, fit, &w, which, lp0, None), f64::min);
    let rise: Vec<f64> = costs.iter().map(|v| v - best).collect();
    let (plo, phi) = hull(&lps, &rise, param.threshold(z))?;
    // The size: profiled over the parameter's points that can hold it.
    let thr = size.threshold(z);
    let inside: Vec<f64> = lps
        .iter()
        .zip(&rise)
        .filter(|(_, &r)| r <= thr)
        .map(|(&lp, _)| lp)
        .collect();
    let stride = inside.len().div_ceil(80).max(1);
    let mut ps: Vec<f64> = inside.iter().step_by(stride).copied().collect();
    ps.push(lp0);
    let g0 = which.size(fit.shapes.c[j0], p0);
    let mut reach: f64 = 0.0;
    for &lp in &ps {
        let sh = cost_free_coef(c, fit, &w, which, lp);
        let g = which.size(sh, lp.exp());
        if g > 0.0 {
            reach = reach.max((g / g0).ln().abs());
        }
    }
    let gh = reach + 6.0 * size.sd();
    let kg = 60usize;
    let lgs: Vec<f64> = (0..=2 * kg)
        .map(|i| g0.ln() - gh + gh * i as f64 / kg as f64)
        .collect();
    let grise: Vec<f64> = lgs
        .iter()
        .map(|&lg| {
            ps.iter()
                .map(|&lp| cost(c, fit, &w, which, lp, Some(lg.exp())))
                .fold(f64::INFINITY, f64::min)
                - best
        })
        .collect();
    let (glo, ghi) = hull(&lgs, &grise, thr)?;
    Some(Profile {
        param: (plo.exp(), phi.exp()),
        size: (glo.exp(), ghi.exp()),
    })
}

/// The term's coefficient in the best model with its parameter at exp(lp).
fn cost_free_coef(c: &Curve, fit: &Fitted, w: &[f64], which: Which, lp: f64) -> f64 {
    let mut sh = fit.shapes;
    match which {
        Which::Sin => sh.f = lp.exp(),
        Which::Markov => sh.t = lp.exp(),
    }
    let idx: Vec<usize> = (0..ALL).filter(|&j| fit.has(j)).collect();
    let cols: Vec<Vec<f64>> = idx
        .iter()
        .map(|&j| c.taus.iter().map(|&tau| sh.unit(j, tau)).collect())
        .collect();
    let sol = nnls(&cols, c.avar, w);
    idx.iter()
        .position(|&j| j == which.shape())
        .map_or(0.0, |k| sol.coef[k])
}
