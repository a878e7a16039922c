//! The noise terms fitted to a whole Allan-variance curve (docs/noise.md):
//! the five power laws, a sinusoid and a first-order Markov term
//! (terms.rs), each reported only where the curve shows it.
//!
//! - For a given sinusoid frequency and Markov correlation time the model is
//!   linear in its coefficients: non-negative weighted least squares
//!   (nnls.rs), iteratively reweighted: the variance of an AVAR estimate is
//!   2 AVAR^2/edf, taken at the model, with each averaging time's degrees of
//!   freedom from the noise types the model holds there.
//! - The power laws are selected as before: a term must carry at least half
//!   of the model at some measured averaging time and its interval must
//!   exclude zero; otherwise it is absent and the rest is refitted.
//! - Three searched shapes are tried on top, one at a time, the best
//!   first (forward selection): the sinusoid (its frequency), the Markov
//!   term (its correlation time, from twice the shortest averaging time
//!   up) and the filter of the white noise (its time constant, below
//!   twice the shortest averaging time: white noise through a sensor's
//!   low-pass is Markov noise of that correlation time, which bends the
//!   -1/2 line down at the first few averaging times). Each is searched on
//!   a grid and refined by golden section in its logarithm, and kept only
//!   if it passes the same test and lowers the chi-square, scaled by the
//!   estimates' correlation (uncertainty.rs), by more than [`PENALTY`].
//! - Then the fit is checked against the measured intervals and the
//!   intervals are made honest (uncertainty.rs).

use super::edf::edf_oavar;
use super::model::{mixture_edf, Curve, Fitted, Shapes, TermFit};
use super::nnls::nnls;
use super::terms::{ALL, MARKOV, SIN};
use super::uncertainty::{self, Checked};
use crate::numerics::search::{golden, grid_then_golden};
use crate::numerics::stats::chi2_quantile;

/// Drop in the correlation-scaled chi-square a sinusoid or a Markov term
/// must buy to enter the model (two parameters each, the frequency or
/// correlation time searched over the whole curve).
pub const PENALTY: f64 = 25.0;
const LIKELIHOOD_KEEP: bool = true;

fn columns(c: &Curve, active: &[bool; ALL], sh: &Shapes) -> (Vec<usize>, Vec<Vec<f64>>) {
    let idx: Vec<usize> = (0..ALL).filter(|&j| active[j]).collect();
    let cols = idx
        .iter()
        .map(|&j| c.taus.iter().map(|&tau| sh.unit(j, tau)).collect())
        .collect();
    (idx, cols)
}

fn weights(model: &[f64], edf: &[f64]) -> Vec<f64> {
    model
        .iter()
        .zip(edf)
        .map(|(m, e)| e / (2.0 * m.max(f64::MIN_POSITIVE).powi(2)))
        .collect()
}

/// The weighted residual of the best non-negative model on the shapes
/// `active` at the searched parameters of `sh`, weights fixed.
fn cost(c: &Curve, active: &[bool; ALL], sh: &Shapes, w: &[f64]) -> f64 {
    let (_, cols) = columns(c, active, sh);
    nnls(&cols, c.avar, w).sse
}

/// Iteratively reweighted fit on the shapes `active` at the searched
/// parameters of `sh`, from the weights of `start`.
fn irls(c: &Curve, active: [bool; ALL], sh: &Shapes, start: &Fitted) -> Fitted {
    let n = c.n();
    let mut model = start.model.clone();
    let mut edf = start.edf.clone();
    let mut shapes = Shapes {
        c: [0.0; ALL],
        ..*sh
    };
    let (idx, cols) = columns(c, &active, sh);
    for it in 0..20 {
        let w = weights(&model, &edf);
        let sol = nnls(&cols, c.avar, &w);
        let mut nc = [0.0; ALL];
        for (k, &j) in idx.iter().enumerate() {
            nc[j] = sol.coef[k];
        }
        let change = (0..ALL)
            .map(|j| {
                (nc[j] - shapes.c[j]).abs()
                    / nc[j].abs().max(shapes.c[j].abs()).max(f64::MIN_POSITIVE)
            })
            .fold(0.0, f64::max);
        shapes.c = nc;
        for i in 0..n {
            model[i] = shapes.at(c.taus[i]).max(f64::MIN_POSITIVE);
            edf[i] = mixture_edf(&shapes, model[i], c.taus[i], c.ms[i], c.n_phase);
        }
        if it > 0 && change < 1e-9 {
            break;
        }
    }
    Fitted {
        shapes,
        active,
        model,
        edf,
    }
}

