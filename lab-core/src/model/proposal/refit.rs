//! A term's parameters fitted to a residual: a user's term written by hand
//! in the model file (discover fits its coefficient), and a proposed term
//! refitted beside the library effects named once it is in the model.
//!
//! Generic over the term language: the Jacobian is the term's change per
//! parameter (exact for a coefficient, a finite difference for a shape
//! parameter), on the whitened rows, made orthogonal to what the fit
//! already carries; Gauss-Newton with step halving, so a parameter the
//! formula uses non-linearly converges and a linear one is exact in one
//! step.

use super::orthogonal::{basis, dot, orthogonal};
use super::validation::{cross_validate, solve, stats, Validation, FOLDS, THRESHOLD};
use crate::model::inputs::Inputs;
use crate::model::term::Term;
use std::collections::BTreeMap;

/// Whitened rows of a per-row column in deg/h.
pub type ToRows<'a> = &'a dyn Fn(&[f64]) -> Vec<f64>;

/// The fitted term, its 95 % intervals and how its coefficients predict
/// blocks of the record they were not fitted on.
#[derive(Clone, Debug, PartialEq)]
pub struct TermFit {
    pub term: Term,
    pub intervals: BTreeMap<String, (f64, f64)>,
    pub validation: Validation,
}

/// `t` with parameter `p` set to `v`.
fn with(t: &Term, p: &str, v: f64) -> Term {
    let mut u = t.clone();
    u.params.insert(p.to_string(), v);
    u
}

fn eval(t: &Term, inp: &Inputs, rows: ToRows) -> Option<Vec<f64>> {
    let v = t.evaluate(inp).ok()?;
    v.iter().all(|x| x.is_finite()).then(|| rows(&v))
}

/// Whether `t` is linear in `p` on this run (its value at p = 0, 1, 2
/// on a line): such a parameter is a coefficient.
pub fn is_linear(t: &Term, p: &str, inp: &Inputs) -> bool {
    let at = |v| with(t, p, v).evaluate(inp).ok();
    let (Some(a), Some(b), Some(c)) = (at(0.0), at(1.0), at(2.0)) else {
        return false;
    };
    let scale = b
        .iter()
        .zip(&a)
        .map(|(b, a)| (b - a).abs())
        .fold(0.0, f64::max);
    scale > 0.0
        && a.iter()
            .zip(&b)
            .zip(&c)
            .all(|((a, b), c)| (c - 2.0 * b + a).abs() <= 1e-9 * scale)
}

/// The Jacobian of `t`'s whitened rows in its parameters `free`, at its
/// current values.
fn jacobian(t: &Term, free: &[String], inp: &Inputs, rows: ToRows) -> Option<Vec<Vec<f64>>> {
    let g0 = eval(t, inp, rows)?;
    free.iter()
        .map(|p| {
            let v = t.params[p];
            let h = if v != 0.0 { 1e-4 * v.abs() } else { 1e-6 };
            let g1 = eval(&with(t, p, v + h), inp, rows)?;
            Some(g1.iter().zip(&g0).map(|(a, b)| (a - b) / h).collect())
        })
        .collect()
}

/// Solves a x = c (m x m) with the parameters whose column is nil held
/// (their step 0): a coefficient at zero leaves its shape parameter no
/// column until the coefficient moves.
fn solve_held(a: &[f64], c: &[f64]) -> Option<Vec<f64>> {
    let m = c.len();
    let big = (0..m).map(|i| a[i * m + i]).fold(0.0, f64::max);
    let mut a = a.to_vec();
    let mut c = c.to_vec();
    for i in 0..m {
        if a[i * m + i] <= 1e-12 * big {
            for j in 0..m {
                a[i * m + j] = 0.0;
                a[j * m + i] = 0.0;
            }
            a[i * m + i] = 1.0;
            c[i] = 0.0;
        }
    }
    solve(&a, &c)
}

