//! Beyond the library (issue 32): the terms of the model file that are
//! not library effects. A user's term written by hand has its parameters
//! fitted; where the library leaves the residual unexplained, a term built
//! from the run's own inputs is proposed (model/proposal/), validated on
//! blocks of the record it was not fitted on, added to the model, and the
//! library's selection run again with it in place, so the effects are
//! named beside the term as they would be had the library held it.
//!
//! A proposal is kept only where the gap after shrinks with it; the gap
//! before stays the model given's.

use super::fit_columns::{columns_of, jointly_linear, saves_at_least, SURELY};
use super::likelihood::{self, Problem};
use super::noise_model::{NoiseModel, Whitener};
use super::result::{Discovery, Options, Proposals, Run, TermFound, NOT_SIGNIFICANT};
use super::select::Implausible;
use super::select::THRESHOLD as NAME_THRESHOLD;
use crate::model::effects::Effect;
use crate::model::gyro_model::Model;
use crate::model::inputs::Inputs;
use crate::model::proposal::refit::{fit_term, is_linear};
use crate::model::proposal::{propose, Validation, Variant};
use crate::model::term::Term;
use std::collections::BTreeMap;

/// The library's discovery (mod.rs's `discover_library`), given by the
/// caller.
pub type Library<'a> = &'a dyn Fn(&Model, &Run, &Options) -> Discovery;

/// A proposed term's label, the intervals its search gave and its
/// validation.
type ProposedMeta = (String, BTreeMap<String, (f64, f64)>, Validation);

/// Most terms proposed on one run.
pub const MAX_PROPOSED: usize = 2;

/// A term is proposed only where the gap after the library stands at
/// least this many times above the noise floor: below it, what is left is
/// as much an imperfect library effect or noise model (a sensor's lag, a
/// flicker at the floor) as a missing term, and a term would be named
/// for a few percent of the gap.
pub const MIN_GAP_OVER_FLOOR: f64 = 1.2;

/// Below this many times the noise floor a proposed term must also be
/// confirmed by the noise fitted again with it in place (the gate that
/// started a search until issue 39's last session).
pub const CONFIRM_BELOW: f64 = 1.5;

/// The least share of the gap's excess over the noise floor (in variance)
/// a proposed term must close.
pub const MIN_CLOSED: f64 = 0.5;

/// The whitened rows of per-row columns in deg/h, under `d`'s noise.
struct Rows<'a> {
    d: &'a Discovery,
    wh: Whitener,
}

impl<'a> Rows<'a> {
    fn new(d: &'a Discovery) -> Self {
        Self::with_noise(d, &d.noise)
    }
    /// Whitened under another noise model than the one `d` fitted.
    fn with_noise(d: &'a Discovery, noise: &NoiseModel) -> Self {
        Self {
            wh: Whitener::new(noise, &d.windows, &d.keep),
            d,
        }
    }
    fn dph(&self, x: &[f64]) -> Vec<f64> {
        let s: Vec<f64> = x.iter().map(|v| v / 3600.0).collect();
        self.wh.whiten(&self.d.windows.mean(&s))
    }
    fn dps(&self, x: &[f64]) -> Vec<f64> {
        self.wh.whiten(&self.d.windows.mean(x))
    }
    /// Window-level columns in deg/h, whitened many at a time.
    fn windows_dph(&self, xs: &[&[f64]]) -> Vec<Vec<f64>> {
        let s: Vec<Vec<f64>> = xs
            .iter()
            .map(|x| x.iter().map(|v| v / 3600.0).collect())
            .collect();
        let r: Vec<&[f64]> = s.iter().map(Vec::as_slice).collect();
        self.wh.whiten_many(&r)
    }
}

/// The whitened columns the discovery's fit carries: the constant, every
/// parameter of the effects it added to `given`, and every parameter of
/// the model's terms but term `skip`.
fn fit_columns(
    given: &Model,
    d: &Discovery,
    inp: &Inputs,
    rows: &Rows,
    skip: Option<usize>,
) -> Vec<Vec<f64>> {
    columns_of(given, d, inp, (skip, None), &|x| rows.dps(x))
}

