//! The figures of `gyro-lab bench discover` from its trials' outcomes:
//! single hidden effects named right, with their parameters and the gap;
//! false effects; the nothing-missing, two-hidden and collinear trials; and
//! the confusion table (what was named against what was hidden).

use super::discover_trials::{Outcome, TrialKind};
use crate::model::effects::Effect;
use std::collections::BTreeMap;

/// Hidden effect (or trial kind) -> named effects and the counts.
pub type Confusion = BTreeMap<String, BTreeMap<String, usize>>;

pub struct Summary {
    /// Single-effect trials, and of them: named right, with every
    /// parameter within 10 % too, with the gap shrunk 80 % too.
    pub single: usize,
    pub single_named_right: usize,
    pub single_params_ok: usize,
    pub single_gap_ok: usize,
    /// Trials with drawn effects (all but the collinear ones), and those
    /// naming a false effect.
    pub randomized: usize,
    pub false_effect_named: usize,
    pub nothing_missing_clean: usize,
    pub two_hidden_both_found: usize,
    pub collinear_ambiguous: usize,
    pub confusion: Confusion,
}

fn confusion(outcomes: &[Outcome]) -> Confusion {
    let mut conf: Confusion = BTreeMap::new();
    for o in outcomes {
        let row = if o.hidden.is_empty() {
            o.kind.to_string()
        } else if matches!(o.kind, TrialKind::TwoHidden | TrialKind::Collinear) {
            format!("{} ({})", Effect::names(&o.hidden, " + "), o.kind)
        } else {
            Effect::names(&o.hidden, " + ")
        };
        let r = conf.entry(row).or_default();
        *r.entry("trials".into()).or_default() += 1;
        if o.named.is_empty() && o.ambiguous.is_empty() {
            *r.entry("nothing".into()).or_default() += 1;
        }
        for n in &o.named {
            *r.entry(n.name().into()).or_default() += 1;
        }
        for g in &o.ambiguous {
            *r.entry(format!("ambiguous {}", Effect::names(g, "/")))
                .or_default() += 1;
        }
        if !o.hidden.is_empty() && o.named_right {
            *r.entry("params within 10 %".into()).or_default() += usize::from(o.params_ok);
            *r.entry("gap shrinks 80 %".into()).or_default() += usize::from(o.gap_ok);
        }
    }
    conf
}

pub fn summarize(outcomes: &[Outcome]) -> Summary {
    let count = |kind: &dyn Fn(TrialKind) -> bool, f: &dyn Fn(&Outcome) -> bool| {
        outcomes.iter().filter(|o| kind(o.kind) && f(o)).count()
    };
    let single = |k: TrialKind| matches!(k, TrialKind::Single(_));
    let randomized = |k: TrialKind| k != TrialKind::Collinear;
    Summary {
        single: count(&single, &|_| true),
        single_named_right: count(&single, &|o| o.named_right),
        single_params_ok: count(&single, &|o| o.named_right && o.params_ok),
        single_gap_ok: count(&single, &|o| o.named_right && o.gap_ok),
        randomized: count(&randomized, &|_| true),
        false_effect_named: count(&randomized, &|o| o.false_effect),
        nothing_missing_clean: count(&|k| k == TrialKind::NothingMissing, &|o| o.named.is_empty()),
        two_hidden_both_found: count(&|k| k == TrialKind::TwoHidden, &|o| o.named_right),
        collinear_ambiguous: count(&|k| k == TrialKind::Collinear, &|o| {
            o.ambiguous
                .iter()
                .any(|g| o.hidden.iter().all(|h| g.contains(h)))
        }),
        confusion: confusion(outcomes),
    }
}
