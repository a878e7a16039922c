//! Discovery (docs/discovery.md): where a model and the measured data
//! disagree, the named effect that is missing, the model with it added,
//! and the gap shrinking; and, said plainly, what no effect of the library
//! explains. The run flows down, once:
//!
//! 1. The model (gyro_model.rs) is evaluated on the run's inputs; the
//!    residual is measured minus model, averaged over 1 s windows.
//! 2. A first selection (select.rs) with white noise; spikes and steps in
//!    what it leaves (transients.rs); the residual's noise from the Allan
//!    analysis of what it leaves (noise_model.rs); then the selection
//!    again on the problem whitened by that noise (design.rs), until the
//!    names no longer change (at most three passes).
//! 3. Every fit carries a constant (constant.rs says whether it is a
//!    bias); the library's effects (effects.rs) and shapes it has no name
//!    for (terms.rs) compete; implausible fits (ranges.rs) and ambiguous
//!    groups are not named. estimates.rs gives the parameters with
//!    intervals; unexplained.rs what is left.
//! 4. The model with the named and carried effects added, checked never to
//!    explain less than the one it started from.

pub mod centre;
pub mod confirm;
pub mod constant;
pub mod design;
pub mod estimates;
pub mod fit_columns;
pub mod likelihood;
pub mod noise_floor;
pub mod noise_model;
pub mod normal;
pub mod outside;
pub mod projection;
pub mod restart;
pub mod result;
pub mod select;
pub mod terms;
pub mod transients;
pub mod trend;
pub mod unexplained;
pub mod white;
pub mod windows;

use crate::model::effects::Effect;
use crate::model::grade::{Grade, GradeChoice};
use crate::model::gyro_kind::GyroKind;
use crate::model::gyro_model::{Model, ModelEffect};
use crate::model::inputs::Inputs;
use crate::model::ranges::Extent;
use constant::Role;
use design::{inflation, Design};
use estimates::{estimate, Estimate};
use noise_floor::{allan_of, disagreements, expected_gap, gap, noise_floor};
use noise_model::{NoiseModel, Whitener, MIN_COLOUR_WINDOWS};
pub use result::{Carried, Discovery, Options, Run, Skipped, NOT_SIGNIFICANT};
use select::{select, Selection};
use std::collections::BTreeMap;
use terms::{rotating, Kind, Term};
use transients::Transients;
use unexplained::{assess, Sources};
use windows::Windows;

/// The gap's averaging, s.
pub const WINDOW_S: f64 = 1.0;
/// Most windows the fit works on: a longer record is fitted on windows of
/// a whole number of seconds that keep it within this (12 h of 1 s
/// windows), so the selection's cost and memory stop growing with the
/// record; the gap and its floor stay those of 1 s means.
pub const MAX_FIT_WINDOWS: f64 = 43_200.0;

/// The fit's window for a record of `span` s: 1 s, or the whole seconds
/// that keep it within [`MAX_FIT_WINDOWS`].
pub fn fit_window_s(span: f64) -> f64 {
    if span <= MAX_FIT_WINDOWS * WINDOW_S {
        WINDOW_S
    } else {
        (span / MAX_FIT_WINDOWS).ceil() * WINDOW_S
    }
}

/// The noise model of fit windows (`win`) at the gap's windows (`win1`):
/// the white level scaled by the rows they hold (the slower levels are
/// per second already), and which gap windows fall in kept fit windows.
fn at_gap_windows(
    noise: &NoiseModel,
    win: &Windows,
    win1: &Windows,
    keep: &[bool],
) -> (NoiseModel, Vec<bool>) {
    let nominal = |w: &Windows| {
        let mut c = w.count.clone();
        let k = c.len() / 2;
        c.get(k)
            .copied()
            .map_or(1.0, |_| *c.select_nth_unstable_by(k, f64::total_cmp).1)
    };
    let mut m = *noise;
    m.white *= nominal(win) / nominal(win1).max(1e-9);
    // Each gap window kept where the fit window holding its first row is.
    let mut first = vec![usize::MAX; win1.len()];
    for (row, &i) in win1.idx.iter().enumerate() {
        if first[i] == usize::MAX {
            first[i] = row;
        }
    }
    let keep1 = first
        .iter()
        .map(|&row| win.idx.get(row).is_none_or(|&j| keep[j]))
        .collect();
    (m, keep1)
}
/// Smoothing of the disagreement search, s.
pub const SMOOTH_S: f64 = 60.0;
/// Most passes of the selection.
pub const MAX_PASSES: usize = 4;

