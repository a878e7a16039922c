//! Stepwise selection of named effects (docs/discovery.md).
//!
//! Every fit carries a constant. At each step every open candidate (the
//! library's effects, and the shapes and steps the library has no name
//! for) is fitted jointly with the terms already in (its non-linear
//! parameter by search); the one that lowers the criterion most comes in
//! if it lowers it by more than [`THRESHOLD`]:
//!
//! - an effect whose fitted parameters leave their physical range
//!   (ranges.rs) is not named: it is an implausible fit, kept as a term
//!   no name explains;
//! - an effect the run cannot tell from others (their criterion within
//!   [`AMBIGUITY_MARGIN`], what they explain correlated at |r| >=
//!   [`AMBIGUITY_CORR`], their parameters plausible) is not named either:
//!   the group is reported and its simplest member carried in the model;
//! - a shape or step comes in as what the library does not explain,
//!   unless an effect explains the same as well (then the effect).
//!
//! After each addition every non-linear parameter is re-fitted, and every
//! term whose removal costs less than [`THRESHOLD`] is dropped, the
//! cheapest first (backward steps), never to return.

use super::design::{Design, Fit};
use super::terms::{without, Kind, Shape, Term, PERIODIC_MIN_S};
use super::transients::{cusum_peaks, step_peaks, white_sigma, MAX_STEPS};
use crate::model::effects::Effect;
use crate::model::ranges;

/// Criterion decrease a term must bring to come in, and to stay ("very
/// strong" evidence).
pub const THRESHOLD: f64 = 10.0;
/// Windows a fit must leave beyond its parameters (its residual's degrees
/// of freedom).
pub const MIN_RESIDUAL_DOF: f64 = 1.0;
/// Ambiguity: criteria within this much of the best's ...
pub const AMBIGUITY_MARGIN: f64 = 10.0;
/// ... and explained parts correlated this much.
pub const AMBIGUITY_CORR: f64 = 0.9;

/// An effect named, with the criterion's change when it came in.
#[derive(Clone, Debug)]
pub struct Step {
    pub term: Term,
    pub delta_bic: f64,
}

/// Effects a run cannot tell apart, and the one carried for them.
#[derive(Clone, Debug, serde::Serialize)]
pub struct Ambiguous {
    pub effects: Vec<Effect>,
    /// Correlation of what each explains with what the first explains.
    pub correlation: Vec<f64>,
    pub delta_bic: Vec<f64>,
    pub suggestion: String,
    /// The member carried in the model for the group (the simplest).
    pub carried_as: Effect,
}

/// A fit of an effect whose parameters leave their physical range.
#[derive(Clone, Debug, serde::Serialize)]
pub struct Implausible {
    pub effect: Effect,
    pub parameters: Vec<(String, f64)>,
    /// The parameters outside, with their range.
    pub outside: Vec<(String, f64, (f64, f64))>,
}

pub struct Selection {
    pub named: Vec<Step>,
    /// Representatives of ambiguous groups (effects, unnamed).
    pub carried: Vec<Term>,
    /// What no effect of the library explains: shapes, steps, implausible
    /// effects.
    pub nuisance: Vec<Term>,
    pub ambiguous: Vec<Ambiguous>,
    pub implausible: Vec<Implausible>,
    /// Terms the backward steps removed.
    pub dropped: Vec<Kind>,
}

impl Selection {
    /// Every term of the final fit: the constant, the named, the carried,
    /// the nuisance.
    pub fn terms(&self) -> Vec<Term> {
        let mut t = vec![Term::of(Kind::Constant)];
        t.extend(self.named.iter().map(|s| s.term));
        t.extend(self.carried.iter().copied());
        t.extend(self.nuisance.iter().copied());
        t
    }

    /// The named effects.
    pub fn named_effects(&self) -> Vec<Effect> {
        self.named
            .iter()
            .filter_map(|s| s.term.kind.effect())
            .collect()
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
    } else if pair(ScaleFactorTemperature, CaseTemperature)
        || pair(ScaleFactorTemperature, Bias)
        || pair(ScaleFactorTemperature, BiasTemperature)
    {
        "reverse the table or rest during the temperature sweep: at one rate a scale factor over temperature is a bias over temperature"
    } else if pair(BiasTemperature, Shupe) || pair(BiasTemperature, Bias) {
        "hold the temperature at plateaus (steps with soaks) and ramp it at different rates: a bias that follows the temperature stays on a plateau, the Shupe bias goes with the ramp"
    } else if pair(LockIn, ScaleFactorError) {
        "add rates close to the lock-in rate (a few times it) and far above it"
    } else {
        "a profile in which the two regressors vary independently"
    };
    s.to_owned()
}