/// Term `i` of `d`'s model fitted on `d`'s residual (its other terms and
/// effects carried), `free` its parameters let move.
fn refit(
    given: &Model,
    d: &Discovery,
    run: &Run,
    i: usize,
    free: &[String],
) -> Option<crate::model::proposal::refit::TermFit> {
    let inp = &run.inputs;
    let rows = Rows::new(d);
    let t = &d.model_after.terms[i];
    let mut y = rows.dps(&d.residual_after);
    let own = rows.dph(&t.evaluate(inp).ok()?);
    y.iter_mut().zip(&own).for_each(|(a, b)| *a += b);
    let fit = fit_columns(given, d, inp, &rows, Some(i));
    fit_term(t, free, inp, &y, &fit, &|x| rows.dph(x))
}

/// The term just added (the model's last) with its coefficients fitted
/// again beside the effects the library named with it, and the library
/// run once more, where that shrinks the gap. The search fitted them
/// beside the effects named without it, and those may be the term's
/// stand-ins that the library drops once it is in (a Shupe bias beside a
/// temperature's curvature): the coefficient carried would be theirs too.
fn settle(
    given: &Model,
    m2: Model,
    next: Discovery,
    run: &Run,
    opts: &Options,
    discover_library: Library,
) -> (Model, Discovery) {
    let i = m2.terms.len() - 1;
    let Some(t) = next.model_after.terms.get(i) else {
        return (m2, next);
    };
    let free = free_params(t, true, &run.inputs);
    let Some(f) = refit(given, &next, run, i, &free) else {
        return (m2, next);
    };
    if f.term.params == t.params {
        return (m2, next);
    }
    let mut m3 = m2.clone();
    m3.terms[i] = f.term;
    let again = discover_library(&m3, run, opts);
    if again.gap_after_dph < next.gap_after_dph {
        (m3, again)
    } else {
        (m2, next)
    }
}

/// With two terms or more proposed, their linear coefficients fitted
/// jointly (fit_columns.rs `jointly_linear`) and the library run again on
/// them, where that shrinks the gap: [`settle`] fits the newest beside the
/// earlier held.
fn jointly(
    given: &Model,
    m2: Model,
    next: Discovery,
    (run, opts, discover_library): (&Run, &Options, Library),
    users: usize,
) -> (Model, Discovery) {
    if m2.terms.len() < users + 2 {
        return (m2, next);
    }
    let rows = Rows::new(&next);
    let Some(ts) = jointly_linear(given, &next, &run.inputs, users, &|x| rows.dps(x)) else {
        return (m2, next);
    };
    let mut m3 = m2.clone();
    m3.terms.truncate(users);
    m3.terms.extend(ts);
    let again = discover_library(&m3, run, opts);
    // A name the library brings in beside them is asked by `prune`, as
    // every name beside a term is.
    if again.gap_after_dph < next.gap_after_dph {
        (m3, again)
    } else {
        (m2, next)
    }
}

/// Twice the log-likelihood ratio of `t` on what `d`'s model leaves: its
/// shape as proposed, its size and a constant free, against the constant
/// alone, each side with the noise's random walk, flicker and Markov
/// levels at their maximum (plain) likelihood (likelihood.rs `profile`).
fn likelihood_gain(d: &Discovery, t: &Term, inp: &Inputs) -> Option<f64> {
    let y = d.windows.mean(&d.residual_after);
    let g: Vec<f64> = t.evaluate(inp).ok()?.iter().map(|v| v / 3600.0).collect();
    let ones = vec![1.0; y.len()];
    let without = Problem::new(&d.windows, &d.keep, &y, std::slice::from_ref(&ones));
    let with = Problem::new(&d.windows, &d.keep, &y, &[ones, d.windows.mean(&g)]);
    let (_, l0) = likelihood::profile(&d.noise, &without, false);
    let (_, l1) = likelihood::profile(&d.noise, &with, false);
    let v = 2.0 * (l1 - l0);
    v.is_finite().then_some(v)
}