/// An effect whose addition to the model varies by less than this share
/// of the noise floor (RMS of its 1 s means about their mean), and
/// nowhere by more than [`IMMATERIAL_PEAK_OF_FLOOR`] of it, is carried but
/// not named: a long record makes it significant, but it changes no
/// prediction the run can check (the gap by under half a percent), and
/// what it follows is as likely a sensor's lag or another effect's
/// remainder as a physical effect of its own.
pub const IMMATERIAL_OF_FLOOR: f64 = 0.1;
/// ... and its largest 1 s mean about the mean (an effect seen in one
/// stretch only, lock-in near zero rate, stays named).
pub const IMMATERIAL_PEAK_OF_FLOOR: f64 = 0.25;

/// The least rate, deg/s, a run must reach beyond the Earth rate (0.004
/// deg/s) for lock-in to show: a lock-in rate below it is not an RLG's.
pub const LOCK_IN_MIN_DPS: f64 = 0.01;

/// Measured minus the model's output, deg/s.
fn residual(model: &Model, run: &Run) -> Vec<f64> {
    let sim = model.evaluate(&run.inputs);
    run.rate.iter().zip(&sim).map(|(y, s)| y - s).collect()
}

/// Why the run cannot show `e` (it has its inputs), or None where it can:
/// each effect judged where it shows. A scale factor needs the table to
/// turn; lock-in needs the rate to reach beyond the Earth rate and to
/// change (at one rate it is a constant, a bias), however slowly: a run in
/// the lock-in regime never reaches a scale factor's rates.
fn cannot_show(e: Effect, inp: &Inputs) -> Option<String> {
    if e == Effect::LockIn {
        let (lo, hi) = inp
            .w
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |a, &w| {
                (a.0.min(w.abs()), a.1.max(w.abs()))
            });
        return (hi < LOCK_IN_MIN_DPS || hi - lo < LOCK_IN_MIN_DPS).then(|| {
            format!(
                "the rate never reaches {LOCK_IN_MIN_DPS} deg/s beyond the Earth rate, or never changes: lock-in cannot show"
            )
        });
    }
    (e.needs_rotation() && !rotating(inp)).then(|| {
        format!(
            "the run does not turn (no rate of {} deg/s): a scale factor cannot show at rest",
            terms::ROTATING_DPS
        )
    })
}

/// The library's effects of this gyro the run can show (the bias aside:
/// every fit carries its constant), and those of this gyro it cannot.
fn candidates(gyro: GyroKind, inp: &Inputs) -> (Vec<Effect>, Vec<Skipped>) {
    let mut ok = vec![];
    let mut skipped = vec![];
    for e in Effect::ALL.into_iter().filter(|e| e.applies_to(gyro)) {
        if !e.available(inp) {
            skipped.push(Skipped {
                effect: e,
                missing: e.needs(),
                reason: "the run lacks its inputs".into(),
            });
        } else if let Some(reason) = cannot_show(e, inp) {
            skipped.push(Skipped {
                effect: e,
                missing: &[],
                reason,
            });
        } else if e != Effect::Bias {
            ok.push(e);
        }
    }
    (ok, skipped)
}

/// The run's angle random walk, deg/sqrt(h), from the noise floor of its
/// window means (`floor_dph`, over windows `tau` s apart): the white noise
/// that tells the grade.
pub fn arw_of_floor(floor_dph: f64, tau: f64) -> f64 {
    floor_dph * tau.max(WINDOW_S).sqrt() / 60.0
}

