//! The columns a discovery's fit carries, per row and mapped as the
//! caller needs (whitened, or to the gap's 1 s means), and from them a
//! least-squares bound on what a library name saves beside the proposed
//! terms (outside.rs's `prune` skips the library runs it makes needless).

use super::result::Discovery;
use crate::model::effects::Effect;
use crate::model::gyro_model::Model;
use crate::model::inputs::Inputs;
use crate::model::proposal::orthogonal::{basis, dot, orthogonal};
use crate::model::proposal::refit::is_linear;
use crate::model::term::Term;

/// The columns of `d`'s fit (outside.rs's `fit_columns`, but term `skip.0` and
/// effect `skip.1`), per row in deg/s, each mapped by `map`.
pub fn columns_of(
    given: &Model,
    d: &Discovery,
    inp: &Inputs,
    skip: (Option<usize>, Option<Effect>),
    map: &dyn Fn(&[f64]) -> Vec<f64>,
) -> Vec<Vec<f64>> {
    let mut cols = vec![map(&vec![1.0; inp.len()])];
    for e in d.model_after.effects.iter().skip(given.effects.len()) {
        if Some(e.effect) == skip.1 {
            continue;
        }
        let c0 = e.effect.contribution(inp, &e.params);
        for (p, &v) in &e.params {
            let h = if v != 0.0 { 1e-4 * v.abs() } else { 1e-6 };
            let mut q = e.params.clone();
            q.insert(p.clone(), v + h);
            let c1 = e.effect.contribution(inp, &q);
            let col: Vec<f64> = c1.iter().zip(&c0).map(|(a, b)| (a - b) / h).collect();
            cols.push(map(&col));
        }
    }
    for (i, t) in d.model_after.terms.iter().enumerate() {
        if Some(i) != skip.0 {
            cols.extend(term_columns(t, inp, map));
        }
    }
    cols
}

/// A term's columns: its derivative in each parameter, per row in deg/s,
/// each mapped by `map`.
pub fn term_columns(t: &Term, inp: &Inputs, map: &dyn Fn(&[f64]) -> Vec<f64>) -> Vec<Vec<f64>> {
    let Ok(g0) = t.evaluate(inp) else {
        return vec![];
    };
    let mut cols = vec![];
    for (p, &v) in &t.params {
        let h = if v != 0.0 { 1e-4 * v.abs() } else { 1e-6 };
        let mut u = t.clone();
        u.params.insert(p.clone(), v + h);
        if let Ok(g1) = u.evaluate(inp) {
            let col: Vec<f64> = g1
                .iter()
                .zip(&g0)
                .map(|(a, b)| (a - b) / h / 3600.0)
                .collect();
            cols.push(map(&col));
        }
    }
    cols
}

/// At least what library name `e` saves beside the rest of `cur`'s fit
/// (and `extra`'s parameters), in the noise variances `prune` counts:
/// the gap's 1 s means with `e` taken out and every other column refitted
/// by least squares, less the gap now. No refit linear in them (a shape's
/// parameters to first order, a term's also far off) leaves less, so a
/// name saving several times its criterion by it is kept unasked.
pub fn saves_at_least(
    given: &Model,
    cur: &Discovery,
    e: Effect,
    (extra, near): (Option<&Term>, Option<usize>),
    inp: &Inputs,
) -> f64 {
    let gw = &cur.gap_windows;
    let map = |x: &[f64]| gw.mean(x);
    let Some(fx) = cur.model_after.effects.iter().find(|x| x.effect == e) else {
        return 0.0;
    };
    let mut cols = columns_of(given, cur, inp, (None, Some(e)), &map);
    if let Some(t) = extra {
        cols.extend(term_columns(t, inp, &map));
    }
    // A shape's parameter may move far (a lag's time constant to none,
    // where it is its input; a step's onset to the record's start, where
    // it is a scale factor): the term at 0.01 to 100 times each; but term
    // `near`'s, a variant's own, whose far moves the library run without
    // the name has tried.
    for (_, t) in cur
        .model_after
        .terms
        .iter()
        .enumerate()
        .filter(|(i, _)| Some(*i) != near)
    {
        for p in t.params.keys().filter(|p| !is_linear(t, p, inp)) {
            for f in [0.01, 0.3, 3.0, 100.0] {
                let mut u = t.clone();
                u.params.insert(p.clone(), t.params[p] * f);
                if let Ok(g) = u.evaluate(inp) {
                    let g: Vec<f64> = g.iter().map(|v| v / 3600.0).collect();
                    cols.push(map(&g));
                }
            }
        }
    }
    let q = basis(&cols);
    let r = gw.mean(&cur.residual_after);
    let c = gw.mean(&fx.effect.contribution(inp, &fx.params));
    let without = orthogonal(r.iter().zip(&c).map(|(a, b)| a + b).collect(), &q);
    let floor = cur.noise_floor_dph / 3600.0;
    (dot(&without, &without) - dot(&r, &r)) / (floor * floor).max(1e-300)
}

/// How many times its criterion [`saves_at_least`] must show a name to
/// save before `prune` keeps it unasked.
pub const SURELY: f64 = 3.0;