/// `m` with term `swap.0` replaced by `swap.1` (if any), the library run
/// on it with `o`, the proposed terms (from `users` on) refitted in all
/// their parameters beside what it names, and the library run again.
fn refitted_without(
    given: &Model,
    m: &Model,
    swap: Option<(usize, &Term)>,
    (run, o, discover_library): (&Run, &Options, Library),
    users: usize,
) -> (Model, Discovery) {
    let mut m1 = m.clone();
    if let Some((i, t)) = swap {
        m1.terms[i] = t.clone();
    }
    let mut d = discover_library(&m1, run, o);
    let mut m2 = m1.clone();
    for i in users..m1.terms.len() {
        let Some(t) = d.model_after.terms.get(i) else {
            continue;
        };
        if let Some(f) = refit(given, &d, run, i, &free_params(t, false, &run.inputs)) {
            m2.terms[i] = f.term;
        }
    }
    if m2 != m1 {
        d = discover_library(&m2, run, o);
    }
    (m2, d)
}

/// The library's names beside the proposed terms, each asked whether it
/// pays its way with them in place: the library run without it, the
/// proposed terms refitted in all their parameters beside what is left
/// (a lag's time constant moves where a scale factor over temperature had
/// stood in for the difference), and the name dropped where the 1 s
/// means' sum of squares it saves, in noise variances, is under the
/// library's own criterion (its threshold and ln n per parameter). The
/// simplest model the data allow: a term and the name that imitates a
/// part of it are one effect told twice. Where the library names another
/// effect in its place, the name stays.
///
/// Where the term alone cannot take the name's place, its variants with
/// a second part are asked (the term led, its lagged input part direct,
/// or its square: a sensor that lags the physics makes a lagged effect
/// look like a lag plus an unlagged scale factor); one that lets the name
/// go replaces the term and its label (`meta`).
fn prune(
    given: &Model,
    mut m: Model,
    mut cur: Discovery,
    (run, opts, discover_library): (&Run, &Options, Library),
    users: usize,
    (meta, variants): (&mut [ProposedMeta], &[Vec<Variant>]),
) -> (Discovery, Vec<String>) {
    let mut pruned = vec![];
    let mut replaced = vec![false; variants.len()];
    // The gap's windows (1 s means), which the gaps are the RMS of.
    let n1 = cur.gap_windows.len() as f64;
    let mut o = *opts;
    let named: Vec<(Effect, usize)> = cur
        .found
        .iter()
        .filter(|e| e.effect != Effect::Bias && !given.effects.iter().any(|g| g.effect == e.effect))
        .map(|e| (e.effect, e.params.len()))
        .collect();
    for (e, dof) in named {
        let o2 = o.excluding(e);
        let asks = NAME_THRESHOLD + dof as f64 * n1.ln();
        let floor2 = cur.noise_floor_dph.powi(2).max(1e-300);
        // What the name saves, and whether nothing else is named in its
        // place (a name for a name is no simpler).
        let judge = |d: &Discovery| {
            let saves = n1 * (d.gap_after_dph.powi(2) - cur.gap_after_dph.powi(2)) / floor2;
            let fewer = d
                .found
                .iter()
                .all(|x| cur.found.iter().any(|y| y.effect == x.effect));
            (saves, saves < asks && fewer)
        };
        let ctx = (run, &o2, discover_library);
        let surely = |extra: (Option<&Term>, Option<usize>)| {
            saves_at_least(given, &cur, e, extra, &run.inputs) > SURELY * asks
        };
        let (mut saves, mut drop, mut chosen) = (f64::NAN, false, None);
        let ran = !surely((None, None));
        if ran {
            let (m2, d) = refitted_without(given, &m, None, ctx, users);
            (saves, drop) = judge(&d);
            chosen = Some((m2, d, None));
        }
        if !drop {
            // A term replaced by a variant already is not asked again (its
            // other variants would drop the part the name went for).
            'variants: for (k, vs) in variants.iter().enumerate().filter(|(k, _)| !replaced[*k]) {
                for (label, v, second) in vs {
                    // At the term's present values, its new part at zero.
                    let mut v = v.clone();
                    for (p, x) in &m.terms[users + k].params {
                        v.params.insert(p.clone(), *x);
                    }
                    if surely((Some(&v), ran.then_some(users + k))) {
                        continue;
                    }
                    let (m3, d3) = refitted_without(given, &m, Some((users + k, &v)), ctx, users);
                    let (s3, ok) = judge(&d3);
                    // Refitted: a second part left at zero is the term.
                    let t3 = &m3.terms[users + k].params;
                    if ok && t3.get("k2_dph").is_some_and(|&x| x != 0.0) && second.plausible(t3) {
                        // The variant must predict blocks of the record it
                        // was not fitted on, as the plain term did, by the
                        // space's threshold (the search validated the plain
                        // term, not it).
                        let i = users + k;
                        let free = free_params(&d3.model_after.terms[i], true, &run.inputs);
                        let thr = meta[k].2.threshold;
                        let Some(mut val) = refit(given, &d3, run, i, &free).map(|f| f.validation)
                        else {
                            continue;
                        };
                        if val.held_out_gain.is_nan() || val.held_out_gain < thr {
                            continue;
                        }
                        val.threshold = val.threshold.max(thr);
                        (saves, drop) = (s3, true);
                        chosen = Some((m3, d3, Some((k, label.clone(), val))));
                        break 'variants;
                    }
                }
            }
        }
        if let (true, Some((m2, d, relabel))) = (drop, chosen) {
            let by = match &relabel {
                Some((_, l, _)) => format!("the proposed term as {l}"),
                None => "the proposed term".into(),
            };
            pruned.push(format!(
                "{} (beside {by}, it saves {:.1} noise variances, under the {:.1} a name of {dof} parameter(s) needs)",
                e.name(),
                saves,
                asks
            ));
            if let Some((k, l, val)) = relabel {
                meta[k].0 = l;
                meta[k].2 = val;
                replaced[k] = true;
            }
            (m, cur, o) = (m2, d, o2);
        }
    }
    (cur, pruned)
}

