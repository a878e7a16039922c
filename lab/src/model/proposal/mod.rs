//! Proposal of a term outside the physics library (issue 32): where the
//! residual holds structure no library effect explains, the simplest term
//! built from the run's own inputs that predicts data it was not fitted on.
//!
//! - candidates.rs: the candidate space, each a formula of the model
//!   file's term language (model/term/), so what is validated is what is
//!   written;
//! - validation.rs: blocked cross-validation on the whitened rows, and the
//!   threshold that pays for the whole space.
//!
//! The caller (discovery) gives the whitened residual of its fit, the
//! whitened columns the fit carries, and the map from a per-row column
//! (deg/h) to whitened rows; the noise model is its, so coloured noise is
//! judged as the noise model says and a candidate gains only what the
//! noise cannot already predict.

pub mod candidates;
pub mod refit;
pub mod validation;

use crate::model::inputs::Inputs;
use crate::model::term::Term;
use candidates::{candidates, Candidate};
use std::collections::BTreeMap;
use validation::{cross_validate, stats, BlockStats, FOLDS, THRESHOLD};

/// How a proposed term was checked on data it was not fitted on.
#[derive(Clone, Debug, PartialEq)]
pub struct Validation {
    pub folds: usize,
    /// Held-out reduction of the sum of squares over all folds, in
    /// variances of the whitened noise, and per fold.
    pub held_out_gain: f64,
    pub fold_gains: Vec<f64>,
    pub threshold: f64,
    /// The share of the whitened residual the term predicts out of sample.
    pub held_out_share: f64,
}

/// A term proposed, its coefficients fitted on the whole record.
#[derive(Clone, Debug, PartialEq)]
pub struct Proposed {
    pub label: &'static str,
    /// The term as the model file writes it (coefficients and the
    /// searched parameter among its parameters).
    pub term: Term,
    /// 95 % intervals of the parameters (the searched one's from the
    /// profile of the sum of squares over its grid).
    pub intervals: BTreeMap<String, (f64, f64)>,
    pub validation: Validation,
}

/// A candidate's score.
#[derive(Clone, Debug, PartialEq)]
pub struct Tried {
    pub label: &'static str,
    pub formula: String,
    pub held_out_gain: f64,
}

/// The outcome: the term proposed (none when no candidate predicts beyond
/// the threshold), and every candidate's score, best first.
#[derive(Clone, Debug, PartialEq)]
pub struct Proposal {
    pub proposed: Option<Proposed>,
    pub tried: Vec<Tried>,
}

/// Unit vectors spanning `cols` (modified Gram-Schmidt; dependent columns
/// dropped).
pub(crate) fn basis(cols: &[Vec<f64>]) -> Vec<Vec<f64>> {
    let mut q: Vec<Vec<f64>> = vec![];
    for c in cols {
        let mut v = c.clone();
        let n0 = dot(&v, &v).sqrt();
        for u in &q {
            let p = dot(u, &v);
            v.iter_mut().zip(u).for_each(|(a, b)| *a -= p * b);
        }
        let n = dot(&v, &v).sqrt();
        if n > 1e-9 * n0.max(1e-300) {
            v.iter_mut().for_each(|a| *a /= n);
            q.push(v);
        }
    }
    q
}

pub(crate) fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// A candidate's whitened columns at one value of its searched parameter,
/// made orthogonal to the fit's basis `q`; None where the run cannot
/// evaluate it.
fn columns(
    c: &Candidate,
    value: Option<f64>,
    inp: &Inputs,
    to_rows: &dyn Fn(&[f64]) -> Vec<f64>,
    q: &[Vec<f64>],
) -> Option<Vec<Vec<f64>>> {
    let mut params = BTreeMap::new();
    if let (Some(s), Some(v)) = (&c.searched, value) {
        params.insert(s.name.to_string(), v);
    }
    c.parts
        .iter()
        .map(|p| {
            let t = Term::new(&p.shape, params.clone()).ok()?;
            let mut x = to_rows(&t.evaluate(inp).ok()?);
            for u in q {
                let d = dot(u, &x);
                x.iter_mut().zip(u).for_each(|(a, b)| *a -= d * b);
            }
            (dot(&x, &x) > 0.0).then_some(x)
        })
        .collect()
}

/// Values of a searched parameter tried between the coarse grid's
/// neighbours of its best.
const REFINE: usize = 40;

/// A candidate with its statistics at each value of its searched
/// parameter kept, the values, its held-out gain and its folds' gains.
type Scored = (Candidate, Vec<BlockStats>, Vec<Option<f64>>, f64, Vec<f64>);

