//! Confirmation of the effects named against the noise re-fitted without
//! them (docs/discovery.md).
//!
//! The selection's criterion is taken on the problem whitened by one noise
//! model, and that model is fitted given the selection's own columns. A
//! slow effect then absorbs the slow noise (a random walk, a Markov
//! wander) it imitates: the noise fitted with it reads no random walk, and
//! on that noise the effect pays handsomely. A bias over temperature was
//! named on a table run that held nothing but a random walk, whose noise
//! model, fitted with it, read a twentieth of the random walk there was.
//!
//! So each named effect, each term no effect explains (issue 31: a
//! sinusoid or a step fitted to a random walk is not what the library
//! lacks), and the constant before it is called a bias, must pay against
//! the noise fitted without it: twice the log-likelihood
//! ratio of the fits with and without it, each side with its random walk,
//! flicker and Markov levels re-fitted by maximum likelihood (plain, not
//! restricted: the two sides have different columns), less the BIC's
//! penalty for its parameters, must exceed the selection's
//! [`THRESHOLD`]. An effect that does not is set aside, said so, and the
//! selection run again without it.

use super::design::Design;
use super::likelihood::{profile, Problem};
use super::noise_model::NoiseModel;
use super::select::{corr, Selection, AMBIGUITY_CORR, THRESHOLD};
use super::terms::{without, Kind, Term};

/// Effects set aside at most (then the selection stands as it is).
pub const MAX_SET_ASIDE: usize = 3;

/// What `terms[j]` gains the fit of `terms` once the noise is re-fitted
/// on each side (its random walk, flicker and Markov levels by maximum
/// likelihood, from `noise`): twice the log-likelihood ratio less its BIC
/// penalty (the criterion's decrease, as the selection's delta with the
/// sign turned). The side without the effect may raise its slow noise to
/// imitate it, but pays for a level the rest of the record does not show:
/// a decaying warm-up is not a random walk that happened to fall.
/// `full` is [`loglik`] of `terms`.
pub fn gain(d: &Design, terms: &[Term], j: usize, noise: &NoiseModel, full: f64) -> f64 {
    let rest = without(terms, j);
    2.0 * (full - loglik(d, &rest, noise)) - terms[j].kind.dof() as f64 * d.n().max(2.0).ln()
}

/// The fit of `terms`' log-likelihood, its noise's slow levels re-fitted
/// by maximum likelihood from `noise`.
pub fn loglik(d: &Design, terms: &[Term], noise: &NoiseModel) -> f64 {
    let (cols, y) = d.raw_problem(terms);
    profile(noise, &Problem::new(d.win, &d.wh.keep, &y, &cols), false).1
}

/// The named effect or term no effect explains (a shape, a step, a
/// periodic disturbance) the fit needs least once the noise is re-fitted
/// without it, with its gain, when that gain is below [`THRESHOLD`]. A
/// shape the noise imitates as well is no more a structure in the residual
/// than an effect is: a random walk's wander fitted by a sinusoid, or a
/// flicker's by a step, is not what the library lacks; but a sinusoidal
/// bias a nominal noise cannot make (a random walk of a deg/h/sqrt(h) on
/// a gyro with none) pays hundreds.
pub fn weakest(d: &Design, sel: &Selection, noise: &NoiseModel) -> Option<(Kind, f64)> {
    if sel.named.is_empty() && sel.nuisance.is_empty() {
        return None;
    }
    let terms = sel.terms();
    let full = loglik(d, &terms, noise);
    terms
        .iter()
        .enumerate()
        .filter(|(_, t)| sel.named.iter().any(|s| s.term == **t) || sel.nuisance.contains(t))
        .map(|(j, t)| {
            let g = if t.kind.effect().is_some() {
                effect_gain(d, &terms, j, &sel.nuisance, noise, full)
            } else {
                gain(d, &terms, j, noise, full)
            };
            (t.kind, g)
        })
        .filter(|(_, g)| *g < THRESHOLD)
        .min_by(|a, b| a.1.total_cmp(&b.1))
}

/// What the named effect `terms[j]` gains once the terms no effect
/// explains that stand in for it are left out: a shape whose column
/// follows the effect's (|correlation| at least [`AMBIGUITY_CORR`]) yields
/// to it, as in the forward step. Judged with such a shape beside it, a
/// MEMS gyro's bias over a 28..60 degC warm-up gains nothing over the
/// (T - 20)^2 shape that curves the same way, is set aside, and the shape
/// is left to carry the thermal bias as unexplained (measured hubs,
/// issue 31).
fn effect_gain(
    d: &Design,
    terms: &[Term],
    j: usize,
    nuisance: &[Term],
    noise: &NoiseModel,
    full: f64,
) -> f64 {
    // The first column, centred (the constant is in every fit).
    let first = |t: &Term| {
        let mut c = d.raw(t).cols.into_iter().next()?;
        let m = c.iter().sum::<f64>() / c.len().max(1) as f64;
        c.iter_mut().for_each(|v| *v -= m);
        Some(c)
    };
    let Some(ej) = first(&terms[j]) else {
        return gain(d, terms, j, noise, full);
    };
    let stand_in = |t: &Term| {
        nuisance.contains(t) && first(t).is_some_and(|c| corr(&c, &ej).abs() >= AMBIGUITY_CORR)
    };
    if !terms.iter().any(stand_in) {
        return gain(d, terms, j, noise, full);
    }
    let kept: Vec<Term> = terms.iter().copied().filter(|t| !stand_in(t)).collect();
    let Some(jk) = kept.iter().position(|t| *t == terms[j]) else {
        return gain(d, terms, j, noise, full);
    };
    gain(d, &kept, jk, noise, loglik(d, &kept, noise))
}

/// What the constant gains the final fit once the noise is re-fitted
/// without it.
pub fn constant_gain(d: &Design, sel: &Selection, noise: &NoiseModel) -> f64 {
    let terms = sel.terms();
    debug_assert_eq!(terms[0].kind, Kind::Constant);
    gain(d, &terms, 0, noise, loglik(d, &terms, noise))
}