/// The parameters of a term refitted: all of a user's; a proposed term's
/// coefficients (its searched shape parameter keeps the value and the
/// profile interval its search gave).
fn free_params(t: &Term, proposed: bool, inp: &Inputs) -> Vec<String> {
    t.params
        .keys()
        .filter(|p| !proposed || is_linear(t, p, inp))
        .cloned()
        .collect()
}

/// The library effect `t` is the shape of, if any: an effect the first
/// selection fitted but found implausible, or one the library holds for
/// another kind of gyro, whose 1 s means follow the term's to 0.95.
fn disguise(t: &Term, d: &Discovery, implausible: &[Implausible], inp: &Inputs) -> Option<String> {
    let g = d.windows.mean(&t.evaluate(inp).ok()?);
    for i in implausible {
        let params: BTreeMap<String, f64> = i.parameters.iter().cloned().collect();
        let c = d.windows.mean(&i.effect.contribution(inp, &params));
        if crate::numerics::stats::pearson(&g, &c).abs() >= 0.95 {
            let out: Vec<String> = i
                .outside
                .iter()
                .map(|(k, v, r)| {
                    format!(
                        "{k} {} outside {} .. {}",
                        crate::report::text::sig(*v),
                        crate::report::text::sig(r.0),
                        crate::report::text::sig(r.1)
                    )
                })
                .collect();
            return Some(format!(
                "the shape of the library's {}, with {} for a {} gyro: the library's effect at an implausible value",
                i.effect.name(),
                out.join(", "),
                d.grade.value
            ));
        }
    }
    for e in Effect::ALL {
        if e.applies_to(d.gyro) || !e.available(inp) || e.nonlinear_param().is_some() {
            continue;
        }
        for col in e.basis(inp, 0.0).cols {
            if crate::numerics::stats::pearson(&g, &d.windows.mean(&col)).abs() >= 0.95 {
                let kinds: Vec<&str> = [
                    crate::model::gyro_kind::GyroKind::Fog,
                    crate::model::gyro_kind::GyroKind::Rlg,
                    crate::model::gyro_kind::GyroKind::Mems,
                ]
                .into_iter()
                .filter(|k| e.applies_to(*k))
                .map(|k| k.name())
                .collect();
                return Some(format!(
                    "the shape of the library's {}, which the library holds for the {} only",
                    e.name(),
                    kinds.join(" and ")
                ));
            }
        }
    }
    None
}

/// Whether every coefficient's interval excludes zero.
fn significant(t: &Term, intervals: &BTreeMap<String, (f64, f64)>, inp: &Inputs) -> bool {
    let lin: Vec<&String> = t.params.keys().filter(|p| is_linear(t, p, inp)).collect();
    !lin.is_empty()
        && lin.iter().any(|p| {
            intervals
                .get(*p)
                .is_some_and(|(lo, hi)| *lo > 0.0 || *hi < 0.0)
        })
}

