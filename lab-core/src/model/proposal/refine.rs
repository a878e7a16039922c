//! A proposed candidate refined off its coarse grid: a searched parameter
//! between the grid's neighbours of its best (`on_grid`), two jointly
//! (coordinate sweeps, then Gauss-Newton on the whitened rows), with
//! their profile intervals.

use super::candidates::{Candidate, PULSE_WIDTH};
use super::orthogonal::{basis, dot, orthogonal};
use super::refit::{fit_term, ToRows};
use super::validation::{self, stats, BlockStats, FOLDS};
use crate::model::inputs::Inputs;
use crate::model::term::Term;
use std::collections::BTreeMap;

/// A candidate with its statistics at each point of its search kept, the
/// points, its held-out gain and its folds' gains.
pub(super) type Scored = (Candidate, Vec<BlockStats>, Vec<Vec<f64>>, f64, Vec<f64>);

/// A proposed term's parameters, their 95 % intervals and the reduction
/// of the sum of squares it makes.
pub(super) type Fitted = (Term, BTreeMap<String, (f64, f64)>, f64);

/// A candidate's whitened columns at one point of its search (a value
/// per searched parameter), made orthogonal to the fit's basis `q`; None
/// where the run cannot evaluate it.
fn columns(
    c: &Candidate,
    point: &[f64],
    inp: &Inputs,
    to_rows: ToRows,
    q: &[Vec<f64>],
) -> Option<Vec<Vec<f64>>> {
    let params = c.params_at(point);
    c.parts
        .iter()
        .map(|p| {
            let t = Term::new(&p.shape, params.clone()).ok()?;
            let x = orthogonal(to_rows(&t.evaluate(inp).ok()?), q);
            (dot(&x, &x) > 0.0).then_some(x)
        })
        .collect()
}

/// Values of a searched parameter tried between the coarse grid's
/// neighbours of its best.
const REFINE: usize = 40;

/// The best point of `grid`'s fits on the whole record: its index, its
/// coefficients and its reduction of the sum of squares.
fn best_fit(grid: &[BlockStats]) -> Option<(usize, Vec<f64>, f64)> {
    grid.iter()
        .enumerate()
        .filter_map(|(i, g)| g.fit(None).map(|(b, r)| (i, b, r)))
        .max_by(|a, b| a.2.total_cmp(&b.2))
}

/// Searched parameter `d` of candidate `c` tried at REFINE - 1 points
/// strictly between `lo` and `hi`, the others held at `at` (with
/// `hold_end`, parameter `d + 1`, a width, moves against it so their sum,
/// the end, holds): each point's
/// statistics added to `grid` and `kept`, and the best point's reduction
/// of the sum of squares and its parameters returned.
fn refine_along(
    c: &Candidate,
    at: &[f64],
    (d, hold_end): (usize, bool),
    (lo, hi): (f64, f64),
    (inp, y, to_rows, q): (&Inputs, &[f64], ToRows, &[Vec<f64>]),
    grid: &mut Vec<BlockStats>,
    kept: &mut Vec<Vec<f64>>,
) -> Option<(f64, Vec<f64>)> {
    let mut best: Option<(f64, Vec<f64>)> = None;
    for j in 1..REFINE {
        let mut p = at.to_vec();
        p[d] = lo + (hi - lo) * j as f64 / REFINE as f64;
        if hold_end {
            // An onset moved with the end held: the width takes the rest.
            p[d + 1] = at[d] + at[d + 1] - p[d];
        }
        let Some(cols) = columns(c, &p, inp, to_rows, q) else {
            continue;
        };
        let st = stats(&cols, y, FOLDS);
        if let Some((_, r)) = st.fit(None) {
            if best.as_ref().is_none_or(|b| r > b.0) {
                best = Some((r, p.clone()));
            }
        }
        grid.push(st);
        kept.push(p);
    }
    best
}

