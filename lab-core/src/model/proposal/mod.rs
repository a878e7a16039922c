//! Proposal of a term outside the physics library (issue 32): where the
//! residual holds structure no library effect explains, the simplest term
//! built from the run's own inputs that predicts data it was not fitted on.
//!
//! - candidates.rs: the candidate space, each a formula of the model
//!   file's term language (model/term/), so what is validated is what is
//!   written;
//! - validation.rs: blocked cross-validation on the whitened rows, and the
//!   threshold that pays for the whole space;
//! - refit.rs: a term's parameters fitted jointly (Gauss-Newton), for a
//!   user's term and for a candidate searched in two parameters;
//! - orthogonal.rs: columns made orthogonal to what the fit carries.
//!
//! The caller (discovery) gives the whitened residual of its fit, the
//! whitened columns the fit carries, and the map from a per-row column
//! (deg/h) to whitened rows; the noise model is its, so coloured noise is
//! judged as the noise model says and a candidate gains only what the
//! noise cannot already predict.

pub mod candidates;
pub mod orthogonal;
mod refine;
pub mod refit;
pub mod screen;
pub mod validation;

use crate::model::inputs::Inputs;
use crate::model::term::Term;
use candidates::{candidates, space_size, Candidate, Second};
use orthogonal::{basis, dot, orthogonal};
use refine::{jointly, on_grid, Scored};
use refit::ToRows;
use screen::Screen;
use std::collections::BTreeMap;
pub use validation::Validation;
use validation::{cross_validate, stats, threshold, BlockStats, FOLDS};

/// A term proposed, its coefficients fitted on the whole record.
#[derive(Clone, Debug, PartialEq)]
pub struct Proposed {
    pub label: String,
    /// The term as the model file writes it (coefficients and the
    /// searched parameter among its parameters).
    pub term: Term,
    /// 95 % intervals of the parameters (one searched parameter's from
    /// the profile of the sum of squares over its grid; the settling's
    /// two, and its coefficient, from their joint fit).
    pub intervals: BTreeMap<String, (f64, f64)>,
    pub validation: Validation,
    /// Where the term is a shape of time alone: the best candidate built
    /// from the run's inputs that the data could not tell from it by
    /// held-out gain. A shape of time carries to no other run; a second
    /// run tells the two apart.
    pub rival: Option<Tried>,
    /// The same term with a second part beside it (candidates.rs's
    /// `paired`: its lead, its square, or the lagged input direct), its label and the
    /// term at the proposed values with the second coefficient at zero.
    /// Where a library name stands in for that part (a scale factor over
    /// temperature beside a lagged one), the name's pruning tries them
    /// (discovery/outside.rs): the part already in the fit gained nothing
    /// in the search.
    pub variants: Vec<Variant>,
}

/// A proposed term with a second part: its label, the term, and what the
/// part is (whose coefficients must stay plausible).
pub type Variant = (String, Term, Second);

/// The `paired` candidates that extend `c` (the same first part, one part
/// more), as terms at `term`'s values with the new coefficient at zero.
fn variants(c: &Candidate, term: &Term, paired: &[Candidate]) -> Vec<Variant> {
    paired
        .iter()
        .filter(|p| p.recipe == c.recipe && c.also.is_empty() && c.parts.len() == 1)
        .filter_map(|p| {
            let mut params = term.params.clone();
            for part in &p.parts[1..] {
                params.insert(part.coef.to_string(), 0.0);
            }
            Some((
                p.label.clone(),
                Term::new(&p.formula(), params).ok()?,
                p.second?,
            ))
        })
        .collect()
}

/// A candidate's score.
#[derive(Clone, Debug, PartialEq)]
pub struct Tried {
    pub label: String,
    pub formula: String,
    pub held_out_gain: f64,
}

/// How far below a held-out gain `g` (a sum of squares; `var`, the noise
/// variance) another is not told from it: a gain G in noise variances
/// scatters by about 2 sqrt(G) from one record of the gyro to the next,
/// and by at least 3 % of itself.
fn scatter(g: f64, var: f64) -> f64 {
    (0.03 * g).max(2.0 * (g / var).max(0.0).sqrt() * var)
}

