//! The windowed regression problem of discovery: the residual's window
//! means against the window means of each effect's columns, the joint fit
//! of a set of effects at their non-linear parameters, the search of those
//! parameters, and the variance inflation for correlated noise.

use super::windows::Windows;
use crate::model::effects::Effect;
use crate::model::inputs::Inputs;
use crate::numerics::lsq::{wls, LsFit};
use crate::numerics::search::{golden, grid_then_golden};

/// An effect in the fit, at its non-linear parameter.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Term {
    pub effect: Effect,
    pub x: f64,
}

/// The windowed problem.
pub struct Design<'a> {
    pub inp: &'a Inputs,
    pub win: &'a Windows,
    /// Window means of the residual, deg/s.
    pub r: Vec<f64>,
}

/// A term's windowed columns and offset.
type WBasis = (Vec<Vec<f64>>, Option<Vec<f64>>);

impl Design<'_> {
    fn wbasis(&self, t: &Term) -> WBasis {
        let b = t.effect.basis(self.inp, t.x);
        (
            b.cols.iter().map(|c| self.win.mean(c)).collect(),
            b.offset.map(|o| self.win.mean(&o)),
        )
    }

    /// Joint fit of `terms`: the least-squares fit (None without linear
    /// columns) and the residual.
    pub fn fit(&self, terms: &[Term]) -> Option<(Option<LsFit>, Vec<f64>)> {
        let mut y = self.r.clone();
        let mut cols = vec![];
        for t in terms {
            let (c, o) = self.wbasis(t);
            if let Some(o) = o {
                for (a, b) in y.iter_mut().zip(o) {
                    *a -= b;
                }
            }
            cols.extend(c);
        }
        if cols.is_empty() {
            return Some((None, y));
        }
        let f = wls(&cols, &y, Some(&self.win.count))?;
        let resid = f.resid.clone();
        Some((Some(f), resid))
    }

    /// Weighted sum of squared residual of a joint fit (infinite when
    /// singular).
    pub fn sse(&self, terms: &[Term]) -> f64 {
        match self.fit(terms) {
            Some((_, r)) => r.iter().zip(&self.win.count).map(|(v, c)| c * v * v).sum(),
            None => f64::INFINITY,
        }
    }

    pub fn n(&self) -> f64 {
        self.win.len() as f64
    }

    /// Best non-linear parameter of `terms[j]` with the others held: grid
    /// then golden section (in ln x for positive, decade-spanning ones).
    pub fn optimize(&self, terms: &mut [Term], j: usize) {
        let e = terms[j].effect;
        if e.nonlinear_param().is_none() {
            return;
        }
        let grid = e.search_grid(self.inp);
        if grid.is_empty() {
            return;
        }
        let log = e.search_log();
        let mut ts = terms.to_vec();
        let cost = |v: f64| {
            ts[j].x = if log { v.exp() } else { v };
            self.sse(&ts)
        };
        let g: Vec<f64> = if log {
            grid.iter().map(|x| x.ln()).collect()
        } else {
            grid
        };
        let (v, _) = grid_then_golden(cost, &g, 30);
        terms[j].x = if log { v.exp() } else { v };
    }

    /// Local re-fit of `terms[j]`'s non-linear parameter around its value.
    pub fn refine(&self, terms: &mut [Term], j: usize) {
        let e = terms[j].effect;
        if e.nonlinear_param().is_none() {
            return;
        }
        let log = e.search_log();
        let x0 = if log { terms[j].x.ln() } else { terms[j].x };
        let half = if log { 0.3 } else { 1.0 };
        let mut ts = terms.to_vec();
        let (v, _) = golden(
            |v: f64| {
                ts[j].x = if log { v.exp() } else { v };
                self.sse(&ts)
            },
            x0 - half,
            x0 + half,
            25,
        );
        terms[j].x = if log { v.exp() } else { v };
    }

    /// Variance inflation of the windowed residual of `terms` for
    /// correlated noise, within 1..100: the largest batch-means ratio over
    /// block lengths of 2, 4, 8 ... windows up to a sixteenth of the record
    /// (the variance of block means times the block length, over the
    /// windows' variance: 1 for white noise). Bias instability and random
    /// walk wander most at the slow effects' hour scales, which a lag-1
    /// correlation of 1 s windows (or an Allan term fit, where white noise
    /// dominates every measured tau) does not see; unweighted by it, their
    /// wander passes for a thermal term or a bias.
    pub fn inflation(&self, terms: &[Term]) -> f64 {
        let Some((_, r)) = self.fit(terms) else {
            return 1.0;
        };
        let n = r.len();
        let var = |x: &[f64]| {
            let m = x.iter().sum::<f64>() / x.len() as f64;
            x.iter().map(|v| (v - m).powi(2)).sum::<f64>() / (x.len() - 1).max(1) as f64
        };
        let v1 = var(&r);
        if v1.is_nan() || v1 <= 0.0 {
            return 1.0;
        }
        let mut phi: f64 = 1.0;
        let mut l = 2;
        while l * 16 <= n {
            let means: Vec<f64> = r
                .chunks_exact(l)
                .map(|c| c.iter().sum::<f64>() / l as f64)
                .collect();
            phi = phi.max(var(&means) * l as f64 / v1);
            l *= 2;
        }
        phi.clamp(1.0, 100.0)
    }
}