/// A candidate with at most one searched parameter, fitted on its grid:
/// the parameter refined between the coarse grid's neighbours of its best
/// value, so its value and profile interval are not the grid's; the
/// coefficients exact at it.
pub(super) fn on_grid(
    s: &Scored,
    inp: &Inputs,
    y: &[f64],
    to_rows: ToRows,
    q: &[Vec<f64>],
    var: f64,
) -> Option<Fitted> {
    let (c, grid, kept, _, _) = s;
    let mut grid = grid.clone();
    let mut kept = kept.clone();
    let coarse_best = best_fit(&grid).map(|b| b.0);
    if let (Some(b), false) = (coarse_best, c.searched.is_empty()) {
        let lo = kept[b.saturating_sub(1)][0];
        let hi = kept[(b + 1).min(kept.len() - 1)][0];
        let at = [kept[b][0]];
        refine_along(
            c,
            &at,
            (0, false),
            (lo, hi),
            (inp, y, to_rows, q),
            &mut grid,
            &mut kept,
        );
    }
    let fits: Vec<(usize, Vec<f64>, f64)> = grid
        .iter()
        .enumerate()
        .filter_map(|(i, g)| g.fit(None).map(|(b, r)| (i, b, r)))
        .collect();
    let (i, beta, red) = best_fit(&grid)?;
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
    for ((s, &v), iv) in c
        .searched
        .iter()
        .zip(&kept[i])
        .zip(profile(&kept, &fits, &kept[i], red, var))
    {
        params.insert(s.name.to_string(), v);
        intervals.insert(s.name.to_string(), iv);
    }
    Some((Term::new(&c.formula(), params).ok()?, intervals, red))
}

/// Profile intervals of the searched parameters on the values tried:
/// per parameter, the values of the points whose fit is within chi2(1,
/// 95 %) of `best` (the other parameters free on their grid, the
/// coefficients exact), and of the point `at`, widened by the spacing of
/// the values tried about them.
fn profile(
    kept: &[Vec<f64>],
    fits: &[(usize, Vec<f64>, f64)],
    at: &[f64],
    best: f64,
    var: f64,
) -> Vec<(f64, f64)> {
    at.iter()
        .enumerate()
        .map(|(d, &v)| {
            let ok: Vec<f64> = fits
                .iter()
                .filter(|f| best - f.2 <= 3.84 * var)
                .map(|f| kept[f.0][d])
                .collect();
            let mut all: Vec<f64> = kept.iter().map(|p| p[d]).collect();
            all.sort_by(f64::total_cmp);
            all.dedup();
            let step_at = |x: f64| -> f64 {
                let k = all.partition_point(|&a| a < x);
                let below = if k > 0 { x - all[k - 1] } else { 0.0 };
                let above = all.get(k + 1).map_or(0.0, |a| a - x);
                below.max(above)
            };
            let lo = ok.iter().copied().fold(v, f64::min);
            let hi = ok.iter().copied().fold(v, f64::max);
            (lo - step_at(lo), hi + step_at(hi))
        })
        .collect()
}