/// Fits the parameters `free` of `t` (the others held) to `y`: the
/// whitened residual of a model WITHOUT the term, the fit carrying the
/// whitened columns `fit` beside it. None where the run cannot evaluate
/// the term or its columns are degenerate.
pub fn fit_term(
    t: &Term,
    free: &[String],
    inp: &Inputs,
    y: &[f64],
    fit: &[Vec<f64>],
    rows: ToRows,
) -> Option<TermFit> {
    let q = basis(fit);
    let yq = orthogonal(y.to_vec(), &q);
    let sse_of = |t: &Term| -> Option<f64> {
        let g = orthogonal(eval(t, inp, rows)?, &q);
        Some(yq.iter().zip(&g).map(|(a, b)| (a - b) * (a - b)).sum())
    };
    let mut cur = t.clone();
    let mut sse = sse_of(&cur)?;
    let m = free.len();
    for _ in 0..12 {
        let g = orthogonal(eval(&cur, inp, rows)?, &q);
        let r: Vec<f64> = yq.iter().zip(&g).map(|(a, b)| a - b).collect();
        let j: Vec<Vec<f64>> = jacobian(&cur, free, inp, rows)?
            .into_iter()
            .map(|c| orthogonal(c, &q))
            .collect();
        let a: Vec<f64> = (0..m * m).map(|k| dot(&j[k / m], &j[k % m])).collect();
        let c: Vec<f64> = j.iter().map(|c| dot(c, &r)).collect();
        let step = solve_held(&a, &c)?;
        let mut lambda = 1.0;
        let mut moved = false;
        for _ in 0..20 {
            let mut next = cur.clone();
            for (p, s) in free.iter().zip(&step) {
                *next.params.get_mut(p)? += lambda * s;
            }
            if let Some(s2) = sse_of(&next) {
                if s2 <= sse {
                    let gain = sse - s2;
                    cur = next;
                    sse = s2;
                    moved = gain > 1e-10 * sse.max(1e-300);
                    break;
                }
            }
            lambda *= 0.5;
        }
        if !moved {
            break;
        }
    }
    // Intervals: var (J'J)^-1 at the optimum, the variance that of the
    // whitened residual left.
    let j: Vec<Vec<f64>> = jacobian(&cur, free, inp, rows)?
        .into_iter()
        .map(|c| orthogonal(c, &q))
        .collect();
    let n = y.iter().filter(|v| **v != 0.0).count() as f64;
    let var = sse / (n - (q.len() + m) as f64).max(1.0);
    let a: Vec<f64> = (0..m * m).map(|k| dot(&j[k / m], &j[k % m])).collect();
    let mut intervals = BTreeMap::new();
    for (i, p) in free.iter().enumerate() {
        let mut e = vec![0.0; m];
        e[i] = 1.0;
        // A parameter the record cannot fix gets no interval (NaN).
        let se = solve(&a, &e).map_or(f64::NAN, |inv| (var * inv[i]).max(0.0).sqrt());
        let v = cur.params[p];
        intervals.insert(p.clone(), (v - 1.96 * se, v + 1.96 * se));
    }
    // Validation: the coefficients (the linear parameters) refitted on
    // blocks of the record and judged on the others, the shape held.
    let lin: Vec<usize> = (0..m).filter(|&i| is_linear(&cur, &free[i], inp)).collect();
    let cols: Vec<Vec<f64>> = lin.iter().map(|&i| j[i].clone()).collect();
    // The residual with the term's linear part put back: what the
    // coefficients are fitted to, fold by fold.
    let g = orthogonal(eval(&cur, inp, rows)?, &q);
    let mut base = yq.clone();
    base.iter_mut().zip(&g).for_each(|(a, b)| *a -= b);
    for (&i, c) in lin.iter().zip(&cols) {
        let v = cur.params[&free[i]];
        base.iter_mut().zip(c).for_each(|(a, b)| *a += v * b);
    }
    let validation = if cols.is_empty() || y.len() < 4 * FOLDS {
        Validation {
            folds: 0,
            held_out_gain: f64::NAN,
            fold_gains: vec![],
            threshold: THRESHOLD,
            held_out_share: f64::NAN,
        }
    } else {
        let (gain, folds) = cross_validate(&[stats(&cols, &base, FOLDS)], FOLDS);
        let v = var.max(1e-300);
        Validation {
            folds: FOLDS,
            held_out_gain: gain / v,
            fold_gains: folds.iter().map(|g| g / v).collect(),
            threshold: THRESHOLD,
            held_out_share: gain / dot(&base, &base).max(1e-300),
        }
    };
    Some(TermFit {
        term: cur,
        intervals,
        validation,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::data::run_file::Column;
    use rand_core::SeedableRng;
    use rand_distr::{Distribution, StandardNormal};

    fn run(n: usize) -> Inputs {
        let t: Vec<f64> = (0..n).map(|k| k as f64 + 1.0).collect();
        let w: Vec<f64> = (0..n)
            .map(|k| [0.0, 50.0, -50.0, 200.0, -200.0, 10.0][(k / 300) % 6])
            .collect();
        Inputs::new(t, w, None, None, None, None)
    }

    fn noise(n: usize, seed: u64) -> Vec<f64> {
        let mut r = rand_xoshiro::Xoshiro256PlusPlus::seed_from_u64(seed);
        (0..n).map(|_| StandardNormal.sample(&mut r)).collect()
    }

    /// A user's exponential written with a wrong time constant and no
    /// coefficient: both fitted, the truth inside the intervals.
    #[test]
    fn a_users_exponential_gets_its_coefficient_and_time_constant() {
        let n = 7200;
        let inp = run(n);
        let e = noise(n, 3);
        let y: Vec<f64> = inp
            .t
            .iter()
            .zip(&e)
            .map(|(t, e)| 6.0 * (-t / 1500.0).exp() + e)
            .collect();
        let params: BTreeMap<String, f64> =
            [("k_dph".to_string(), 0.0), ("tau_s".to_string(), 900.0)].into();
        let t = Term::new(
            &format!("k_dph * exp(-{} / tau_s)", Column::Time.name()),
            params,
        )
        .unwrap();
        let free = vec!["k_dph".to_string(), "tau_s".to_string()];
        let f = fit_term(&t, &free, &inp, &y, &[vec![1.0; n]], &|x| x.to_vec()).unwrap();
        for (p, truth) in [("k_dph", 6.0), ("tau_s", 1500.0)] {
            let (lo, hi) = f.intervals[p];
            assert!(lo < truth && truth < hi, "{p}: {lo} .. {hi}");
        }
        assert!(f.validation.held_out_gain > THRESHOLD, "{:?}", f.validation);
    }

    #[test]
    fn linearity_is_told_from_the_formula_on_the_run() {
        let inp = run(1000);
        let params: BTreeMap<String, f64> =
            [("k_dph".to_string(), 1.0), ("tau_s".to_string(), 900.0)].into();
        let t = Term::new(
            &format!("k_dph * exp(-{} / tau_s)", Column::Time.name()),
            params,
        )
        .unwrap();
        assert!(is_linear(&t, "k_dph", &inp));
        assert!(!is_linear(&t, "tau_s", &inp));
    }
}
