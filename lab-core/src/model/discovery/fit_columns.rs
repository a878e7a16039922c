//! The columns a discovery's fit carries, per row and mapped as the
//! caller needs (whitened, or to the gap's 1 s means), and from them a
//! least-squares bound on what a library name saves beside the proposed
//! terms (outside.rs's `prune` skips the library runs it makes needless).

use super::normal::normal_solve;
use super::result::Discovery;
use crate::model::effects::Effect;
use crate::model::gyro_model::Model;
use crate::model::inputs::Inputs;
use crate::model::proposal::orthogonal::{basis, dot, orthogonal};
use crate::model::proposal::refit::is_linear;
use crate::model::term::Term;
use std::collections::BTreeMap;

/// A contribution per row at the parameters given (None where it cannot
/// be evaluated).
type Contribution<'a> = dyn Fn(&BTreeMap<String, f64>) -> Option<Vec<f64>> + 'a;

/// Per row, the derivative of `f` in each parameter of `params` that
/// `keep` lets through, by a forward difference, in deg/s (`per_dps` of
/// `f`'s unit make a deg/s: 3600 for deg/h), each mapped by `map`.
fn derivatives(
    params: &BTreeMap<String, f64>,
    f: &Contribution,
    (keep, per_dps): (&dyn Fn(&str) -> bool, f64),
    map: &dyn Fn(&[f64]) -> Vec<f64>,
) -> Vec<Vec<f64>> {
    let Some(f0) = f(params) else {
        return vec![];
    };
    let mut cols = vec![];
    for (p, &v) in params.iter().filter(|(p, _)| keep(p)) {
        let h = if v != 0.0 { 1e-4 * v.abs() } else { 1e-6 };
        let mut q = params.clone();
        q.insert(p.clone(), v + h);
        if let Some(f1) = f(&q) {
            let col: Vec<f64> = f1
                .iter()
                .zip(&f0)
                .map(|(a, b)| (a - b) / h / per_dps)
                .collect();
            cols.push(map(&col));
        }
    }
    cols
}

/// The constant and every parameter of the effects `d` added to `given`
/// but `skip`, per row in deg/s, each mapped by `map`.
fn effect_columns(
    given: &Model,
    d: &Discovery,
    inp: &Inputs,
    skip: Option<Effect>,
    map: &dyn Fn(&[f64]) -> Vec<f64>,
) -> Vec<Vec<f64>> {
    let mut cols = vec![map(&vec![1.0; inp.len()])];
    for e in d.model_after.effects.iter().skip(given.effects.len()) {
        if Some(e.effect) != skip {
            let f = |q: &BTreeMap<String, f64>| Some(e.effect.contribution(inp, q));
            cols.extend(derivatives(&e.params, &f, (&|_| true, 1.0), map));
        }
    }
    cols
}

/// The columns of `d`'s fit (outside.rs's `fit_columns`, but term `skip.0` and
/// effect `skip.1`), per row in deg/s, each mapped by `map`.
pub fn columns_of(
    given: &Model,
    d: &Discovery,
    inp: &Inputs,
    skip: (Option<usize>, Option<Effect>),
    map: &dyn Fn(&[f64]) -> Vec<f64>,
) -> Vec<Vec<f64>> {
    let mut cols = effect_columns(given, d, inp, skip.1, map);
    for (i, t) in d.model_after.terms.iter().enumerate() {
        if Some(i) != skip.0 {
            cols.extend(term_columns(t, inp, map));
        }
    }
    cols
}

/// A term's derivatives in the parameters `keep` lets through, per row in
/// deg/s, each mapped by `map`.
fn term_derivatives(
    t: &Term,
    inp: &Inputs,
    keep: &dyn Fn(&str) -> bool,
    map: &dyn Fn(&[f64]) -> Vec<f64>,
) -> Vec<Vec<f64>> {
    let f = |q: &BTreeMap<String, f64>| {
        let mut u = t.clone();
        u.params = q.clone();
        u.evaluate(inp).ok()
    };
    derivatives(&t.params, &f, (keep, 3600.0), map)
}

/// A term's columns: its derivative in each parameter, per row in deg/s,
/// each mapped by `map`.
pub fn term_columns(t: &Term, inp: &Inputs, map: &dyn Fn(&[f64]) -> Vec<f64>) -> Vec<Vec<f64>> {
    term_derivatives(t, inp, &|_| true, map)
}

/// The terms of `d`'s model from `from` on, their linear coefficients
/// fitted jointly (each term's other parameters held, the effects and the
/// earlier terms carried) on the residual whitened by `map`. A term added
/// after another is fitted beside the first held at its value, and two
/// terms on one input (a temperature's square and its cube) are as
/// correlated as their coefficients are: held, the first keeps what the
/// second should take. None where the fit is degenerate or nothing moves.
pub fn jointly_linear(
    given: &Model,
    d: &Discovery,
    inp: &Inputs,
    from: usize,
    map: &dyn Fn(&[f64]) -> Vec<f64>,
) -> Option<Vec<Term>> {
    let terms = &d.model_after.terms;
    let mut carried = effect_columns(given, d, inp, None, map);
    for t in terms.iter().take(from) {
        carried.extend(term_columns(t, inp, map));
    }
    let q = basis(&carried);
    let mut cols = vec![];
    let mut which = vec![];
    for (i, t) in terms.iter().enumerate().skip(from) {
        let linear = |p: &str| is_linear(t, p, inp);
        for p in t.params.keys().filter(|p| linear(p)) {
            which.push((i, p.clone()));
        }
        cols.extend(term_derivatives(t, inp, &linear, map));
    }
    if cols.is_empty() || cols.len() != which.len() {
        return None;
    }
    // A column the carried ones (nearly) hold, a term linear in what the
    // library names beside it, is round-off once they are taken out: its
    // step would be noise, so there is none.
    let mut out_cols = vec![];
    for c in cols {
        let was = dot(&c, &c);
        let o = orthogonal(c, &q);
        let kept = dot(&o, &o);
        if kept.is_nan() || kept <= 1e-12 * was {
            return None;
        }
        out_cols.push(o);
    }
    let cols = out_cols;
    let y = orthogonal(map(&d.residual_after), &q);
    let step = normal_solve(&cols, &y)?;
    if step.iter().any(|s| !s.is_finite()) || step.iter().all(|s| *s == 0.0) {
        return None;
    }
    let mut out: Vec<Term> = terms[from..].to_vec();
    for ((i, p), s) in which.iter().zip(&step) {
        *out[i - from].params.get_mut(p)? += s;
    }
    Some(out)
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
    let terms = &cur.model_after.terms;
    for t in (0..terms.len())
        .filter(|i| Some(*i) != near)
        .map(|i| &terms[i])
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