/// The user's terms refitted on `cur` until the library's selection no
/// longer moves them (twice at most); a refit is kept where the gap after
/// does not grow.
fn refit_users(
    given: &Model,
    mut m: Model,
    mut cur: Discovery,
    run: &Run,
    opts: &Options,
    users: usize,
    discover_library: Library,
) -> (Model, Discovery) {
    for _ in 0..2 {
        let mut next_m = m.clone();
        let mut moved = false;
        for i in 0..users {
            let free = free_params(&cur.model_after.terms[i], false, &run.inputs);
            if let Some(f) = refit(given, &cur, run, i, &free) {
                moved |= f.term.params != next_m.terms[i].params;
                next_m.terms[i] = f.term;
            }
        }
        if !moved {
            break;
        }
        let next = discover_library(&next_m, run, opts);
        if next.gap_after_dph > cur.gap_after_dph {
            break;
        }
        (m, cur) = (next_m, next);
    }
    (m, cur)
}

/// Discovery with the terms beyond the library: `first` is the library's
/// discovery on `given`.
pub fn beyond(
    given: &Model,
    run: &Run,
    opts: &Options,
    mut first: Discovery,
    discover_library: Library,
) -> Discovery {
    let inp = &run.inputs;
    if first.short.is_some() {
        return first;
    }
    let users = given.terms.len();
    // What the model given leaves, kept for the discovery's 'before'.
    let implausible = first.implausible.clone();
    let gap_before = first.gap_before_dph;
    let residual_before = first.residual_before.clone();
    let allan_before = first.allan_before.take();
    let disagreements = std::mem::take(&mut first.disagreements);
    let (mut m, mut cur) = if users > 0 {
        refit_users(
            given,
            given.clone(),
            first,
            run,
            opts,
            users,
            discover_library,
        )
    } else {
        (given.clone(), first)
    };
    // Proposals: what they were, with their validation.
    let mut proposed: Vec<ProposedMeta> = vec![];
    // Beside each: the input-built candidate a shape of time alone could
    // not be told from.
    let mut rivals: Vec<Option<crate::model::proposal::Tried>> = vec![];
    let mut variants: Vec<Vec<Variant>> = vec![];
    let mut log = Proposals::default();
    // Per proposed term: the gap after without and with it, and the share
    // of the excess above the floor it closed.
    let mut closure: Vec<(f64, f64, f64)> = vec![];
    while cur.unexplained.is_some() && proposed.len() < MAX_PROPOSED {
        if cur.gap_after_dph < MIN_GAP_OVER_FLOOR * cur.noise_floor_dph {
            log.note = Some(format!(
                "the gap after the model, {:.4} deg/h, is less than {MIN_GAP_OVER_FLOOR} times the noise floor ({:.4} deg/h): what stands above the floor is too little to propose a term for",
                cur.gap_after_dph, cur.noise_floor_dph
            ));
            break;
        }
        // First under the noise the discovery fitted; then, where that
        // gives no term the checks below accept, a second look under the
        // grade's noise: where the noise model fitted slow levels beyond
        // any gyro of this grade's (the floor's caps), they may have taken
        // an event of the record as noise (a random walk explains a jump
        // as well as the jump does), and whitened by them the event
        // predicts nothing. A term found there must pass the same checks:
        // it closes most of what stands above the floor, with the
        // library's effects fitted again beside it.
        //
        // Last, where neither gives one, a look under the white noise
        // alone: a grade's caps are wide (a consumer MEMS gyro's random
        // walk may be anything), and an event hundreds of deg/h tall that
        // the fitted noise took as a wander is still the event. Whitened
        // by white noise any wander gains, so a term found there must also
        // be confirmed by the noise fitted again with it in place: refitted
        // on blocks of the record whitened by that noise, it predicts the
        // others by the space's threshold. On a wander it does not: the
        // wander is still there for the noise to fit.
        //
        // Below CONFIRM_BELOW times the floor every look's term is so
        // confirmed: there a noise model that missed a wander (a Markov
        // process of minutes read as flicker) leaves as much above the
        // floor as a term would, and whitened by it the wander gains.
        let marginal = cur.gap_after_dph < CONFIRM_BELOW * cur.noise_floor_dph;
        let capped = cur.noise.capped(cur.grade.value.noise_caps());
        let white = cur.noise.capped((0.0, 0.0, 0.0));
        let mut looks: Vec<(&NoiseModel, bool)> = vec![(&cur.noise, marginal)];
        if capped != cur.noise {
            looks.push((&capped, marginal));
        }
        if white != capped && white != cur.noise {
            looks.push((&white, true));
        }
        let mut accepted = None;
        for (noise, confirm) in looks {
            let rows = Rows::with_noise(&cur, noise);
            let y = rows.dps(&cur.residual_after);
            let fit = fit_columns(given, &cur, inp, &rows, None);
            let p = propose(inp, &y, &fit, &|x| rows.dph(x), &cur.windows, &|xs| {
                rows.windows_dph(xs)
            });
            log.tried = p.tried;
            log.space = p.space;
            log.threshold = p.threshold;
            let Some(pr) = p.proposed else {
                log.note = Some(match log.tried.first() {
                    Some(b) => format!(
                        "no term built from the run's inputs predicts what is left on data it was not fitted on: the best, {} ({}), gains {:.1} noise variances out of sample, below the {} the candidate space's false alarms ask",
                        b.label, b.formula, b.held_out_gain, p.threshold
                    ),
                    None => "the run's inputs give no candidate term".into(),
                });
                continue;
            };
            let mut m2 = m.clone();
            m2.terms.push(pr.term.clone());
            let next = discover_library(&m2, run, opts);
            let (m2, next) = settle(given, m2, next, run, opts, discover_library);
            let (m2, next) = jointly(given, m2, next, (run, opts, discover_library), users);
            // What stood above the floor, and what of it the term closed:
            // a term that predicts a little of a residual it cannot
            // explain (a slow wander the noise model misread) is not the
            // missing effect.
            let floor = cur.noise_floor_dph.min(next.noise_floor_dph);
            let excess = |g: f64| (g * g - floor * floor).max(0.0);
            let closed = 1.0 - excess(next.gap_after_dph) / excess(cur.gap_after_dph).max(1e-300);
            if next.gap_after_dph < cur.gap_after_dph && closed < MIN_CLOSED {
                log.note = Some(format!(
                    "{} ({}) predicted blocks of the record it was not fitted on, but closed only {:.0} % of what stood above the noise floor ({:.4} -> {:.4} deg/h, floor {:.4}), less than the {:.0} % that makes it the missing effect: not added",
                    pr.label,
                    pr.term.formula,
                    100.0 * closed,
                    cur.gap_after_dph,
                    next.gap_after_dph,
                    floor,
                    100.0 * MIN_CLOSED
                ));
                continue;
            }
            if confirm {
                // The likelihood must prefer it with the noise's
                // slow levels free on both sides: a smooth term that takes
                // a wander a random walk explains as well is confirmed by
                // the noise refitted without the walk, but not here.
                let lr = likelihood_gain(&cur, &pr.term, inp).unwrap_or(f64::NAN);
                if lr.is_nan() || lr < p.threshold {
                    log.note = Some(format!(
                        "{} ({}) predicted blocks of the record it was not fitted on, but with the noise's slow levels at their most likely beside it and without it, it raises twice the log-likelihood by {:.1}, below the threshold of {:.1}: a wander the noise explains as well; not added",
                        pr.label, pr.term.formula, lr, p.threshold
                    ));
                    continue;
                }
                // ... and, refitted on blocks whitened by the noise fitted
                // again with it in place, it must predict the others.
                let i = m2.terms.len() - 1;
                let t = &next.model_after.terms[i];
                let gain = refit(given, &next, run, i, &free_params(t, true, inp))
                    .map_or(f64::NAN, |f| f.validation.held_out_gain);
                if gain.is_nan() || gain < p.threshold {
                    log.note = Some(format!(
                        "{} ({}) predicted blocks of the record it was not fitted on, but with the noise fitted again beside it, it predicts them by {:.1} noise variances, below the threshold of {:.1}: the noise's wander, not an effect; not added",
                        pr.label, pr.term.formula, gain, p.threshold
                    ));
                    continue;
                }
            }
            if next.gap_after_dph >= cur.gap_after_dph {
                log.note = Some(format!(
                    "{} ({}) predicted blocks of the record it was not fitted on, but with the library's effects fitted again beside it the gap after did not shrink ({:.4} -> {:.4} deg/h): not added",
                    pr.label,
                    pr.term.formula,
                    cur.gap_after_dph,
                    next.gap_after_dph
                ));
                continue;
            }
            log.note = None;
            accepted = Some((pr, m2, next, closed));
            break;
        }
        let Some((pr, m2, next, closed)) = accepted else {
            break;
        };
        closure.push((cur.gap_after_dph, next.gap_after_dph, closed));
        proposed.push((pr.label.clone(), pr.intervals, pr.validation));
        rivals.push(pr.rival);
        variants.push(pr.variants);
        (m, cur) = (m2, next);
    }
    let mut pruned = vec![];
    if !proposed.is_empty() {
        (cur, pruned) = prune(
            given,
            m,
            cur,
            (run, opts, discover_library),
            users,
            (&mut proposed, &variants),
        );
    }
    // Every term's final values, intervals and validation, beside the
    // effects named with it.
    let mut found = vec![];
    for i in 0..cur.model_after.terms.len() {
        let is_proposed = i >= users;
        let t = cur.model_after.terms[i].clone();
        let free = free_params(&t, is_proposed, inp);
        let fitted = refit(given, &cur, run, i, &free);
        let (label, mut intervals, validation) = if is_proposed {
            let (l, iv, v) = proposed[i - users].clone();
            (l, iv, v)
        } else {
            match &fitted {
                Some(f) => (
                    "written in the model".to_string(),
                    f.intervals.clone(),
                    f.validation.clone(),
                ),
                None => (
                    "written in the model".to_string(),
                    BTreeMap::new(),
                    Validation {
                        folds: 0,
                        held_out_gain: f64::NAN,
                        fold_gains: vec![],
                        threshold: crate::model::proposal::validation::THRESHOLD,
                        held_out_share: f64::NAN,
                    },
                ),
            }
        };
        // A proposed term whose shape was fitted in two parameters (the
        // settling) has its coefficients' intervals from a fit that frees
        // them too: the shape held would leave out what the onset and the
        // time constant leave uncertain.
        let shape_free = t.params.len() - free.len();
        let joint = (is_proposed && shape_free >= 2)
            .then(|| {
                let all: Vec<String> = t.params.keys().cloned().collect();
                refit(given, &cur, run, i, &all)
            })
            .flatten();
        if let Some(f) = &fitted {
            // The coefficients' intervals beside the effects named with
            // the term (the value is the one the model carries).
            for p in &free {
                if let (Some(iv), Some(v)) = (f.intervals.get(p), t.params.get(p)) {
                    let wide = joint
                        .as_ref()
                        .and_then(|j| j.intervals.get(p))
                        .map_or(0.0, |j| 0.5 * (j.1 - j.0));
                    let half = (0.5 * (iv.1 - iv.0)).max(if wide.is_finite() { wide } else { 0.0 });
                    intervals.insert(p.clone(), (v - half, v + half));
                }
            }
        }
        let carried = if !significant(&t, &intervals, inp) {
            Some(format!("not named: {}", NOT_SIGNIFICANT))
        } else if validation.held_out_gain.is_nan()
            || validation.held_out_gain < validation.threshold
        {
            Some(format!(
                "not named: refitted on blocks of the record, it predicts the others by {:.1} noise variances, below the threshold of {}",
                validation.held_out_gain, validation.threshold
            ))
        } else {
            None
        };
        let disguise = if is_proposed {
            disguise(&t, &cur, &implausible, inp)
        } else {
            None
        };
        found.push(TermFound {
            label,
            term: t,
            intervals,
            validation,
            proposed: is_proposed,
            carried,
            disguise,
            closure: is_proposed.then(|| closure[i - users]),
            rival: if is_proposed {
                rivals[i - users].clone()
            } else {
                None
            },
        });
    }
    let mut out = cur;
    out.dropped.extend(pruned);
    out.terms = found;
    out.proposals = log;
    // The gap before, its residual and where it disagreed: the model
    // given's.
    out.gap_before_dph = gap_before;
    out.residual_before = residual_before;
    out.allan_before = allan_before;
    out.disagreements = disagreements;
    out
}
