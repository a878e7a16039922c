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

use super::design::{Design, Term};
use crate::model::effects::Effect;

/// BIC decrease an effect must bring to be named ("very strong" evidence).
pub const BIC_THRESHOLD: f64 = 10.0;
/// Ambiguity: BIC gains within this much of the best (the data prefers
/// neither strongly) ...
pub const AMBIGUITY_MARGIN: f64 = 10.0;
/// ... and explained parts correlated this much.
pub const AMBIGUITY_CORR: f64 = 0.9;

/// A step of the selection.
#[derive(Clone, Debug)]
pub struct Step {
    pub term: Term,
    pub delta_bic: f64,
}

/// Effects a run cannot tell apart.
#[derive(Clone, Debug, serde::Serialize)]
pub struct Ambiguous {
    pub effects: Vec<Effect>,
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

/// The chosen effects, then the nuisance ones: the terms of the fit.
fn current(chosen: &[Step], nuisance: &[Term]) -> Vec<Term> {
    chosen
        .iter()
        .map(|s| s.term)
        .chain(nuisance.iter().copied())
        .collect()
}

impl Selection {
    /// Every term in the final fit, chosen first.
    pub fn terms(&self) -> Vec<Term> {
        current(&self.chosen, &self.nuisance)
    }
}

/// A candidate's best fit added to the current set.
#[derive(Clone)]
struct Trial {
    term: Term,
    delta_bic: f64,
    /// What it explains beyond the current set (window means).
    explained: Vec<f64>,
}

/// Weighted sum of squares of window means.
fn weighted_sse(d: &Design, r: &[f64]) -> f64 {
    r.iter().zip(&d.win.count).map(|(v, c)| c * v * v).sum()
}

/// Every candidate `open` admits, fitted jointly with the current terms
/// `base` (their residual `r_cur`, its weighted sum `sse_cur`): its BIC
/// change with inflation `phi` and what it explains.
fn trials(
    d: &Design,
    candidates: &[Effect],
    open: impl Fn(Effect) -> bool,
    base: &[Term],
    (r_cur, sse_cur): (&[f64], f64),
    phi: f64,
) -> Vec<Trial> {
    let n = d.n();
    let mut evals = vec![];
    for &e in candidates {
        if !open(e) {
            continue;
        }
        let mut terms = base.to_vec();
        terms.push(Term { effect: e, x: 0.0 });
        let j = terms.len() - 1;
        d.optimize(&mut terms, j);
        let Some((_, r)) = d.fit(&terms) else {
            continue;
        };
        let sse = weighted_sse(d, &r);
        let k = (e.linear_params().len() + usize::from(e.nonlinear_param().is_some())) as f64;
        evals.push(Trial {
            term: terms[j],
            delta_bic: n * (sse / sse_cur).ln() / phi + k * n.ln(),
            explained: r_cur.iter().zip(&r).map(|(a, b)| a - b).collect(),
        });
    }
    evals
}

/// The best trial and those the run cannot tell from it (BIC change within
/// [`AMBIGUITY_MARGIN`] of the best's, what they explain correlated with
/// what it explains): (effect, correlation, BIC change), the best first.
fn ambiguity_group(d: &Design, evals: &[Trial], best: usize) -> Vec<(Effect, f64, f64)> {
    let b = &evals[best];
    let mut group = vec![(b.term.effect, 1.0, b.delta_bic)];
    for (i, t) in evals.iter().enumerate() {
        if i == best || t.delta_bic > b.delta_bic + AMBIGUITY_MARGIN {
            continue;
        }
        let c = corr(&b.explained, &t.explained, &d.win.count);
        if c.abs() >= AMBIGUITY_CORR {
            group.push((t.term.effect, c, t.delta_bic));
        }
    }
    group
}

/// Re-fits every non-linear parameter with the new set: over its whole
/// grid (an effect chosen early may have bent far to imitate one chosen
/// later: a knee fitted alone takes the linear slope's share), then
/// locally.
fn refit(d: &Design, chosen: &mut [Step], nuisance: &mut [Term]) {
    let mut terms = current(chosen, nuisance);
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

/// Forward selection over `candidates` with variance inflation `phi`.
pub fn select(d: &Design, candidates: &[Effect], phi: f64) -> Selection {
    let mut chosen: Vec<Step> = vec![];
    let mut nuisance: Vec<Term> = vec![];
    let mut ambiguous = vec![];
    let mut excluded: Vec<Effect> = vec![];
    loop {
        let base = current(&chosen, &nuisance);
        let Some((_, r_cur)) = d.fit(&base) else {
            break;
        };
        let sse_cur = weighted_sse(d, &r_cur);
        if sse_cur <= 0.0 {
            break;
        }
        let open =
            |e: Effect| !(excluded.contains(&e) || chosen.iter().any(|s| s.term.effect == e));
        let evals = trials(d, candidates, open, &base, (&r_cur, sse_cur), phi);
        let Some(best) = evals
            .iter()
            .enumerate()
            .min_by(|a, b| a.1.delta_bic.total_cmp(&b.1.delta_bic))
            .map(|(i, _)| i)
        else {
            break;
        };
        let (bt, bdbic) = (evals[best].term, evals[best].delta_bic);
        if bdbic > -BIC_THRESHOLD {
            break;
        }
        let group = ambiguity_group(d, &evals, best);
        if group.len() > 1 {
            ambiguous.push(Ambiguous {
                effects: group.iter().map(|g| g.0).collect(),
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
        refit(d, &mut chosen, &mut nuisance);
    }
    Selection {
        chosen,
        nuisance,
        ambiguous,
        inflation: phi,
    }
}