/// The outcome: the term proposed (none when no candidate predicts beyond
/// the threshold), and every candidate's score, best first.
#[derive(Clone, Debug, PartialEq)]
pub struct Proposal {
    pub proposed: Option<Proposed>,
    pub tried: Vec<Tried>,
    /// The candidate columns searched (every point of every grid) and the
    /// held-out gain they had to pass (validation.rs's `threshold`).
    pub space: usize,
    pub threshold: f64,
}

/// Whitens window means (deg/h per unit of a coefficient, one value per
/// window of the fit) into the rows of `y`, many at a time.
pub type WhitenWindows<'a> = &'a dyn Fn(&[&[f64]]) -> Vec<Vec<f64>>;

/// Finalists refined and compared by the criterion.
const FINALISTS: usize = 6;

/// Points of a candidate's grid screened at once.
const SCREEN_BATCH: usize = 8;

/// A candidate's cross-validation statistics at every point of its grid,
/// screened on window means (screen.rs): its columns made, whitened in
/// batches, made orthogonal to `q`, reduced to their statistics and
/// dropped. The points kept are those the run can evaluate.
fn screened(
    c: &Candidate,
    prims: &[candidates::Prim],
    screen: &Screen,
    whiten: WhitenWindows,
    q: &[Vec<f64>],
    y: &[f64],
) -> (Vec<BlockStats>, Vec<Vec<f64>>) {
    let mut grid = vec![];
    let mut kept = vec![];
    for chunk in c.points().chunks(SCREEN_BATCH) {
        let raw: Vec<(Vec<f64>, Vec<Vec<f64>>)> = chunk
            .iter()
            .filter_map(|v| Some((v.clone(), screen.columns(prims, c, v)?)))
            .collect();
        let all: Vec<&[f64]> = raw
            .iter()
            .flat_map(|(_, cols)| cols.iter().map(Vec::as_slice))
            .collect();
        let mut w = whiten(&all).into_iter();
        for (v, cols) in &raw {
            let x: Vec<Vec<f64>> = w
                .by_ref()
                .take(cols.len())
                .map(|col| orthogonal(col, q))
                .collect();
            if x.iter().all(|col| dot(col, col) > 0.0) {
                grid.push(stats(&x, y, FOLDS));
                kept.push(v.clone());
            }
        }
    }
    (grid, kept)
}

