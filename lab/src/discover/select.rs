//! Forward selection of named effects (docs/discovery.md).
//!
//! The residual (measured minus model) and every effect's regressors are
//! averaged over the same windows (1 s: the gap's averaging), so the fit is
//! of what the gap measures and the noise of a window mean is close to
//! white. At each step every candidate effect is fitted jointly with those
//! already chosen (its non-linear parameter by search); the one that lowers
//! BIC most is added if it lowers it by more than [`BIC_THRESHOLD`], then
//! the non-linear parameters of all chosen effects are re-fitted. A lag-1
//! correlation of the residual inflates the noise variance (and divides the
//! likelihood gain) by (1 + rho)/(1 - rho).
//!
//! Collinearity: when another candidate explains nearly the same (its BIC
//! gain within [`AMBIGUITY_MARGIN`] of the best's, and what it explains
//! correlated with what the best explains at |r| >= [`AMBIGUITY_CORR`]) the
//! run cannot tell them apart: both are reported as ambiguous, neither is
//! named; the best stands in the fit as an unnamed nuisance so that other
//! effects are judged on the rest.

use crate::effects::{Effect, Inputs};
use crate::numerics::lsq::{wls, LsFit};
use crate::numerics::search::{golden, grid_then_golden, profile_interval, CHI2_1_95};

/// BIC decrease an effect must bring to be named ("very strong" evidence).
pub const BIC_THRESHOLD: f64 = 10.0;
/// Ambiguity: BIC gains within this much of the best (the data prefers
/// neither strongly) ...
pub const AMBIGUITY_MARGIN: f64 = 10.0;
/// ... and explained parts correlated this much.
pub const AMBIGUITY_CORR: f64 = 0.9;

/// Windows of the run: row -> window, rows per window, window mid time.
pub struct Windows {
    pub idx: Vec<usize>,
    pub count: Vec<f64>,
    pub t: Vec<f64>,
}

impl Windows {
    /// Windows of `len_s` seconds from the first row (a row every `len_s`
    /// or slower is a window of its own).
    pub fn new(t: &[f64], len_s: f64) -> Self {
        let mut idx = Vec::with_capacity(t.len());
        let (mut count, mut tsum): (Vec<f64>, Vec<f64>) = (vec![], vec![]);
        let t0 = t.first().copied().unwrap_or(0.0);
        let mut last: Option<i64> = None;
        for &tk in t {
            let w = ((tk - t0) / len_s).floor() as i64;
            if last != Some(w) {
                count.push(0.0);
                tsum.push(0.0);
                last = Some(w);
            }
            let i = count.len() - 1;
            count[i] += 1.0;
            tsum[i] += tk;
            idx.push(i);
        }
        let t = tsum.iter().zip(&count).map(|(s, c)| s / c).collect();
        Self { idx, count, t }
    }

    pub fn len(&self) -> usize {
        self.count.len()
    }

    pub fn is_empty(&self) -> bool {
        self.count.is_empty()
    }