/// Fits at the searched parameters of `sh` and drops the shapes the curve
/// does not show, until every remaining one shows; with the check of the
/// last fit.
fn prune_fit(c: &Curve, mut active: [bool; ALL], sh: &Shapes, start: &Fitted) -> (Fitted, Checked) {
    let mut fit = irls(c, active, sh, start);
    for _round in 0..2 * ALL {
        let mut chk = uncertainty::check(c, &fit);
        if LIKELIHOOD_KEEP {
            keep_by_likelihood(c, &fit, &mut chk);
        }
        // Shapes the fit left at zero go at once; of the others that the
        // curve does not show, the least significant one (two rising
        // terms may be significant together and not alone).
        let mut next = active;
        for j in 0..ALL {
            if active[j] && fit.shapes.c[j] <= 0.0 {
                next[j] = false;
            }
        }
        if next == active {
            let weakest = (0..ALL)
                .filter(|&j| active[j] && !chk.present[j])
                .min_by(|&a, &b| chk.significance[a].total_cmp(&chk.significance[b]));
            if let Some(j) = weakest {
                next[j] = false;
            }
        }
        if next == active || !next.iter().any(|&a| a) {
            return (fit, chk);
        }
        active = next;
        fit = irls(c, active, sh, &fit);
    }
    let mut chk = uncertainty::check(c, &fit);
    keep_by_likelihood(c, &fit, &mut chk);
    (fit, chk)
}

/// A term whose interval reaches zero is still kept when the curve asks
/// for it: leaving it out raises the chi-square by more than the 99.9 %
/// point of one degree of freedom, scaled for the estimates' correlation
/// (the Wald interval of a term seen only at the few long averaging times
/// where its own scatter is large can reach zero when the likelihood
/// clearly wants it).
fn keep_by_likelihood(c: &Curve, fit: &Fitted, chk: &mut Checked) {
    let g = uncertainty::satterthwaite(c, fit).0;
    let limit = g * chi2_quantile(1.0 - 1e-5, 1.0);
    let base = uncertainty::chi2(c, fit);
    for j in 0..ALL {
        if chk.present[j] || !fit.has(j) || !chk.shows[j] {
            continue;
        }
        let mut without = fit.active;
        without[j] = false;
        let other = irls(c, without, &fit.shapes, fit);
        if uncertainty::chi2(c, &other) - base > limit {
            chk.present[j] = true;
            chk.by_likelihood[j] = true;
        }
    }
}

fn log_grid(a: f64, b: f64, per_decade: f64) -> Vec<f64> {
    if !(a > 0.0 && b > a) {
        return vec![];
    }
    let k = ((b / a).log10() * per_decade).ceil().max(1.0) as usize;
    (0..=k)
        .map(|i| a.ln() + (b.ln() - a.ln()) * i as f64 / k as f64)
        .collect()
}

/// A searched shape.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Searched {
    Sin,
    Markov,
    Filter,
}

impl Searched {
    /// The grid of the log of its parameter: the sinusoid's bumps from the
    /// shortest averaging time (up to the Nyquist frequency) to the
    /// longest; Markov correlation times from twice the shortest averaging
    /// time to three times the longest; filter time constants below.
    fn grid(self, c: &Curve) -> Vec<f64> {
        let (t0, t1) = (c.taus[0], c.taus[c.n() - 1]);
        match self {
            Searched::Sin => log_grid(0.3 / t1, (0.5 / c.tau0()).min(0.8 / t0), 20.0),
            Searched::Markov => log_grid(2.0 * t0, 3.0 * t1, 10.0),
            Searched::Filter => log_grid(t0 / 30.0, 2.0 * t0, 10.0),
        }
    }
    fn set(self, sh: &mut Shapes, v: f64) {
        match self {
            Searched::Sin => sh.f = v,
            Searched::Markov => sh.t = v,
            Searched::Filter => sh.tf = v,
        }
    }
    fn on(self, active: &mut [bool; ALL]) {
        match self {
            Searched::Sin => active[SIN] = true,
            Searched::Markov => active[MARKOV] = true,
            Searched::Filter => active[1] = true,
        }
    }
    fn in_fit(self, f: &Fitted) -> bool {
        match self {
            Searched::Sin => f.has(SIN),
            Searched::Markov => f.has(MARKOV),
            Searched::Filter => f.filtered(),
        }
    }
}

/// The best parameter of `what` for the shapes `active`, the other
/// searched parameters as in `sh`, weights fixed.
fn search(c: &Curve, what: Searched, active: &[bool; ALL], sh: &Shapes, w: &[f64]) -> Option<f64> {
    let grid = what.grid(c);
    if grid.is_empty() {
        return None;
    }
    let mut trial = *sh;
    let (lv, best) = grid_then_golden(
        |lv| {
            what.set(&mut trial, lv.exp());
            cost(c, active, &trial, w)
        },
        &grid,
        30,
    );
    if what == Searched::Sin {
        return Some(refine_frequency(c, active, sh, w, lv.exp(), best));
    }
    Some(lv.exp())
}