/// What a run covers, and the grade its ranges are judged at.
fn extent(inp: &Inputs, grade: Grade) -> Extent {
    let t0 = inp.t.first().copied().unwrap_or(0.0);
    let t1 = inp.t.last().copied().unwrap_or(0.0);
    let temp_c = inp.temp.as_ref().map(|v| {
        v.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |a, &x| {
            (a.0.min(x), a.1.max(x))
        })
    });
    Extent {
        record_s: (t1 - t0).max(0.0),
        temp_c,
        grade,
    }
}

/// Window means of `r` less every part of `terms` in `d`'s final fit.
fn left(d: &Design, terms: &[Term]) -> Vec<f64> {
    let Some(f) = d.fit(terms) else {
        return d.r.clone();
    };
    let parts = d.parts(terms, &f.coef);
    (0..d.r.len())
        .map(|k| d.r[k] - parts.iter().map(|p| p[k]).sum::<f64>())
        .collect()
}

/// The passes: white noise first, then the noise of what each leaves. On
/// a short record (fewer than [`MIN_COLOUR_WINDOWS`] windows) the window
/// means cannot show their noise: one pass, with the white noise the
/// samples' own scatter measures, and that level the least variance the
/// intervals take.
fn passes<'a>(
    inp: &'a Inputs,
    win: &'a Windows,
    r: &[f64],
    rw: &[f64],
    cands: &[Effect],
    excluded: &[Kind],
    grade: Grade,
) -> (Design<'a>, Selection, NoiseModel, Transients, usize) {
    let n = win.len();
    let x = extent(inp, grade);
    let all = vec![true; n];
    let white = NoiseModel::white_of(rw, &all);
    if n < MIN_COLOUR_WINDOWS {
        let noise = NoiseModel::white_of_samples(r, win).unwrap_or(white);
        let mut d = Design::new(
            inp,
            win,
            x,
            rw.to_vec(),
            Whitener::new(&noise, win, &all),
            vec![],
        );
        d.min_scale = 1.0;
        let sel = select(&d, cands, excluded);
        return (d, sel, noise, Transients::default(), 1);
    }
    let d1 = Design::new(
        inp,
        win,
        x,
        rw.to_vec(),
        Whitener::new(&white, win, &all),
        vec![],
    );
    let sel1 = select(&d1, cands, excluded);
    let e1 = left(&d1, &sel1.terms());
    let tr = transients::find(win, &e1);
    let keep = tr.keep(n);
    let tau0 = if n > 1 {
        (win.t[n - 1] - win.t[0]) / (n - 1) as f64
    } else {
        WINDOW_S
    };
    let noise_a = NoiseModel::from_residual(&e1, &keep, tau0);
    let design =
        |noise: &NoiseModel| d1.renoised(Whitener::new(noise, win, &keep), tr.steps.clone());
    let d2 = design(&noise_a);
    let sel2 = select(&d2, cands, excluded);
    // The noise's slow levels by maximum likelihood given what the second
    // pass selected, then the selection again on that noise (weighing the
    // criterion by the correlation its whitened residual still holds);
    // once more if the noise and the names still moved.
    let ml = |d: &Design, sel: &Selection, start: &NoiseModel| {
        let (cols, y) = d.raw_problem(&sel.terms());
        likelihood::refine(start, &likelihood::Problem::new(win, &keep, &y, &cols))
    };
    let mut noise = ml(&d2, &sel2, &noise_a);
    let mut names = sel2.named_effects();
    let mut prev = sel2.terms();
    let mut pass = 2;
    loop {
        pass += 1;
        let mut d = design(&noise);
        d.phi = d.fit(&prev).map_or(1.0, |f| inflation(&f.resid, &keep));
        let sel = select(&d, cands, excluded);
        let now = sel.named_effects();
        if now == names || pass >= MAX_PASSES {
            return (d, sel, noise, tr, pass);
        }
        names = now;
        prev = sel.terms();
        noise = ml(&d, &sel, &noise);
    }
}