    pub fn mean(&self, x: &[f64]) -> Vec<f64> {
        let mut s = vec![0.0; self.len()];
        for (k, &v) in x.iter().enumerate() {
            s[self.idx[k]] += v;
        }
        s.iter().zip(&self.count).map(|(a, c)| a / c).collect()
    }
}

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
    fn refine(&self, terms: &mut [Term], j: usize) {
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

/// A step of the selection.
#[derive(Clone, Debug)]
pub struct Step {
    pub term: Term,
    pub delta_bic: f64,
}

/// Effects a run cannot tell apart.
#[derive(Clone, Debug, serde::Serialize)]
pub struct Ambiguous {
    pub effects: Vec<&'static str>,
    /// Correlation of what each explains with what the first explains.
    pub correlation: Vec<f64>,
    pub delta_bic: Vec<f64>,
    pub suggestion: String,
}

pub struct Selection {
    pub chosen: Vec<Step>,
    pub nuisance: Vec<Term>,
    pub ambiguous: Vec<Ambiguous>,
    pub inflation: f64,
}

/// Weighted cosine of two explained parts: uncentred, because the fits
/// have no intercept of their own (a bias is an effect like the others),
/// so two effects that both explain a constant are the same to this run.
fn corr(a: &[f64], b: &[f64], w: &[f64]) -> f64 {
    let (mut sab, mut saa, mut sbb) = (0.0, 0.0, 0.0);
    for i in 0..a.len() {
        sab += w[i] * a[i] * b[i];
        saa += w[i] * a[i] * a[i];
        sbb += w[i] * b[i] * b[i];
    }
    if saa > 0.0 && sbb > 0.0 {
        sab / (saa * sbb).sqrt()
    } else {
        0.0
    }
}

/// What test profile would separate two effects.
pub fn separation(a: Effect, b: Effect) -> String {
    use Effect::*;
    let pair = |x: Effect, y: Effect| (a == x && b == y) || (a == y && b == x);
    let s = if pair(Bias, ScaleFactorError) || pair(ScaleFactorError, ScaleFactorAsymmetry) {
        "turn the table at several rates in both directions (and rest): a constant rate cannot tell a scale-factor error from a bias"
    } else if pair(Bias, ScaleFactorAsymmetry) {
        "turn the table at several rate magnitudes: at one magnitude the asymmetry is a constant"
    } else if pair(ThermalDifference, ThermalGradient)
        || pair(ThermalGradient, ThermalDifferenceSquared)
    {
        "hold the chamber at plateaus long enough for the monoblock difference to settle (steps with soaks): on a ramp or a single exponential the difference and its rate move together"
    } else if pair(ThermalDifference, ThermalDifferenceSquared) {
        "sweep the monoblock difference through zero (cool and heat): over one sign dT and dT^2 are nearly proportional"
    } else if pair(CaseTemperature, ThermalDifference)
        || pair(CaseTemperature, ThermalDifferenceSquared)
    {
        "a profile where the case temperature and the monoblock difference change apart: chamber steps with soaks (the monoblocks lag differently)"
    } else if pair(WarmUp, Bias) || pair(WarmUp, CaseTemperature) || pair(WarmUp, ThermalDifference)
    {
        "start cold and record several warm-up time constants, or restart at a constant chamber temperature"
    } else if pair(ScaleFactorTemperature, ScaleFactorKnee) {
        "sweep the temperature well beyond the knee on both sides"
    } else if pair(VibrationRectification, Bias) {
        "vary the vibration level (off, then several amplitudes): at one level it is a constant bias"
    } else if pair(ScaleFactorTemperature, CaseTemperature) || pair(ScaleFactorTemperature, Bias) {
        "reverse the table or rest during the temperature sweep: at one rate a scale factor over temperature is a bias over temperature"
    } else if pair(LockIn, ScaleFactorError) {
        "add rates close to the lock-in rate (a few times it) and far above it"
    } else {
        "a profile in which the two regressors vary independently"
    };
    s.to_owned()
}

/// Forward selection over `candidates` with variance inflation `phi`.
pub fn select(d: &Design, candidates: &[Effect], phi: f64) -> Selection {
    let n = d.n();
    let mut chosen: Vec<Step> = vec![];
    let mut nuisance: Vec<Term> = vec![];
    let mut ambiguous = vec![];
    let mut excluded: Vec<Effect> = vec![];
    let current = |chosen: &[Step], nuisance: &[Term]| -> Vec<Term> {
        chosen
            .iter()
            .map(|s| s.term)
            .chain(nuisance.iter().copied())
            .collect()
    };
    loop {
        let base = current(&chosen, &nuisance);
        let Some((_, r_cur)) = d.fit(&base) else {
            break;
        };
        let sse_cur: f64 = r_cur.iter().zip(&d.win.count).map(|(v, c)| c * v * v).sum();
        if sse_cur <= 0.0 {
            break;
        }
        // Every candidate's best fit with the current set.
        let mut evals: Vec<(Term, f64, Vec<f64>)> = vec![];
        for &e in candidates {
            if excluded.contains(&e) || chosen.iter().any(|s| s.term.effect == e) {
                continue;
            }
            let mut terms = base.clone();
            terms.push(Term { effect: e, x: 0.0 });
            let j = terms.len() - 1;
            d.optimize(&mut terms, j);
            let Some((_, r)) = d.fit(&terms) else {
                continue;
            };
            let sse: f64 = r.iter().zip(&d.win.count).map(|(v, c)| c * v * v).sum();
            let k = (e.linear_params().len() + usize::from(e.nonlinear_param().is_some())) as f64;
            let dbic = n * (sse / sse_cur).ln() / phi + k * n.ln();
            // What it explains beyond the current set.
            let explained: Vec<f64> = r_cur.iter().zip(&r).map(|(a, b)| a - b).collect();
            evals.push((terms[j], dbic, explained));
        }
        let Some(best) = evals
            .iter()
            .enumerate()
            .min_by(|a, b| a.1 .1.total_cmp(&b.1 .1))
            .map(|(i, _)| i)
        else {
            break;
        };
        let (bt, bdbic, bexp) = evals[best].clone();
        if bdbic > -BIC_THRESHOLD {
            break;
        }
        let margin = AMBIGUITY_MARGIN;
        let mut group = vec![(bt.effect, 1.0, bdbic)];
        for (i, (t, dbic, exp)) in evals.iter().enumerate() {
            if i == best || *dbic > bdbic + margin {
                continue;
            }
            let c = corr(&bexp, exp, &d.win.count);
            if c.abs() >= AMBIGUITY_CORR {
                group.push((t.effect, c, *dbic));
            }
        }
        if group.len() > 1 {
            ambiguous.push(Ambiguous {
                effects: group.iter().map(|g| g.0.name()).collect(),
                correlation: group.iter().map(|g| g.1).collect(),
                delta_bic: group.iter().map(|g| g.2).collect(),
                suggestion: separation(group[0].0, group[1].0),
            });
            excluded.extend(group.iter().map(|g| g.0));
            nuisance.push(bt);
        } else {
            chosen.push(Step {
                term: bt,
                delta_bic: bdbic,
            });
        }
        // Re-fit every non-linear parameter with the new set.
        // Re-fit every non-linear parameter with the new set: over its
        // whole grid (an effect chosen early may have bent far to imitate
        // one chosen later: a knee fitted alone takes the linear slope's
        // share), then locally.
        let mut terms = current(&chosen, &nuisance);
        for j in 0..terms.len() {
            d.optimize(&mut terms, j);
        }
        for j in 0..terms.len() {
            d.refine(&mut terms, j);
        }
        let nc = chosen.len();
        for (j, t) in terms.iter().enumerate() {
            if j < nc {
                chosen[j].term = *t;
            } else {
                nuisance[j - nc] = *t;
            }
        }
    }
    Selection {
        chosen,
        nuisance,
        ambiguous,
        inflation: phi,
    }
}

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
    let terms: Vec<Term> = sel
        .chosen
        .iter()
        .map(|s| s.term)
        .chain(sel.nuisance.iter().copied())
        .collect();
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