/// A candidate searched in two parameters (the settling from a time):
/// started from its best point on the grid, every parameter refined
/// jointly by Gauss-Newton on the whitened rows (refit.rs), with the
/// joint fit's intervals. The grid's point is kept where the refinement
/// fails or leaves a parameter without an interval.
pub(super) fn jointly(
    s: &Scored,
    inp: &Inputs,
    y: &[f64],
    fit: &[Vec<f64>],
    to_rows: ToRows,
    var: f64,
) -> Option<Fitted> {
    let (c, coarse_grid, coarse_kept, _, _) = s;
    let q = basis(fit);
    // Each searched parameter refined between its coarse grid's
    // neighbours of the best, the other held, twice round: Gauss-Newton
    // alone cannot move an onset (its derivative is a step's), and a jump
    // placed a grid spacing off loses to a plain step refined on_grid. A
    // pulse's onset moves with its end held: a pulse wider than the truth
    // fits as well anywhere it covers it, so with the width held the
    // onset has nowhere better to go, while onset and end are each the
    // truth's edge whatever the other is.
    let pulse = c.searched.get(1).is_some_and(|s| s.name == PULSE_WIDTH);
    let mut grid = coarse_grid.clone();
    let mut kept = coarse_kept.clone();
    if let Some((b, _, mut best)) = best_fit(&grid) {
        let mut at = kept[b].clone();
        for _ in 0..2 {
            for d in 0..at.len() {
                let mut values: Vec<f64> = coarse_kept.iter().map(|p| p[d]).collect();
                values.sort_by(f64::total_cmp);
                values.dedup();
                let k = values.partition_point(|&v| v < at[d]);
                let lo = values[k.saturating_sub(1)];
                let hi = values[(k + 1).min(values.len() - 1)];
                let span = (lo, hi);
                let hold_end = pulse && d == 0;
                if let Some((r, p)) = refine_along(
                    c,
                    &at,
                    (d, hold_end),
                    span,
                    (inp, y, to_rows, &q),
                    &mut grid,
                    &mut kept,
                ) {
                    if r > best {
                        best = r;
                        at = p;
                    }
                }
            }
        }
    }
    let (grid, kept) = (&grid, &kept);
    let fits: Vec<(usize, Vec<f64>, f64)> = grid
        .iter()
        .enumerate()
        .filter_map(|(i, g)| g.fit(None).map(|(b, r)| (i, b, r)))
        .collect();
    let (i, beta, red) = best_fit(grid)?;
    let mut params: BTreeMap<String, f64> = c
        .parts
        .iter()
        .zip(&beta)
        .map(|(p, &b)| (p.coef.to_string(), b))
        .collect();
    for (s, &v) in c.searched.iter().zip(&kept[i]) {
        params.insert(s.name.to_string(), v);
    }
    let start = Term::new(&c.formula(), params).ok()?;
    let free: Vec<String> = start.params.keys().cloned().collect();
    // The reduction of the sum of squares a term's values make.
    let yq = orthogonal(y.to_vec(), &q);
    let reduction = |t: &Term| -> Option<f64> {
        let g = orthogonal(to_rows(&t.evaluate(inp).ok()?), &q);
        Some(
            dot(&yq, &yq)
                - yq.iter()
                    .zip(&g)
                    .map(|(a, b)| (a - b) * (a - b))
                    .sum::<f64>(),
        )
    };
    let joint = fit_term(&start, &free, inp, y, fit, to_rows)
        .filter(|f| {
            f.intervals
                .values()
                .all(|(lo, hi)| lo.is_finite() && hi.is_finite())
        })
        .and_then(|f| Some((reduction(&f.term)?, f)))
        .filter(|(r, _)| *r >= red);
    let (term, mut intervals, best) = match joint {
        Some((r, f)) => (f.term, f.intervals, r),
        None => {
            // The grid's point, its coefficient's interval from X'X.
            let (a, _) = grid[i].sums(None);
            let mut iv = BTreeMap::new();
            for (j, p) in c.parts.iter().enumerate() {
                let mut e = vec![0.0; c.parts.len()];
                e[j] = 1.0;
                let se = (var * validation::solve(&a, &e)?[j]).sqrt();
                iv.insert(
                    p.coef.to_string(),
                    (beta[j] - 1.96 * se, beta[j] + 1.96 * se),
                );
            }
            (start, iv, red)
        }
    };
    // The searched parameters' intervals hold both the joint fit's and
    // the profile on the grid (the sum of squares of a settling is not
    // quadratic in its onset and time constant far from the optimum).
    for (s, (lo, hi)) in c
        .searched
        .iter()
        .zip(profile(kept, &fits, &kept[i], best, var))
    {
        let e = intervals.entry(s.name.to_string()).or_insert((lo, hi));
        *e = (e.0.min(lo), e.1.max(hi));
    }
    Some((term, intervals, best))
}