/// What a short record's intervals rest on, said plainly (None for a
/// record long enough to measure its noise's colour).
fn short_record(d: &Design, sel: &Selection) -> Option<String> {
    let n = d.win.len();
    if n >= MIN_COLOUR_WINDOWS {
        return None;
    }
    let p: usize = sel.terms().iter().map(|t| t.kind.dof()).sum();
    let dof = n.saturating_sub(p);
    Some(format!(
        "the record has {n} windows of {WINDOW_S} s, fewer than the {MIN_COLOUR_WINDOWS} its noise's colour is measured from: the intervals are unreliable (they assume white noise, at least the level its samples' scatter shows, with Student's t on {dof} degree{} of freedom, and cannot see slower noise); record longer for intervals to rely on",
        if dof == 1 { "" } else { "s" }
    ))
}

/// The intervals widened for the slow noise the record cannot exclude:
/// the flicker and the random walk the restricted likelihood still allows
/// at 95 % (likelihood.rs's `slow_bounds`), each in turn, the final terms
/// refitted on the problem whitened by it. A slow level fitted as nothing
/// (white noise hides a bias instability at every averaging time the Allan
/// curve measures well) otherwise leaves a slow regressor's interval
/// that of white noise.
fn allow_slow_noise(
    d: &Design,
    terms: &[Term],
    noise: &NoiseModel,
    bounds: &[NoiseModel],
    fin: &mut estimates::Final,
) {
    for up in bounds.iter().copied() {
        if up == *noise {
            continue;
        }
        let mut du = d.renoised(Whitener::new(&up, d.win, &d.wh.keep), d.steps.clone());
        du.phi = d.phi;
        if let Some(f) = estimate(&du, terms) {
            estimates::widen(fin, &f);
        }
    }
}

/// Whether `e`'s 95 % interval holds zero: every linear parameter's, or,
/// for an effect with none (lock-in), its non-linear one's; an interval
/// the record cannot give (NaN) holds it too.
pub fn holds_zero(e: &Estimate) -> bool {
    let lin = e.effect.linear_params();
    let holds = |p: &(&str, f64, f64, f64)| !(p.2 > 0.0 || p.3 < 0.0);
    if lin.is_empty() {
        return e.params.iter().all(holds);
    }
    e.params.iter().filter(|p| lin.contains(&p.0)).all(holds)
}

/// A model effect from an estimate's values.
fn model_effect(e: &Estimate) -> ModelEffect {
    ModelEffect {
        effect: e.effect,
        params: e
            .params
            .iter()
            .map(|p| (p.0.to_owned(), p.1))
            .collect::<BTreeMap<String, f64>>(),
    }
}

/// RMS and largest magnitude of what `e` adds to `model` on `run` (whose
/// residual is `base`), its 1 s means about their mean (a constant offset
/// is the bias's), deg/h.
fn varying_dph(model: &Model, run: &Run, base: &[f64], win: &Windows, e: &Estimate) -> (f64, f64) {
    let added = residual(&with(model, &[e]), run);
    let diff: Vec<f64> = base.iter().zip(&added).map(|(a, b)| a - b).collect();
    let m = win.mean(&diff);
    let n = m.len().max(1) as f64;
    let mean = m.iter().sum::<f64>() / n;
    let rms = (m.iter().map(|v| (v - mean) * (v - mean)).sum::<f64>() / n).sqrt();
    let peak = m.iter().map(|v| (v - mean).abs()).fold(0.0, f64::max);
    (rms * 3600.0, peak * 3600.0)
}

/// `model` with `add` appended.
fn with(model: &Model, add: &[&Estimate]) -> Model {
    let mut m = model.clone();
    m.effects.extend(add.iter().map(|e| model_effect(e)));
    m
}

