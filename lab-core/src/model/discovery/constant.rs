//! The constant every fit carries, and whether it is a bias.
//!
//! It is named `bias` when the fit cannot do without it: removing it costs
//! more than the threshold, and (with a warm-up in the fit) so does
//! letting the warm-up settle to nothing instead, A exp(-t/tau) in place of
//! c + A (1 - exp(-t/tau)): a gyro that warms up from a turn-on offset to
//! no bias has no bias to name, though its model carries the constant.
//! When an effect of the library can stand in for it (a scale-factor error
//! at one constant rate, rectification at one vibration level), the two
//! are ambiguous: the constant is carried as the bias, the simplest, and
//! not named. Otherwise it is carried unnamed whenever anything else is in
//! the model, and left out when nothing is.

use super::design::Design;
use super::select::{
    corr, params_of, separation, Ambiguous, Selection, AMBIGUITY_CORR, AMBIGUITY_MARGIN, THRESHOLD,
};
use super::terms::{Kind, Term};
use crate::model::effects::Effect;
use crate::model::ranges;

/// What the constant is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Role {
    /// A bias, named.
    Named,
    /// Carried for an ambiguous group (reported there).
    Ambiguous,
    /// Carried unnamed: the other terms need it.
    Carried,
    /// Nothing in the model: left out.
    Unneeded,
}

/// The constant's role in the final fit of `sel`, with the ambiguity it
/// makes; `candidates` are the library's effects the run can show, their
/// removal cost in the criterion.
pub fn role(d: &Design, sel: &Selection, candidates: &[Effect]) -> (Role, Option<Ambiguous>, f64) {
    let terms = sel.terms();
    let c_full = d.criterion_of(&terms);
    let without: Vec<Term> = terms[1..].to_vec();
    let cost = d.criterion_of(&without) - c_full;
    let decay_cost = terms
        .iter()
        .position(|t| t.kind == Kind::Effect(Effect::WarmUp))
        .map(|j| {
            let mut ts = without.clone();
            ts[j - 1] = Term {
                kind: Kind::Decay,
                x: terms[j].x,
            };
            d.criterion_of(&ts) - c_full
        });
    let needed = cost > THRESHOLD && decay_cost.is_none_or(|c| c > THRESHOLD);
    let anything = !(sel.named.is_empty() && sel.carried.is_empty() && sel.nuisance.is_empty());
    if !needed {
        let r = if anything {
            Role::Carried
        } else {
            Role::Unneeded
        };
        return (r, None, cost);
    }
    // Effects that could stand in for the constant.
    let (Some(f0), Some(f_full)) = (d.fit(&without), d.fit(&terms)) else {
        return (Role::Named, None, cost);
    };
    let explained: Vec<f64> = f0
        .resid
        .iter()
        .zip(&f_full.resid)
        .map(|(a, b)| a - b)
        .collect();
    let mut group = vec![(Effect::Bias, 1.0, -cost)];
    for &e in candidates {
        if terms.iter().any(|t| t.kind == Kind::Effect(e))
            || sel.ambiguous.iter().any(|g| g.effects.contains(&e))
        {
            continue;
        }
        let mut ts = without.clone();
        ts.push(Term::of(Kind::Effect(e)));
        let j = ts.len() - 1;
        d.optimize(&mut ts, j);
        let Some(f) = d.fit(&ts) else {
            continue;
        };
        let dof: usize = ts.iter().map(|t| t.kind.dof()).sum();
        let delta = d.criterion(f.sse, dof) - c_full;
        if delta > AMBIGUITY_MARGIN {
            continue;
        }
        let p = params_of(&ts, &f, j);
        if !ranges::outside(e, &p, &d.extent).is_empty() {
            continue;
        }
        // A warm-up that settles within a twentieth of the record is the
        // constant after its first minutes: the simpler, one-parameter
        // bias is what the record shows, not an ambiguity a longer record
        // would resolve.
        if e == Effect::WarmUp && ts[j].x < d.extent.record_s / 20.0 {
            continue;
        }
        let ex: Vec<f64> = f0.resid.iter().zip(&f.resid).map(|(a, b)| a - b).collect();
        let c = corr(&explained, &ex);
        if c.abs() >= AMBIGUITY_CORR {
            group.push((e, c, delta - cost));
        }
    }
    if group.len() == 1 {
        return (Role::Named, None, cost);
    }
    let amb = Ambiguous {
        effects: group.iter().map(|g| g.0).collect(),
        correlation: group.iter().map(|g| g.1).collect(),
        delta_bic: group.iter().map(|g| g.2).collect(),
        suggestion: separation(group[0].0, group[1].0),
        carried_as: Effect::Bias,
    };
    (Role::Ambiguous, Some(amb), cost)
}