/// Proposes a term for the whitened residual `y` of a fit whose whitened
/// columns are `fit` (the constant among them). `inp` are the inputs the
/// candidates are built from and `to_rows` maps a value per input row
/// (deg/h) to the whitened rows of `y`.
pub fn propose(
    inp: &Inputs,
    y: &[f64],
    fit: &[Vec<f64>],
    to_rows: ToRows,
    win: &crate::model::discovery::windows::Windows,
    whiten: WhitenWindows,
) -> Proposal {
    let q = basis(fit);
    let n = y.len();
    let (prims, cands) = candidates(inp);
    let space = space_size(&cands);
    let thr = threshold(space);
    let screen = Screen::new(inp, win, &prims);
    let paired: Vec<Candidate> = cands
        .iter()
        .filter(|c| !c.also.is_empty())
        .cloned()
        .collect();
    let mut scored: Vec<Scored> = vec![];
    for c in cands {
        if n < 4 * FOLDS {
            break;
        }
        let (grid, kept) = screened(&c, &prims, &screen, whiten, &q, y);
        if grid.is_empty() {
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
            label: s.0.label.clone(),
            formula: s.0.formula(),
            held_out_gain: s.3 / var,
        })
        .collect();
    // Finalists: those the data cannot tell from the best by their
    // held-out gains (a gain G, in noise variances, scatters by about
    // 2 sqrt(G) from one record of the gyro to the next) that pass the
    // threshold. Among them the criterion chooses: each refined to its
    // best (on_grid, jointly), its reduction of the sum of squares less
    // ln n noise variances for each freedom it has (BIC). A composition a
    // little ahead of the plain truth by chance loses to it, and an event
    // searched in two parameters wins only where it explains clearly more
    // than a simpler shape (a step whose onset falls between two of the
    // coarse grid's is refined before it is compared).
    let pen = (n as f64).ln();
    let grid_red = |s: &Scored| {
        s.1.iter()
            .filter_map(|g| g.fit(None))
            .map(|f| f.1)
            .fold(f64::NEG_INFINITY, f64::max)
    };
    // A composition is a choice among many: each order beyond a
    // primitive costs as a freedom does.
    let cost = |c: &Candidate| (c.freedom() as i32 + c.order() - 1) as f64;
    let coarse = |s: &Scored| grid_red(s) / var - pen * cost(&s.0);
    let fitted = |s: &Scored| {
        if s.0.searched.len() > 1 {
            jointly(s, inp, y, fit, to_rows, var)
        } else {
            on_grid(s, inp, y, to_rows, &q, var)
        }
    };
    // The choice among the candidates `pool` lets in.
    let choose = |pool: &dyn Fn(&Scored) -> bool| {
        let top = scored
            .iter()
            .filter(|s| pool(s))
            .map(|s| s.3)
            .fold(f64::NEG_INFINITY, f64::max);
        let margin = scatter(top, var);
        let mut finalists: Vec<&Scored> = scored
            .iter()
            .filter(|s| pool(s) && s.3 >= top - margin && s.3 / var >= thr)
            .collect();
        finalists.sort_by(|a, b| coarse(b).total_cmp(&coarse(a)));
        finalists.truncate(FINALISTS);
        // The events searched in two parameters that pass the threshold
        // join them, the best two by gain, however far behind: on the
        // coarse grid an onset a grid spacing off the event's costs it
        // most of its gain where the noise model whitens by differences
        // (a random walk), while a smooth shape that misses the jump
        // itself does not pay that, and only the refinement (jointly)
        // puts the onset where it belongs.
        let mut events: Vec<&Scored> = scored
            .iter()
            .filter(|s| pool(s) && s.0.searched.len() == 2 && s.3 / var >= thr)
            .filter(|s| !finalists.iter().any(|f| std::ptr::eq(*f, *s)))
            .collect();
        events.truncate(2);
        finalists.extend(events);
        finalists
            .into_iter()
            .filter_map(|s| Some((s, fitted(s)?)))
            .filter(|(s, f)| s.0.second.is_none_or(|k| k.plausible(&f.0.params)))
            .max_by(|(a, fa), (b, fb)| {
                let sa = fa.2 / var - pen * cost(&a.0);
                let sb = fb.2 / var - pen * cost(&b.0);
                sa.total_cmp(&sb).then(b.0.order().cmp(&a.0.order()))
            })
    };
    // Where every finalist was a pair that did not stay what it stands
    // for, and it had set the margin, the choice again without the pairs.
    let chosen = choose(&|_| true).or_else(|| choose(&|s| s.0.second.is_none()));
    // A shape of time alone (an event, a sinusoid, a ramp: no input in its
    // recipe) and the best input-built candidate within its gain's scatter.
    let of_time = |c: &Candidate| c.recipe.iter().all(|f| !prims[f.prim].is_input());
    let rival = |s: &Scored| -> Option<Tried> {
        if !of_time(&s.0) {
            return None;
        }
        let margin = scatter(s.3, var);
        scored
            .iter()
            .filter(|r| !of_time(&r.0) && r.3 >= s.3 - margin && r.3 / var >= thr)
            .max_by(|a, b| a.3.total_cmp(&b.3))
            .map(|r| Tried {
                label: r.0.label.clone(),
                formula: r.0.formula(),
                held_out_gain: r.3 / var,
            })
    };
    let proposed = chosen.map(|(s, (term, intervals, _))| {
        let (gain, folds) = (s.3, &s.4);
        Proposed {
            rival: rival(s),
            label: s.0.label.clone(),
            variants: variants(&s.0, &term, &paired),
            term,
            intervals,
            validation: Validation {
                folds: FOLDS,
                held_out_gain: gain / var,
                fold_gains: folds.iter().map(|g| g / var).collect(),
                threshold: thr,
                held_out_share: gain / ss.max(1e-300),
            },
        }
    });
    Proposal {
        proposed,
        tried,
        space,
        threshold: thr,
    }
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

    /// [`propose`] on a run of one row a window, the windows whitened as
    /// the rows are.
    fn prop(inp: &Inputs, y: &[f64], fit: &[Vec<f64>], to_rows: ToRows) -> Proposal {
        let win = crate::model::discovery::windows::Windows::new(&inp.t, 1.0);
        propose(inp, y, fit, to_rows, &win, &|xs| {
            xs.iter().map(|x| to_rows(x)).collect()
        })
    }

    fn constant(n: usize) -> Vec<Vec<f64>> {
        vec![vec![1.0; n]]
    }

    /// `x` (one row a second) through a first-order lag of `tau` s,
    /// starting settled.
    fn lagged(x: &[f64], tau: f64) -> Vec<f64> {
        let a = 1.0 - (-1.0 / tau).exp();
        let mut out = vec![x[0]; x.len()];
        for k in 1..x.len() {
            out[k] = out[k - 1] + a * (x[k] - out[k - 1]);
        }
        out
    }

    /// The term proposed on white noise of one per row, which must be the
    /// candidate `label`.
    fn proposed_as(inp: &Inputs, y: &[f64], label: &str) -> Proposed {
        let p = prop(inp, y, &constant(y.len()), &|x| x.to_vec());
        let got = p.proposed.expect("a term");
        assert_eq!(got.label, label, "{:?}", &p.tried[..3]);
        got
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
        let p = prop(&inp, &y, &constant(n), &|x| x.to_vec());
        let got = p.proposed.expect("a term");
        assert_eq!(got.label, "rate squared", "{:?}", p.tried);
        let (lo, hi) = got.intervals["k_dph"];
        assert!(lo < k && k < hi, "{lo} {hi}");
        assert!((got.term.params["k_dph"] - k).abs() < 0.02 * k);
        assert!(
            got.validation.held_out_gain > 100.0 * validation::THRESHOLD,
            "{:?}",
            got.validation
        );
    }

    /// A scale factor following the coil's temperature, read by a sensor
    /// that lags it by a minute (a chamber swinging +-15 degC every 20
    /// min): the term proposed is the sensor's temperature with a lead,
    /// and the lead k2 / k is the sensor's lag.
    #[test]
    fn a_sensor_behind_the_physics_is_proposed_as_a_lead() {
        let n = 7200;
        let t: Vec<f64> = (0..n).map(|k| k as f64 + 1.0).collect();
        let w: Vec<f64> = (0..n)
            .map(|k| [50.0, -50.0, 200.0, -200.0, 100.0, -100.0][(k / 300) % 6])
            .collect();
        let coil: Vec<f64> = t
            .iter()
            .map(|t| 25.0 + 15.0 * (2.0 * std::f64::consts::PI * t / 1200.0).sin())
            .collect();
        let lag_s = 60.0;
        let inp = Inputs::new(t, w.clone(), Some(lagged(&coil, lag_s)), None, None, None);
        let k = 1e-3;
        let e = noise(n, 11);
        let y: Vec<f64> = (0..n).map(|i| k * w[i] * (coil[i] - 20.0) + e[i]).collect();
        let got = proposed_as(&inp, &y, "rate times temperature less 20 degC, with a lead");
        let lead = got.term.params["k2_dph"] / got.term.params["k_dph"];
        assert!((lead - lag_s).abs() < 0.1 * lag_s, "lead {lead} s");
        assert!((got.term.params["k_dph"] - k).abs() < 0.01 * k);
    }

    /// A bias quadratic in a temperature that reaches the gyro through a
    /// 15 min lag (a chamber cycling +-15 degC every 50 min, the gyro at
    /// rest): the lag and its square, each with its coefficient, the time
    /// constant and the square's coefficient inside their intervals.
    #[test]
    fn a_bias_quadratic_in_a_lagged_temperature_is_one_candidate() {
        let n = 7200;
        let t: Vec<f64> = (0..n).map(|k| k as f64 + 1.0).collect();
        let temp: Vec<f64> = t
            .iter()
            .map(|t| 25.0 + 15.0 * (2.0 * std::f64::consts::PI * t / 3000.0).sin())
            .collect();
        let inp = Inputs::new(t, vec![0.0; n], Some(temp.clone()), None, None, None);
        let tau = 900.0;
        let x: Vec<f64> = lagged(&temp, tau).iter().map(|v| v - 20.0).collect();
        let e = noise(n, 12);
        let y: Vec<f64> = (0..n)
            .map(|i| 0.2 * x[i] - 0.05 * x[i].powi(2) + e[i])
            .collect();
        let got = proposed_as(&inp, &y, "temperature through a lag, and its square");
        let (lo, hi) = got.intervals["tau_s"];
        assert!(lo < tau && tau < hi, "tau {lo} .. {hi}");
        let (lo, hi) = got.intervals["k2_dph"];
        assert!(lo < -0.05 && -0.05 < hi, "k2 {lo} .. {hi}");
    }

    /// What a pair stands for: a sensor behind the physics by minutes, a
    /// share direct whose sensor lag is as short; not two shapes fitted
    /// against each other.
    #[test]
    fn a_pair_is_plausible_only_as_what_it_stands_for() {
        let at = |k: f64, k2: f64, tau: f64| {
            BTreeMap::from([
                ("k_dph".to_string(), k),
                ("k2_dph".to_string(), k2),
                ("tau_s".to_string(), tau),
            ])
        };
        assert!(Second::Lead.plausible(&at(2.0, 120.0, 0.0)));
        assert!(!Second::Lead.plausible(&at(2.0, -120.0, 0.0)));
        assert!(!Second::Lead.plausible(&at(2.0, 2.0 * 1000.0, 0.0)));
        // 4 % direct of a 10 min lag: a sensor 24 s behind.
        assert!(Second::Direct.plausible(&at(-0.96, -0.04, 600.0)));
        // The RLG's one monoblock less the case: 69 % direct of a 45 min
        // lag, a sensor 31 min behind.
        assert!(!Second::Direct.plausible(&at(0.123, 0.280, 2681.0)));
        assert!(!Second::Direct.plausible(&at(-0.085, 0.298, 952.0)));
        assert!(Second::Square.plausible(&at(1.0, -5.0, 0.0)));
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
        let p = prop(&inp, &y, &constant(n), &|x| x.to_vec());
        let got = p.proposed.expect("a term");
        assert_eq!(got.label, "step", "{:?}", p.tried);
        let (lo, hi) = got.intervals["t0_s"];
        assert!(lo <= 4000.0 + 70.0 && hi >= 4000.0 - 70.0, "{lo} {hi}");
    }

    #[test]
    fn white_noise_gets_no_term() {
        // The whole grammar on a table run with a drifting temperature:
        // the nulls' largest held-out gain stays under half the threshold
        // the space's size sets (noise buys no term).
        let n = 7200;
        let inp = run(n);
        let mut worst = f64::NEG_INFINITY;
        for seed in 0..10 {
            let y = noise(n, 100 + seed);
            let p = prop(&inp, &y, &constant(n), &|x| x.to_vec());
            assert!(p.proposed.is_none(), "seed {seed}: {:?}", p.tried.first());
            assert!(p.space > 2000, "the space holds {} columns", p.space);
            worst = worst.max(
                p.tried
                    .first()
                    .map_or(f64::NEG_INFINITY, |t| t.held_out_gain),
            );
            assert!(
                worst < p.threshold / 2.0,
                "seed {seed}: a null gained {worst} against a threshold of {} ({} columns)",
                p.threshold,
                p.space
            );
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
            let p = prop(&inp, &diff(&y), &[], &diff);
            assert!(p.proposed.is_none(), "seed {seed}: {:?}", p.tried.first());
            let with: Vec<f64> = y
                .iter()
                .zip(&inp.w)
                .map(|(y, w)| y + 2e-4 * w * w)
                .collect();
            let p = prop(&inp, &diff(&with), &[], &diff);
            let got = p.proposed.expect("a term");
            assert_eq!(got.label, "rate squared", "seed {seed}: {:?}", p.tried);
        }
    }

    /// A first-order settling from a time under white noise, 20 draws: the
    /// settling (not a step, a ramp or an exponential from power-on) is
    /// proposed, and its size, onset and time constant lie inside their
    /// 95 % intervals about as often as 95 % intervals should (16 or fewer
    /// of 20 has a chance of 1.6 % at 95 % coverage).
    #[test]
    fn a_settling_from_a_time_is_proposed_with_its_onset_and_time_constant() {
        let n = 7200;
        let inp = run(n);
        let (k, t1, tau) = (1.0, 2500.0, 900.0);
        let draws = 20;
        let mut named = 0;
        let mut covered = [0; 3];
        for seed in 0..draws {
            let e = noise(n, 300 + seed);
            let y: Vec<f64> = inp
                .t
                .iter()
                .zip(&e)
                .map(|(t, e)| {
                    let s = if *t >= t1 {
                        k * (1.0 - (-(t - t1) / tau).exp())
                    } else {
                        0.0
                    };
                    s + e
                })
                .collect();
            let p = prop(&inp, &y, &constant(n), &|x| x.to_vec());
            let got = p.proposed.expect("a term");
            if got.label != "settling from a time" {
                continue;
            }
            named += 1;
            for (c, (name, truth)) in
                covered
                    .iter_mut()
                    .zip([("k_dph", k), ("t1_s", t1), ("tau_s", tau)])
            {
                let (lo, hi) = got.intervals[name];
                *c += usize::from(lo < truth && truth < hi);
            }
            // Informative, not merely wide: t1 to a few minutes.
            let (lo, hi) = got.intervals["t1_s"];
            assert!(hi - lo < 900.0, "seed {seed}: t1 {lo} .. {hi}");
        }
        assert!(named >= 18, "the settling named on {named} of {draws}");
        for c in covered {
            assert!(c + 3 >= named, "covered {covered:?} of {named}");
        }
    }

    /// White noise and flicker (as a sum of first-order processes, the
    /// noise model's own representation), whitened by that noise model as
    /// discovery whitens a residual: no term, and the settling, the most
    /// flexible candidate, far from the threshold.
    #[test]
    fn a_flicker_null_gets_no_term_and_no_settling() {
        use crate::model::discovery::noise_model::{NoiseModel, Whitener};
        use crate::model::discovery::windows::Windows;
        let n = 7200;
        let inp = run(n);
        let win = Windows::new(&inp.t, 1.0);
        let nm = NoiseModel {
            white: 1.0,
            flicker: 0.25,
            random_walk: 0.0,
            markov: 0.0,
            markov_s: 1.0,
        };
        let keep = vec![true; win.len()];
        let wh = Whitener::new(&nm, &win, &keep);
        let to_rows = |x: &[f64]| wh.whiten(&win.mean(x));
        for seed in 0..4 {
            let mut y = noise(n, 400 + seed);
            for (j, (tc, var)) in nm.processes(inp.t[n - 1] - inp.t[0]).iter().enumerate() {
                let phi = (-1.0 / tc).exp();
                let e = noise(n, 1000 * (seed + 1) + j as u64);
                let mut x = var.sqrt() * e[0];
                for (yi, ei) in y.iter_mut().zip(&e) {
                    x = phi * x + (var * (1.0 - phi * phi)).sqrt() * ei;
                    *yi += x;
                }
            }
            let yw = to_rows(&y);
            let p = prop(&inp, &yw, &[to_rows(&vec![1.0; n])], &to_rows);
            assert!(p.proposed.is_none(), "seed {seed}: {:?}", p.tried.first());
            let settling = p
                .tried
                .iter()
                .find(|t| t.label == "settling from a time")
                .expect("the settling tried");
            assert!(
                settling.held_out_gain < validation::THRESHOLD / 2.0,
                "seed {seed}: {settling:?}"
            );
        }
    }
}