/// Least squares of the window means on the written terms alone (no
/// whitening, no nuisance): never worse than no term, by construction.
fn plain_refit(d: &Design, written: &[(Term, Estimate)]) -> Vec<Estimate> {
    let mut y = d.r.clone();
    let mut cols = vec![];
    for (t, _) in written {
        let raw = d.raw(t);
        if let Some(o) = raw.offset {
            for (a, b) in y.iter_mut().zip(o) {
                *a -= b;
            }
        }
        cols.extend(raw.cols);
    }
    let coef = if cols.is_empty() {
        Some(vec![])
    } else {
        crate::numerics::lsq::wls(&cols, &y, None).map(|f| f.coef)
    };
    let Some(coef) = coef else {
        return vec![];
    };
    let mut col = 0;
    written
        .iter()
        .map(|(t, e)| {
            let mut e = e.clone();
            for p in e.params.iter_mut() {
                if t.kind == Kind::Effect(Effect::LockIn) || Some(p.0) == e.effect.nonlinear_param()
                {
                    continue;
                }
                // The value re-fitted; its interval keeps the joint fit's
                // width (which allows for the unexplained terms), about it.
                let v = coef.get(col).copied().unwrap_or(p.1);
                let shift = v - p.1;
                p.1 = v;
                p.2 += shift;
                p.3 += shift;
                col += 1;
            }
            e
        })
        .collect()
}

/// The median spacing of the windows' mid times, s.
fn window_spacing(win: &Windows) -> f64 {
    let mut d: Vec<f64> = win.t.windows(2).map(|p| p[1] - p[0]).collect();
    if d.is_empty() {
        return WINDOW_S;
    }
    d.sort_by(f64::total_cmp);
    d[d.len() / 2]
}

/// What `model` misses of `run`: the effects found, the terms outside the
/// library (a user's fitted, one proposed where the library leaves the
/// residual unexplained), the model with them added, the residual before
/// and after, and what stays unexplained.
pub fn discover(model: &Model, run: &Run, opts: &Options) -> Discovery {
    // Every library run the search compares is centred as the model
    // written will be: a constant fitted under a random walk sits where the
    // noise wanders at the record's ends, and its offset, counted in the
    // gap, hides what a term closes (a measured chamber sweep's cubic
    // closed 5 % of the excess uncentred, 62 % centred).
    let library =
        |m: &Model, r: &Run, o: &Options| centre::centre(r, discover_library(m, r, o), WINDOW_S);
    let whole = |o: &Options| {
        let first = library(model, run, o);
        let warm = restart::names_warm_up(model, &first);
        let d = centre::centre(
            run,
            outside::beyond(model, run, o, first, &library),
            WINDOW_S,
        );
        (d, warm)
    };
    let (main, warm) = whole(opts);
    if !warm || !restart::worth_another(&main) {
        return main;
    }
    let (alt, _) = whole(&restart::without_warm_up(opts));
    restart::better(model, main, alt)
}