/// Weighted cosine of two explained parts.
pub fn corr(a: &[f64], b: &[f64]) -> f64 {
    let (mut sab, mut saa, mut sbb) = (0.0, 0.0, 0.0);
    for i in 0..a.len().min(b.len()) {
        sab += a[i] * b[i];
        saa += a[i] * a[i];
        sbb += b[i] * b[i];
    }
    if saa > 0.0 && sbb > 0.0 {
        sab / (saa * sbb).sqrt()
    } else {
        0.0
    }
}

/// The parameters of `terms[j]` in a joint fit: its linear ones from the
/// coefficients (in the units their names state), then its non-linear one.
pub fn params_of(terms: &[Term], fit: &Fit, j: usize) -> Vec<(&'static str, f64)> {
    let mut col = 0;
    for t in &terms[..j] {
        col += columns(t.kind);
    }
    match terms[j].kind {
        Kind::Effect(e) => {
            let mut p: Vec<(&'static str, f64)> = e
                .linear_params()
                .iter()
                .enumerate()
                .map(|(i, n)| (*n, fit.coef.get(col + i).copied().unwrap_or(0.0)))
                .collect();
            if let Some(n) = e.nonlinear_param() {
                p.push((n, terms[j].x));
            }
            p
        }
        Kind::Constant => vec![("bias_dph", fit.coef.get(col).copied().unwrap_or(0.0))],
        _ => vec![],
    }
}

/// Columns a term adds to the fit.
pub fn columns(k: Kind) -> usize {
    match k {
        Kind::Effect(e) => e.linear_params().len(),
        Kind::Periodic => 2,
        _ => 1,
    }
}

/// A candidate fitted jointly with the current terms.
#[derive(Clone)]
struct Trial {
    term: Term,
    delta: f64,
    /// What it explains beyond the current set (whitened).
    explained: Vec<f64>,
    params: Vec<(&'static str, f64)>,
}

impl Trial {
    fn plausible(&self, d: &Design) -> bool {
        match self.term.kind {
            Kind::Effect(e) => ranges::outside(e, &self.params, &d.extent).is_empty(),
            _ => true,
        }
    }
}

/// Every candidate in `open`, fitted with `base` (criterion `c_cur`, its
/// whitened residual `r_cur`).
fn trials(d: &Design, open: &[Term], base: &[Term], r_cur: &[f64], c_cur: f64) -> Vec<Trial> {
    let trial = |cand: Term, full: bool| -> Option<Trial> {
        let mut terms = base.to_vec();
        terms.push(cand);
        let dof: usize = terms.iter().map(|t| t.kind.dof()).sum();
        // A fit must leave the residual some scatter to measure its noise
        // by: as many parameters as windows fit any record exactly.
        if (dof as f64) + MIN_RESIDUAL_DOF > d.n() {
            return None;
        }
        let j = terms.len() - 1;
        if full {
            d.optimize(&mut terms, j);
        } else {
            d.optimize_on_grid(&mut terms, j);
        }
        let f = d.fit(&terms)?;
        Some(Trial {
            term: terms[j],
            delta: d.criterion(f.sse, dof) - c_cur,
            explained: r_cur.iter().zip(&f.resid).map(|(a, b)| a - b).collect(),
            params: params_of(&terms, &f, j),
        })
    };
    // Every candidate on its parameter's grid; then those that could
    // lead, their parameter refined between the grid's points.
    let mut out: Vec<Trial> = open.iter().filter_map(|c| trial(*c, false)).collect();
    let best = out.iter().map(|t| t.delta).fold(f64::INFINITY, f64::min);
    for t in out.iter_mut() {
        if d.searched(&t.term) && t.delta <= best + REFINE_MARGIN {
            if let Some(r) = trial(Term::of(t.term.kind), true) {
                if r.delta <= t.delta {
                    *t = r;
                }
            }
        }
    }
    out
}

/// Candidates whose grid search comes within this much of the best
/// trial's criterion have their parameter refined.
const REFINE_MARGIN: f64 = 2.0 * AMBIGUITY_MARGIN;

/// The library trials the run cannot tell from `best` (plausible, within
/// the margin, correlated): (effect, correlation, criterion change), best
/// first.
fn group_of(d: &Design, ts: &[Trial], best: usize) -> Vec<(Effect, f64, f64, Term)> {
    let b = &ts[best];
    let Some(be) = b.term.kind.effect() else {
        return vec![];
    };
    let mut g = vec![(be, 1.0, b.delta, b.term)];
    for (i, t) in ts.iter().enumerate() {
        let Some(e) = t.term.kind.effect() else {
            continue;
        };
        if i == best || t.delta > b.delta + AMBIGUITY_MARGIN || !t.plausible(d) {
            continue;
        }
        let c = corr(&b.explained, &t.explained);
        if c.abs() >= AMBIGUITY_CORR {
            g.push((e, c, t.delta, t.term));
        }
    }
    g
}

/// The simplest of a group: fewest parameters, then the library's order.
fn simplest(g: &[(Effect, f64, f64, Term)]) -> usize {
    (0..g.len())
        .min_by_key(|&i| (g[i].0.dof(), g[i].0))
        .unwrap_or(0)
}

/// The selection's state while it runs.
struct State {
    sel: Selection,
    /// Effects and shapes that may no longer come in, and step times.
    closed: Vec<Kind>,
    closed_steps: Vec<f64>,
    /// Kinds the selection never offers (set aside by the confirmation).
    excluded: Vec<Kind>,
}

impl State {
    fn removable(&self) -> Vec<(usize, Term)> {
        let s = &self.sel;
        let a = s.named.iter().map(|x| (0, x.term));
        let b = s.carried.iter().map(|t| (1, *t));
        let c = s.nuisance.iter().map(|t| (2, *t));
        a.chain(b).chain(c).collect()
    }

    fn remove(&mut self, list: usize, t: &Term) {
        let s = &mut self.sel;
        match list {
            0 => s.named.retain(|x| x.term != *t),
            1 => {
                s.carried.retain(|x| x != t);
                if let Some(e) = t.kind.effect() {
                    s.ambiguous.retain(|g| g.carried_as != e);
                }
            }
            _ => s.nuisance.retain(|x| x != t),
        }
        self.sel.dropped.push(t.kind);
        if t.kind == Kind::Step {
            self.closed_steps.push(t.x);
        } else {
            self.closed.push(t.kind);
        }
    }
}

/// Re-fits every non-linear parameter with the current set: over its whole
/// grid, then locally.
fn refit(d: &Design, sel: &mut Selection) {
    let mut terms = sel.terms();
    for j in 0..terms.len() {
        d.optimize(&mut terms, j);
    }
    for j in 0..terms.len() {
        d.refine(&mut terms, j);
    }
    let (nn, nc) = (sel.named.len(), sel.carried.len());
    for (j, t) in terms.into_iter().enumerate().skip(1) {
        let i = j - 1;
        if i < nn {
            sel.named[i].term = t;
        } else if i < nn + nc {
            sel.carried[i - nn] = t;
        } else {
            sel.nuisance[i - nn - nc] = t;
        }
    }
}

/// Backward steps: drops the cheapest term while its removal costs less
/// than [`THRESHOLD`].
fn backward(d: &Design, st: &mut State) {
    loop {
        let terms = st.sel.terms();
        let c_full = d.criterion_of(&terms);
        let cheapest = st
            .removable()
            .into_iter()
            .map(|(list, t)| {
                let rest: Vec<Term> = terms.iter().filter(|x| **x != t).copied().collect();
                (list, t, d.criterion_of(&rest) - c_full)
            })
            .min_by(|a, b| a.2.total_cmp(&b.2));
        match cheapest {
            Some((list, t, cost)) if cost < THRESHOLD => {
                st.remove(list, &t);
                refit(d, &mut st.sel);
            }
            _ => return,
        }
    }
}

/// Named effects whose parameters left their range after later
/// additions: moved to the nuisance terms, reported implausible.
fn recheck(d: &Design, st: &mut State) {
    let terms = st.sel.terms();
    let Some(f) = d.fit(&terms) else {
        return;
    };
    let mut moved = vec![];
    for (j, t) in terms.iter().enumerate() {
        let Some(e) = t.kind.effect() else {
            continue;
        };
        if !st.sel.named.iter().any(|s| s.term == *t) {
            continue;
        }
        let p = params_of(&terms, &f, j);
        let out = ranges::outside(e, &p, &d.extent);
        if !out.is_empty() {
            st.sel.implausible.push(Implausible {
                effect: e,
                parameters: p.iter().map(|(n, v)| (n.to_string(), *v)).collect(),
                outside: out,
            });
            moved.push(*t);
        }
    }
    for t in moved {
        st.sel.named.retain(|s| s.term != t);
        st.sel.nuisance.push(t);
        st.closed.push(t.kind);
    }
}

/// The open candidates: library effects and shapes not in or closed, and
/// the steps offered.
fn open(d: &Design, candidates: &[Effect], st: &State) -> Vec<Term> {
    let inside = st.sel.terms();
    let taken = |k: Kind| {
        st.closed.contains(&k) || st.excluded.contains(&k) || inside.iter().any(|t| t.kind == k)
    };
    let periodic = (d.win.len() > 1
        && d.win.t[d.win.len() - 1] - d.win.t[0] >= 3.0 * PERIODIC_MIN_S)
        .then_some(Kind::Periodic);
    let mut v: Vec<Term> = candidates
        .iter()
        .map(|&e| Kind::Effect(e))
        .chain(
            Shape::ALL
                .into_iter()
                .filter(|s| s.available(d.inp))
                .map(Kind::Shape),
        )
        .chain(periodic)
        .filter(|&k| !taken(k))
        .map(Term::of)
        .collect();
    // Steps: those found after the first pass, and where the current
    // residual's level jumps most (a step is searched for like a knee).
    let n_steps = inside.iter().filter(|t| t.kind == Kind::Step).count();
    if n_steps < MAX_STEPS && st.closed_steps.is_empty() && !st.excluded.contains(&Kind::Step) {
        let mut xs = d.steps.clone();
        if let Some(f) = d.fit(&inside) {
            let parts = d.parts(&inside, &f.coef);
            let e: Vec<f64> = (0..d.r.len())
                .map(|k| d.r[k] - parts.iter().map(|p| p[k]).sum::<f64>())
                .collect();
            xs.extend(step_peaks(d.win, &e, white_sigma(&e), 4.0, 3));
            xs.extend(cusum_peaks(d.win, &e, 2));
        }
        for x in xs {
            let t = Term {
                kind: Kind::Step,
                x,
            };
            if !inside.contains(&t) && !v.contains(&t) {
                v.push(t);
            }
        }
    }
    v
}

/// Exchanges a selection may make.
pub const MAX_EXCHANGES: usize = 4;

/// Exchanges tried in full per exchange step (the best of the quick
/// trials).
const EXCHANGE_TRIES: usize = 6;

/// The criterion of `terms` once every non-linear parameter is re-fitted
/// and every term (the constant aside) whose removal costs less than
/// [`THRESHOLD`] is dropped, cheapest first.
fn settled(d: &Design, mut terms: Vec<Term>) -> f64 {
    for j in 0..terms.len() {
        d.optimize(&mut terms, j);
    }
    loop {
        let c = d.criterion_of(&terms);
        let cheapest = (1..terms.len())
            .map(|j| {
                let rest = without(&terms, j);
                (j, d.criterion_of(&rest) - c)
            })
            .min_by(|a, b| a.1.total_cmp(&b.1));
        match cheapest {
            Some((j, cost)) if cost < THRESHOLD => {
                terms.remove(j);
            }
            _ => return c,
        }
    }
}

/// The exchange step (sequential replacement), once nothing more comes in:
/// each term in (named or unexplained) is tried replaced by each open
/// candidate, the latter's non-linear parameter searched; the best few
/// replacements are then settled (every non-linear parameter re-fitted,
/// what the replacement makes redundant dropped). When one lowers the
/// criterion by more than [`THRESHOLD`], the term it replaces and the
/// kind that replaces it: the term leaves (it may come back), and the
/// replacement comes in through the forward step's checks. A forward
/// selection that took first what explains most of two effects together
/// (a monoblock difference's square for a case temperature with a
/// warm-up) otherwise keeps it, and the effects it imitates never come in.
fn exchange(d: &Design, candidates: &[Effect], st: &State) -> Option<(usize, Term, Term)> {
    let base = st.sel.terms();
    let c_cur = d.criterion_of(&base);
    let open = open(d, candidates, st);
    let mut quick: Vec<(usize, Term, Term, f64)> = vec![];
    for (list, t) in st.removable() {
        if list == 1 {
            continue;
        }
        let rest: Vec<Term> = base.iter().filter(|x| **x != t).copied().collect();
        let Some(cur) = d.fit(&rest) else {
            continue;
        };
        let c_rest = d.criterion_of(&rest);
        for tr in trials(d, &open, &rest, &cur.resid, c_rest) {
            if tr.term.kind != t.kind {
                quick.push((list, t, tr.term, c_rest + tr.delta - c_cur));
            }
        }
    }
    quick.sort_by(|a, b| a.3.total_cmp(&b.3));
    let mut best: Option<(usize, Term, Term, f64)> = None;
    for (list, t, cand, _) in quick.into_iter().take(EXCHANGE_TRIES) {
        let mut terms: Vec<Term> = base.iter().filter(|x| **x != t).copied().collect();
        terms.push(cand);
        let delta = settled(d, terms) - c_cur;
        if best.as_ref().is_none_or(|b| delta < b.3) {
            best = Some((list, t, cand, delta));
        }
    }
    let (list, t, cand, delta) = best?;
    (delta < -THRESHOLD).then_some((list, t, cand))
}

/// Stepwise selection over `candidates` (library effects; not the bias,
/// whose constant every fit carries), never offering the kinds in
/// `excluded` (shapes, steps, the periodic disturbance).
pub fn select(d: &Design, candidates: &[Effect], excluded: &[Kind]) -> Selection {
    let mut st = State {
        sel: Selection {
            named: vec![],
            carried: vec![],
            nuisance: vec![],
            ambiguous: vec![],
            implausible: vec![],
            dropped: vec![],
        },
        closed: vec![],
        closed_steps: vec![],
        excluded: excluded.to_vec(),
    };
    let mut exchanges = 0;
    let mut next_forced: Option<Term> = None;
    for _ in 0..4 * (candidates.len() + Shape::ALL.len() + d.steps.len() + 3) {
        let forced = next_forced.take();
        let base = st.sel.terms();
        let Some(cur) = d.fit(&base) else {
            break;
        };
        let c_cur = d.criterion_of(&base);
        let ts = trials(d, &open(d, candidates, &st), &base, &cur.resid, c_cur);
        let forced = forced.and_then(|k: Term| {
            ts.iter()
                .position(|t| t.term.kind == k.kind && (k.kind != Kind::Step || t.term.x == k.x))
        });
        let Some(mut best) =
            forced.or_else(|| (0..ts.len()).min_by(|&a, &b| ts[a].delta.total_cmp(&ts[b].delta)))
        else {
            break;
        };
        if forced.is_none() && ts[best].delta > -THRESHOLD {
            if exchanges < MAX_EXCHANGES {
                if let Some((list, t, cand)) = exchange(d, candidates, &st) {
                    exchanges += 1;
                    let s = &mut st.sel;
                    match list {
                        0 => s.named.retain(|x| x.term != t),
                        _ => s.nuisance.retain(|x| *x != t),
                    }
                    refit(d, s);
                    next_forced = Some(cand);
                    continue;
                }
            }
            break;
        }
        // A shape yields to an effect that explains the same as well.
        if ts[best].term.kind.effect().is_none() {
            let rival = (0..ts.len())
                .filter(|&i| {
                    ts[i].term.kind.effect().is_some()
                        && ts[i].delta <= ts[best].delta + AMBIGUITY_MARGIN
                        && ts[i].delta < -THRESHOLD
                        && ts[i].plausible(d)
                        && corr(&ts[i].explained, &ts[best].explained).abs() >= AMBIGUITY_CORR
                })
                .min_by(|&a, &b| ts[a].delta.total_cmp(&ts[b].delta));
            match rival {
                Some(i) => best = i,
                None => {
                    st.sel.nuisance.push(ts[best].term);
                    refit(d, &mut st.sel);
                    backward(d, &mut st);
                    continue;
                }
            }
        }
        let b = &ts[best];
        let Some(e) = b.term.kind.effect() else {
            break;
        };
        if !b.plausible(d) {
            st.sel.implausible.push(Implausible {
                effect: e,
                parameters: b.params.iter().map(|(n, v)| (n.to_string(), *v)).collect(),
                outside: ranges::outside(e, &b.params, &d.extent),
            });
            st.sel.nuisance.push(b.term);
            st.closed.push(b.term.kind);
        } else {
            let g = group_of(d, &ts, best);
            if g.len() > 1 {
                let rep = simplest(&g);
                st.sel.ambiguous.push(Ambiguous {
                    effects: g.iter().map(|x| x.0).collect(),
                    correlation: g.iter().map(|x| x.1).collect(),
                    delta_bic: g.iter().map(|x| x.2).collect(),
                    suggestion: separation(g[0].0, g[1].0),
                    carried_as: g[rep].0,
                });
                st.sel.carried.push(g[rep].3);
                st.closed.extend(g.iter().map(|x| Kind::Effect(x.0)));
            } else {
                st.sel.named.push(Step {
                    term: b.term,
                    delta_bic: b.delta,
                });
            }
        }
        refit(d, &mut st.sel);
        backward(d, &mut st);
        recheck(d, &mut st);
    }
    st.sel
}
