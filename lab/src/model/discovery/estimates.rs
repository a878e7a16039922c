//! The parameters of the effects found, with their 95 % intervals, and
//! each one's share of the residual variance.

use super::design::{Design, Term};
use super::select::Selection;
use crate::model::effects::Effect;
use crate::numerics::search::{profile_interval, CHI2_1_95};

/// A found effect's parameters with 95 % intervals.
#[derive(Clone, Debug)]
pub struct Estimate {
    pub effect: Effect,
    pub params: Vec<(&'static str, f64, f64, f64)>,
    pub delta_bic: f64,
    pub explained_share: f64,
}

/// Parameters of the chosen effects from the final joint fit (nuisance
/// included), their intervals (linear: least squares with the inflated
/// residual variance; non-linear: profile likelihood) and each effect's
/// share of the residual variance (the rise of the weighted residual sum
/// without it, over the sum before any effect).
pub fn estimates(d: &Design, sel: &Selection) -> Vec<Estimate> {
    let terms: Vec<Term> = sel.terms();
    let Some((fit, r)) = d.fit(&terms) else {
        return vec![];
    };
    let sse: f64 = r.iter().zip(&d.win.count).map(|(v, c)| c * v * v).sum();
    let sse0: f64 = d.r.iter().zip(&d.win.count).map(|(v, c)| c * v * v).sum();
    let p: usize = terms
        .iter()
        .map(|t| t.effect.linear_params().len() + usize::from(t.effect.nonlinear_param().is_some()))
        .sum();
    let var = sse / (d.n() - p as f64).max(1.0);
    let v = var * sel.inflation;
    let mut out = vec![];
    let mut col = 0;
    for (j, step) in sel.chosen.iter().enumerate() {
        let e = step.term.effect;
        let mut params = vec![];
        for name in e.linear_params() {
            let (c, se) = match &fit {
                Some(f) => (f.coef[col], f.se(col, v)),
                None => (0.0, 0.0),
            };
            params.push((*name, c, c - 1.96 * se, c + 1.96 * se));
            col += 1;
        }
        if let Some(name) = e.nonlinear_param() {
            let log = e.search_log();
            let x = step.term.x;
            let prof = |u: f64| {
                let mut ts = terms.clone();
                ts[j].x = if log { u.exp() } else { u };
                d.sse(&ts)
            };
            let (u0, step_u, bounds) = if log {
                (x.ln(), 0.005, (x.ln() - 5.0, x.ln() + 5.0))
            } else {
                (x, 0.02, (x - 30.0, x + 30.0))
            };
            let (lo, hi) = profile_interval(prof, u0, sse, CHI2_1_95 * v, step_u, bounds);
            let (lo, hi) = if log { (lo.exp(), hi.exp()) } else { (lo, hi) };
            params.push((name, x, lo, hi));
        }
        let without: Vec<Term> = terms
            .iter()
            .enumerate()
            .filter(|(i, _)| *i != j)
            .map(|(_, t)| *t)
            .collect();
        let share = ((d.sse(&without) - sse) / sse0).clamp(0.0, 1.0);
        out.push(Estimate {
            effect: e,
            params,
            delta_bic: step.delta_bic,
            explained_share: share,
        });
    }
    out
}