/// The sinusoid's frequency refined from the coarse search `f0` (cost
/// `cost0`). Its AVAR, A^2 sin^4(pi f tau) / (pi f tau)^2, has nulls at
/// tau = k/f: where the estimates are precise (white angle noise keeps
/// them so at every averaging time) the cost over f is a comb of minima
/// about 1/tau apart out to the longest tau, finer than any grid, and a
/// golden section between grid points stops in whichever tooth it meets
/// (a 0.1 Hz sinusoid on quantization noise was fitted at 0.104 Hz and
/// missed every point). So the frequency is pinned stage by stage: on the
/// points up to tau_L, which show no teeth finer than about 1/tau_L, a
/// scan of +-2/tau_L around the last stage's best at 1/(16 tau_L) and a
/// golden section about the best; then tau_L four times longer. Kept only
/// if it lowers the whole curve's cost.
fn refine_frequency(
    c: &Curve,
    active: &[bool; ALL],
    sh: &Shapes,
    w: &[f64],
    f0: f64,
    cost0: f64,
) -> f64 {
    let mut trial = *sh;
    let mut at = |sub: &Curve, wk: &[f64], f: f64| {
        trial.f = f;
        cost(sub, active, &trial, wk)
    };
    let mut f = f0;
    let mut tl = 16.0 / f0;
    loop {
        let k = c.taus.iter().take_while(|&&t| t <= tl).count().max(1);
        let sub = Curve {
            taus: &c.taus[..k],
            avar: &c.avar[..k],
            ms: &c.ms[..k],
            n_phase: c.n_phase,
        };
        let step = 1.0 / (16.0 * tl);
        let mut best = (f, at(&sub, &w[..k], f));
        for i in -32i32..=32 {
            let fi = f + i as f64 * step;
            if fi > 0.0 {
                let v = at(&sub, &w[..k], fi);
                if v < best.1 {
                    best = (fi, v);
                }
            }
        }
        let (a, b) = ((best.0 - step).max(best.0 / 2.0), best.0 + step);
        let (fg, vg) = golden(|x| at(&sub, &w[..k], x), a, b, 20);
        f = if vg < best.1 { fg } else { best.0 };
        if k >= c.n() {
            break;
        }
        tl *= 4.0;
    }
    if at(c, w, f) < cost0 {
        f
    } else {
        f0
    }
}

/// `from` with the searched shape `what` added: its parameter searched,
/// the model fitted (every power law offered again), the searched
/// parameters refined at that fit's weights and the model fitted again.
fn candidate(c: &Curve, from: &Fitted, what: Searched) -> Option<(Fitted, Checked)> {
    let mut active = [true; ALL];
    active[SIN] = from.has(SIN);
    active[MARKOV] = from.has(MARKOV);
    what.on(&mut active);
    let mut sh = from.shapes;
    if !from.filtered() {
        sh.tf = 0.0;
    }
    let mut fit = from.clone();
    let mut chk = None;
    for pass in 0..2 {
        let w = weights(&fit.model, &fit.edf);
        let order: Vec<Searched> = if pass == 0 {
            vec![what]
        } else {
            [Searched::Sin, Searched::Markov, Searched::Filter]
                .into_iter()
                .filter(|s| s.in_fit(&fit))
                .collect()
        };
        for s in order {
            let v = search(c, s, &active, &sh, &w)?;
            s.set(&mut sh, v);
        }
        let (f, k) = prune_fit(c, active, &sh, &fit);
        if !what.in_fit(&f) {
            return None;
        }
        active = f.active;
        for j in 0..crate::noise::terms::COUNT {
            active[j] = true;
        }
        fit = f;
        chk = Some(k);
    }
    chk.map(|k| (fit, k))
}

/// Fits the terms to `avar` (deg/s)^2 at `taus` (averaging factors `ms`,
/// `n_phase` angle points).
pub fn fit(taus: &[f64], avar: &[f64], ms: &[usize], n_phase: usize) -> TermFit {
    let c = Curve {
        taus,
        avar,
        ms,
        n_phase,
    };
    // Start: weights at the measured points, white-noise degrees of freedom.
    let start = Fitted {
        shapes: Shapes {
            f: 1.0,
            t: 1.0,
            ..Shapes::default()
        },
        active: [false; ALL],
        model: avar.iter().map(|v| v.max(f64::MIN_POSITIVE)).collect(),
        edf: ms.iter().map(|&m| edf_oavar(0, m, n_phase)).collect(),
    };
    let mut laws = [true; ALL];
    laws[SIN] = false;
    laws[MARKOV] = false;
    let (mut best, mut best_chk) = prune_fit(&c, laws, &start.shapes, &start);
    if taus.len() >= 8 {
        let scale = uncertainty::satterthwaite(&c, &best).0;
        let score = |f: &Fitted| uncertainty::chi2(&c, f) / scale + PENALTY * f.nonlinear() as f64;
        let mut best_score = score(&best);
        // Forward selection: the searched shape that lowers the score most,
        // while one does.
        loop {
            let mut round: Option<(Fitted, Checked, f64)> = None;
            for what in [Searched::Filter, Searched::Sin, Searched::Markov] {
                if what.in_fit(&best) {
                    continue;
                }
                if let Some((f, k)) = candidate(&c, &best, what) {
                    let s = score(&f);
                    if s < best_score && round.as_ref().is_none_or(|r| s < r.2) {
                        round = Some((f, k, s));
                    }
                }
            }
            match round {
                Some((f, k, s)) => {
                    best = f;
                    best_chk = k;
                    best_score = s;
                }
                None => break,
            }
        }
    }
    uncertainty::finish(&c, best, best_chk)
}