/// Proposes a term for the whitened residual `y` of a fit whose whitened
/// columns are `fit` (the constant among them). `inp` are the inputs the
/// candidates are built from and `to_rows` maps a value per input row
/// (deg/h) to the whitened rows of `y`.
pub fn propose(
    inp: &Inputs,
    y: &[f64],
    fit: &[Vec<f64>],
    to_rows: &dyn Fn(&[f64]) -> Vec<f64>,
) -> Proposal {
    let q = basis(fit);
    let n = y.len();
    let mut scored: Vec<Scored> = vec![];
    for c in candidates(inp) {
        let values: Vec<Option<f64>> = match &c.searched {
            Some(s) => s.grid.iter().map(|&v| Some(v)).collect(),
            None => vec![None],
        };
        let mut grid = vec![];
        let mut kept = vec![];
        for v in values {
            if let Some(cols) = columns(&c, v, inp, to_rows, &q) {
                grid.push(stats(&cols, y, FOLDS));
                kept.push(v);
            }
        }
        if grid.is_empty() || n < 4 * FOLDS {
            continue;
        }
        let (gain, folds) = cross_validate(&grid, FOLDS);
        scored.push((c, grid, kept, gain, folds));
    }
    scored.sort_by(|a, b| b.3.total_cmp(&a.3));
    // The noise's variance: what the residual holds beyond the best
    // candidate's in-sample fit (conservative while a term is in it).
    let ss: f64 = dot(y, y);
    let best_red = scored
        .first()
        .and_then(|s| {
            s.1.iter()
                .filter_map(|g| g.fit(None))
                .map(|f| f.1)
                .reduce(f64::max)
        })
        .unwrap_or(0.0);
    let var = ((ss - best_red) / (n as f64 - 3.0).max(1.0)).max(1e-300);
    let tried: Vec<Tried> = scored
        .iter()
        .map(|s| Tried {
            label: s.0.label,
            formula: s.0.formula(),
            held_out_gain: s.3 / var,
        })
        .collect();
    // The simplest of those within a few percent of the best.
    let top = scored.first().map_or(0.0, |s| s.3);
    let pick = scored
        .iter()
        .filter(|s| s.3 >= 0.97 * top && s.3 / var >= THRESHOLD)
        .min_by_key(|s| s.0.freedom());
    let proposed = pick.and_then(|(c, grid, kept, gain, folds)| {
        // The searched parameter refined between the coarse grid's
        // neighbours of its best value, so its value and profile interval
        // are not the grid's.
        let mut grid = grid.clone();
        let mut kept = kept.clone();
        let coarse_best = grid
            .iter()
            .enumerate()
            .filter_map(|(i, g)| g.fit(None).map(|f| (i, f.1)))
            .max_by(|a, b| a.1.total_cmp(&b.1))
            .map(|b| b.0);
        if let (Some(b), Some(_)) = (coarse_best, &c.searched) {
            let lo = kept[b.saturating_sub(1)];
            let hi = kept[(b + 1).min(kept.len() - 1)];
            if let (Some(lo), Some(hi)) = (lo, hi) {
                for k in 1..REFINE {
                    let v = lo + (hi - lo) * k as f64 / REFINE as f64;
                    if let Some(cols) = columns(c, Some(v), inp, to_rows, &q) {
                        grid.push(stats(&cols, y, FOLDS));
                        kept.push(Some(v));
                    }
                }
            }
        }
        let fits: Vec<(usize, Vec<f64>, f64)> = grid
            .iter()
            .enumerate()
            .filter_map(|(i, g)| g.fit(None).map(|(b, r)| (i, b, r)))
            .collect();
        let (i, beta, red) = fits.iter().max_by(|a, b| a.2.total_cmp(&b.2))?.clone();
        let mut params = BTreeMap::new();
        let mut intervals = BTreeMap::new();
        let (a, _) = grid[i].sums(None);
        for (j, p) in c.parts.iter().enumerate() {
            // The coefficient's variance: var (X'X)^-1 at (j, j).
            let mut e = vec![0.0; c.parts.len()];
            e[j] = 1.0;
            let inv = validation::solve(&a, &e)?;
            let se = (var * inv[j]).sqrt();
            params.insert(p.coef.to_string(), beta[j]);
            intervals.insert(
                p.coef.to_string(),
                (beta[j] - 1.96 * se, beta[j] + 1.96 * se),
            );
        }
        if let (Some(s), Some(v)) = (&c.searched, kept[i]) {
            // Profile: the values whose fit is within chi2(1, 95 %) of the
            // best, widened by the spacing of the values tried about them.
            let ok: Vec<f64> = fits
                .iter()
                .filter(|f| red - f.2 <= 3.84 * var)
                .filter_map(|f| kept[f.0])
                .collect();
            let mut all: Vec<f64> = kept.iter().flatten().copied().collect();
            all.sort_by(f64::total_cmp);
            let step_at = |x: f64| -> f64 {
                let k = all.partition_point(|&a| a < x);
                let below = if k > 0 { x - all[k - 1] } else { 0.0 };
                let above = all.get(k + 1).map_or(0.0, |a| a - x);
                below.max(above)
            };
            let lo = ok.iter().copied().fold(v, f64::min);
            let hi = ok.iter().copied().fold(v, f64::max);
            params.insert(s.name.to_string(), v);
            intervals.insert(s.name.to_string(), (lo - step_at(lo), hi + step_at(hi)));
        }
        let term = Term::new(&c.formula(), params).ok()?;
        Some(Proposed {
            label: c.label,
            term,
            intervals,
            validation: Validation {
                folds: FOLDS,
                held_out_gain: gain / var,
                fold_gains: folds.iter().map(|g| g / var).collect(),
                threshold: THRESHOLD,
                held_out_share: gain / ss.max(1e-300),
            },
        })
    });
    Proposal { proposed, tried }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand_core::SeedableRng;
    use rand_distr::{Distribution, StandardNormal};

    /// A table-like run at 1 row per window: rate steps and a drifting
    /// temperature.
    fn run(n: usize) -> Inputs {
        let t: Vec<f64> = (0..n).map(|k| k as f64 + 1.0).collect();
        let w: Vec<f64> = (0..n)
            .map(|k| [0.0, 50.0, -50.0, 200.0, -200.0, 10.0, -10.0, 100.0][(k / 300) % 8])
            .collect();
        let temp: Vec<f64> = t.iter().map(|t| 25.0 + 15.0 * (t / 5000.0).sin()).collect();
        Inputs::new(t, w, Some(temp), None, None, None)
    }

    fn noise(n: usize, seed: u64) -> Vec<f64> {
        let mut r = rand_xoshiro::Xoshiro256PlusPlus::seed_from_u64(seed);
        (0..n).map(|_| StandardNormal.sample(&mut r)).collect()
    }

    fn constant(n: usize) -> Vec<Vec<f64>> {
        vec![vec![1.0; n]]
    }

    #[test]
    fn a_hidden_rate_squared_term_is_proposed_with_its_coefficient() {
        let n = 7200;
        let inp = run(n);
        let k = 2e-4; // deg/h per (deg/s)^2: 8 deg/h at 200 deg/s
                      // The residual in units of a 1 deg/h white noise (whitened = /1).
        let e = noise(n, 7);
        let y: Vec<f64> = inp
            .w
            .iter()
            .zip(&e)
            .map(|(w, e)| 3.0 + k * w * w + e)
            .collect();
        let p = propose(&inp, &y, &constant(n), &|x| x.to_vec());
        let got = p.proposed.expect("a term");
        assert_eq!(got.label, "rate squared", "{:?}", p.tried);
        let (lo, hi) = got.intervals["k_dph"];
        assert!(lo < k && k < hi, "{lo} {hi}");
        assert!((got.term.params["k_dph"] - k).abs() < 0.02 * k);
        assert!(
            got.validation.held_out_gain > 100.0 * THRESHOLD,
            "{:?}",
            got.validation
        );
    }

    #[test]
    fn a_step_is_proposed_at_its_time() {
        let n = 7200;
        let inp = run(n);
        let e = noise(n, 8);
        let y: Vec<f64> = inp
            .t
            .iter()
            .zip(&e)
            .map(|(t, e)| if *t >= 4000.0 { 0.5 } else { 0.0 } + e)
            .collect();
        let p = propose(&inp, &y, &constant(n), &|x| x.to_vec());
        let got = p.proposed.expect("a term");
        assert_eq!(got.label, "step", "{:?}", p.tried);
        let (lo, hi) = got.intervals["t0_s"];
        assert!(lo <= 4000.0 + 70.0 && hi >= 4000.0 - 70.0, "{lo} {hi}");
    }

    #[test]
    fn white_noise_gets_no_term() {
        let n = 7200;
        let inp = run(n);
        for seed in 0..5 {
            let y = noise(n, 100 + seed);
            let p = propose(&inp, &y, &constant(n), &|x| x.to_vec());
            assert!(p.proposed.is_none(), "seed {seed}: {:?}", p.tried.first());
        }
    }

    /// Random walk, whitened exactly (first differences, as the noise
    /// model's whitener does for a walk): no term on the walk alone, the
    /// rate-squared term under it.
    #[test]
    fn a_random_walk_is_not_a_term_once_whitened() {
        let n = 7200;
        let inp = run(n);
        let diff = |x: &[f64]| -> Vec<f64> { x.windows(2).map(|p| p[1] - p[0]).collect() };
        for seed in 0..4 {
            let mut walk = 0.0;
            let y: Vec<f64> = noise(n, 200 + seed)
                .iter()
                .map(|e| {
                    walk += e;
                    walk
                })
                .collect();
            let p = propose(&inp, &diff(&y), &[], &diff);
            assert!(p.proposed.is_none(), "seed {seed}: {:?}", p.tried.first());
            let with: Vec<f64> = y
                .iter()
                .zip(&inp.w)
                .map(|(y, w)| y + 2e-4 * w * w)
                .collect();
            let p = propose(&inp, &diff(&with), &[], &diff);
            let got = p.proposed.expect("a term");
            assert_eq!(got.label, "rate squared", "seed {seed}: {:?}", p.tried);
        }
    }
}