/// [`discover`] with the library's effects alone (the model's terms held
/// as given).
pub fn discover_library(model: &Model, run: &Run, opts: &Options) -> Discovery {
    let inp = &run.inputs;
    let r = residual(model, run);
    let win1 = Windows::new(&inp.t, WINDOW_S);
    let span = inp.t.last().copied().unwrap_or(0.0) - inp.t.first().copied().unwrap_or(0.0);
    let win = match fit_window_s(span) {
        w if w > WINDOW_S => Windows::new(&inp.t, w),
        _ => Windows::new(&inp.t, WINDOW_S),
    };
    let rw = win.mean(&r);
    let allan_before = allan_of(&inp.t, &r);
    let floor = noise_floor(&win1, allan_before.as_ref(), &inp.t, &r, WINDOW_S);
    let grade = match opts.grade {
        Some(g) => GradeChoice::given(g),
        None => GradeChoice::inferred(arw_of_floor(floor, window_spacing(&win1))),
    };
    let disagreements = disagreements(&inp.t, &r, allan_before.as_ref(), SMOOTH_S);
    let (mut cands, skipped) = candidates(model.gyro, inp);
    cands.retain(|e| !opts.excludes(*e));
    // The selection, run again without any named effect or unexplained
    // term the fit does not need once its noise is re-fitted without it
    // (confirm.rs).
    let mut not_confirmed: Vec<(Kind, f64)> = vec![];
    let (d, sel, noise, tr, passes) = loop {
        let now: Vec<Effect> = cands
            .iter()
            .copied()
            .filter(|e| !not_confirmed.iter().any(|x| x.0 == Kind::Effect(*e)))
            .collect();
        let excluded: Vec<Kind> = not_confirmed
            .iter()
            .map(|x| x.0)
            .filter(|k| k.effect().is_none())
            .collect();
        let out = passes(inp, &win, &r, &rw, &now, &excluded, grade.value);
        if out.0.win.len() < MIN_COLOUR_WINDOWS || not_confirmed.len() >= confirm::MAX_SET_ASIDE {
            break out;
        }
        match confirm::weakest(&out.0, &out.1, &out.2) {
            Some(w) => not_confirmed.push(w),
            None => break out,
        }
    };
    let short = short_record(&d, &sel);
    let (mut role, amb_const, _) = constant::role(&d, &sel, &cands);
    if role == Role::Named && short.is_none() {
        let g = confirm::constant_gain(&d, &sel, &noise);
        if g < select::THRESHOLD {
            // Not named a bias (the noise's slow wander imitates it), but
            // carried: the level the noise wanders about, which the gap
            // and its floor are taken from (a MEMS gyro's turn-on bias of
            // hundreds of deg/h is one a flicker of tens can imitate).
            not_confirmed.push((Kind::Constant, g));
            role = Role::Carried;
        }
    }
    let terms = sel.terms();
    let mut fin = estimate(&d, &terms);
    // The slow noise the record cannot exclude at 95 % (likelihood.rs's
    // slow_bounds): it widens the intervals, and it bounds the floor the
    // gap after is judged against.
    let bounds = if short.is_none() {
        let (cols, y) = d.raw_problem(&terms);
        likelihood::slow_bounds(
            &noise,
            &likelihood::Problem::new(&win, &d.wh.keep, &y, &cols),
        )
    } else {
        vec![]
    };
    if let Some(f) = fin.as_mut() {
        allow_slow_noise(&d, &terms, &noise, &bounds, f);
    }
    let est = |j: usize| -> Option<Estimate> {
        fin.as_ref()
            .and_then(|f| f.estimates.get(j).cloned().flatten())
    };
    let nn = sel.named.len();
    let nc = sel.carried.len();
    // The model written: the constant (unless nothing needs it), the named
    // effects, the ambiguous groups' representatives.
    let mut written: Vec<(Term, Estimate, Option<String>)> = vec![];
    if role != Role::Unneeded {
        if let Some(e) = est(0) {
            let why = match role {
                Role::Named if holds_zero(&e) => Some(format!(
                    "the constant the other terms are fitted with (not named a bias: {NOT_SIGNIFICANT})"
                )),
                Role::Named => None,
                Role::Ambiguous => Some("the constant, for the ambiguous group it heads".into()),
                _ if not_confirmed.iter().any(|x| x.0 == Kind::Constant) => Some(
                    "the level the noise wanders about (not named a bias: once the noise is re-fitted without it, it gains less than the threshold)"
                        .into(),
                ),
                _ => Some(
                    "the constant the other terms are fitted with (no bias of its own: removing it, or letting a warm-up settle to nothing, costs less than the threshold)"
                        .into(),
                ),
            };
            written.push((terms[0], e, why));
        }
    }
    for j in 1..=nn {
        if let Some(e) = est(j) {
            let why = holds_zero(&e).then(|| format!("not named: {NOT_SIGNIFICANT}"));
            written.push((terms[j], e, why));
        }
    }
    for j in nn + 1..=nn + nc {
        if let Some(e) = est(j) {
            written.push((
                terms[j],
                e,
                Some("the simplest of an ambiguous group, carried for it".into()),
            ));
        }
    }
    let gap_before = gap(&win1, &r);
    let build = |w: &[(Term, Estimate, Option<String>)]| {
        let m = with(model, &w.iter().map(|x| &x.1).collect::<Vec<_>>());
        let ra = residual(&m, run);
        let g = gap(&win1, &ra);
        (m, ra, g)
    };
    let (mut model_after, mut r_after, mut gap_after) = build(&written);
    let mut fallback = None;
    // The named effects' values from the joint fit with the terms no
    // effect explains are what the effects are where those terms are what
    // the record holds; but where those terms took a shape the effects
    // follow too (a drift linear in time on a hub warming as steadily,
    // issue 31's measured records), the effects written on their own
    // leave more than twice what they leave re-fitted alone: then the
    // model written is re-fitted on its own effects.
    if gap_after <= gap_before && written.len() > 1 && !sel.nuisance.is_empty() {
        let pairs: Vec<(Term, Estimate)> = written.iter().map(|x| (x.0, x.1.clone())).collect();
        let refit = plain_refit(&d, &pairs);
        if refit.len() == written.len() {
            let mut alt = written.clone();
            for (w, e) in alt.iter_mut().zip(refit) {
                w.1 = e;
            }
            let (m, ra, g) = build(&alt);
            if g < 0.5 * gap_after {
                fallback = Some(format!(
                    "the effects as fitted beside the unexplained terms left {gap_after:.4} deg/h, more than twice the {g:.4} they leave re-fitted on their own (the unexplained terms took part of what they follow): the model written was re-fitted on its own effects"
                ));
                (written, model_after, r_after, gap_after) = (alt, m, ra, g);
            }
        }
    }
    if gap_after > gap_before {
        let pairs: Vec<(Term, Estimate)> = written.iter().map(|x| (x.0, x.1.clone())).collect();
        let refit = plain_refit(&d, &pairs);
        if refit.len() == written.len() {
            for (w, e) in written.iter_mut().zip(refit) {
                w.1 = e;
            }
        } else {
            written.clear();
        }
        (model_after, r_after, gap_after) = build(&written);
        if gap_after > gap_before {
            written.clear();
            (model_after, r_after, gap_after) = build(&written);
        }
        fallback = Some(format!(
            "the joint fit with the unexplained terms would have widened the gap ({gap_before:.4} deg/h before); the model written was re-fitted on its own effects"
        ));
    }
    let mut found = vec![];
    let mut carried = vec![];
    for (_, e, why) in written {
        // Named only where the interval, as written (after any re-fit),
        // excludes zero.
        let why = match why {
            None if holds_zero(&e) => Some(if e.effect == Effect::Bias {
                format!("the constant the other terms are fitted with (not named a bias: {NOT_SIGNIFICANT})")
            } else {
                format!("not named: {NOT_SIGNIFICANT}")
            }),
            None if e.effect != Effect::Bias => {
                let (size, peak) = varying_dph(model, run, &r, &win1, &e);
                (size < IMMATERIAL_OF_FLOOR * floor && peak < IMMATERIAL_PEAK_OF_FLOOR * floor)
                    .then(|| {
                    format!(
                        "not named: what it adds to the model varies by {size:.4} deg/h RMS (at most {peak:.4}), under {IMMATERIAL_OF_FLOOR} ({IMMATERIAL_PEAK_OF_FLOOR}) of the noise floor ({floor:.4} deg/h): significant over this record, but too small to change what the run can check"
                    )
                })
            }
            w => w,
        };
        match why {
            None => found.push(e),
            Some(w) => carried.push(Carried {
                estimate: e,
                why: w,
            }),
        }
    }
    let mut ambiguous = sel.ambiguous.clone();
    ambiguous.extend(amb_const);
    let whitened = d.fit(&terms).map(|f| f.resid).unwrap_or_default();
    let after_w = win.mean(&r_after);
    let parts: Vec<(&[f64], String)> = match &fin {
        Some(f) => (nn + nc + 1..terms.len())
            .map(|j| (f.parts[j].as_slice(), terms[j].describe()))
            .collect(),
        None => vec![],
    };
    let mut unexplained = assess(
        &d,
        &noise,
        &Sources {
            parts,
            spikes: &tr.spikes,
            whitened: &whitened,
            scale: fin.as_ref().map_or(1.0, |f| f.scale),
            after: &after_w,
        },
    );
    // What is unexplained is part of the residual after: never more than
    // the gap after (the shapes' parts of a joint fit the model written
    // fell back from can cancel each other by thousands of deg/h).
    if let Some(u) = unexplained.as_mut() {
        if gap_after.is_finite() {
            u.excess_dph = u.excess_dph.min(gap_after);
        }
    }
    // The floor: what the noise alone leaves in the gap, its slow levels
    // at most those of a gyro of this grade; and above it by more than
    // its uncertainty (the slow levels at their 95 % bounds, three of its
    // standard deviations) the gap after is unexplained, whatever the
    // noise model swallowed.
    let caps = grade.value.noise_caps();
    let keep = &d.wh.keep;
    let (noise1, keep1) = at_gap_windows(&noise, &win, &win1, keep);
    let (floor2, _) = expected_gap(&noise1.capped(caps), &win1, &keep1);
    let hi2 = std::iter::once(&noise)
        .chain(&bounds)
        .map(|m| {
            let (m1, _) = at_gap_windows(m, &win, &win1, keep);
            let (m2, v2) = expected_gap(&m1.capped(caps), &win1, &keep1);
            m2 + 3.0 * v2.sqrt()
        })
        .fold(0.0, f64::max);
    let noise_floor_dph = if short.is_none() {
        floor2.sqrt() * 3600.0
    } else {
        floor
    };
    let floor_hi_dph = hi2.sqrt() * 3600.0;
    if short.is_none() && unexplained.is_none() && gap_after > floor_hi_dph {
        let fitted = (
            noise.random_walk.sqrt() * 216_000.0,
            noise.flicker.sqrt() * 3600.0,
        );
        let why = format!(
            "the gap after the model, {gap_after:.4} deg/h, stands above what the noise of a {} gyro can leave ({noise_floor_dph:.4} deg/h, at most {floor_hi_dph:.4}); the noise fitted to it reads a random walk of {} deg/h/sqrt(h) and a bias instability of {} deg/h",
            grade.value,
            crate::report::text::sig(fitted.0),
            crate::report::text::sig(fitted.1)
        );
        let excess = (gap_after.powi(2) - noise_floor_dph.powi(2))
            .max(0.0)
            .sqrt();
        unexplained = Some(unexplained::beyond_floor(&d, &noise, &after_w, excess, why));
    }
    // What a function of the inputs explains that the noise model took
    // as its own (trend.rs): said, not absorbed.
    if short.is_none() && unexplained.is_none() {
        if let Some(tr) = trend::input_trend(inp, &win, &after_w, &d.wh.keep) {
            let slow = (
                noise.random_walk.sqrt() * 216_000.0,
                noise.flicker.sqrt() * 3600.0,
            );
            unexplained = Some(tr.unexplained(&win, slow));
        }
    }
    let allan_after = allan_of(&inp.t, &r_after);
    let keep = d.wh.keep.clone();
    drop(d);
    Discovery {
        gyro: model.gyro,
        grade,
        found,
        carried,
        ambiguous,
        implausible: sel.implausible.clone(),
        unexplained,
        dropped: sel.dropped.iter().map(|k| k.describe()).collect(),
        not_confirmed,
        skipped,
        gap_before_dph: gap_before,
        gap_after_dph: gap_after,
        noise_floor_dph,
        noise_floor_hi_dph: floor_hi_dph,
        noise_floor_white_dph: floor,
        noise,
        passes,
        fallback,
        short,
        disagreements,
        residual_before: r,
        residual_after: r_after,
        windows: win,
        gap_windows: win1,
        model_after,
        allan_before,
        allan_after,
        keep,
        terms: vec![],
        proposals: Default::default(),
        residual_mean_dph: f64::NAN,
        residual_mean_sd_dph: f64::NAN,
        centred_by_dph: 0.0,
    }
}
