//! The figures of `gyro-lab bench discover` from its trials' outcomes: per
//! category the trials right, the false names, the gap growing and the
//! interval coverage; and the confusion table (what was named, reported
//! ambiguous or unexplained, against what was hidden).

use super::discover_trials::{Outcome, TrialKind};
use crate::model::effects::Effect;
use std::collections::BTreeMap;

/// Row (what was hidden) -> column (what was said) -> count.
pub type Confusion = BTreeMap<String, BTreeMap<String, usize>>;

/// A category's or the whole bench's figures.
#[derive(Clone, Debug, Default, serde::Serialize)]
pub struct Tally {
    pub trials: usize,
    pub right: usize,
    pub false_names: usize,
    pub gap_grew: usize,
    pub unexplained: usize,
    pub covered: usize,
    pub intervals: usize,
    /// Of the trials with an effect hidden and named right: every
    /// parameter within 10 %, and the gap to reality shrunk 80 %.
    pub named_right_with_truth: usize,
    pub params_ok: usize,
    pub gap_ok: usize,
}

impl Tally {
    fn add(&mut self, o: &Outcome) {
        self.trials += 1;
        self.right += usize::from(o.right);
        self.false_names += o.false_names;
        self.gap_grew += usize::from(o.gap_grew);
        self.unexplained += usize::from(o.unexplained);
        self.covered += o.covered;
        self.intervals += o.intervals;
        if o.right && !o.expect.is_empty() && !o.named.is_empty() {
            self.named_right_with_truth += 1;
            self.params_ok += usize::from(o.params_ok);
            self.gap_ok += usize::from(o.gap_ok);
        }
    }

    /// Interval coverage, percent.
    pub fn coverage_pct(&self) -> f64 {
        100.0 * self.covered as f64 / self.intervals.max(1) as f64
    }
}

/// Issue 32's figures: terms outside the library proposed where they are
/// missing, and nowhere else.
#[derive(Clone, Debug, Default, serde::Serialize)]
pub struct Beyond {
    pub physical: usize,
    pub physical_explained: usize,
    pub events: usize,
    pub events_explained: usize,
    /// Outside trials explained with library effects named beside (or
    /// instead of) a term: the hidden shape spans them.
    pub explained_with_library_names: usize,
    /// Outside trials whose model written predicts a second run.
    pub second_runs: usize,
    pub second_runs_predicted: usize,
    /// Nulls (nothing missing, coloured noise) with any term named.
    pub nulls: usize,
    pub nulls_with_term: usize,
    /// Trials hiding library effects with any term named.
    pub library: usize,
    pub library_with_term: usize,
}

fn beyond(outcomes: &[Outcome]) -> Beyond {
    let mut b = Beyond::default();
    for o in outcomes {
        match o.kind {
            TrialKind::Outside(x) => {
                if x.is_event() {
                    b.events += 1;
                    b.events_explained += usize::from(o.right);
                } else {
                    b.physical += 1;
                    b.physical_explained += usize::from(o.right);
                }
                b.explained_with_library_names += usize::from(o.right && !o.named.is_empty());
                if let Some(p) = o.predicts_b {
                    b.second_runs += 1;
                    b.second_runs_predicted += usize::from(p);
                }
            }
            TrialKind::NothingMissing | TrialKind::ColouredNull => {
                b.nulls += 1;
                b.nulls_with_term += usize::from(o.terms > 0);
            }
            _ => {
                b.library += 1;
                b.library_with_term += usize::from(o.terms > 0);
            }
        }
    }
    b
}

pub struct Summary {
    pub beyond: Beyond,
    pub total: Tally,
    /// Per category (the trial kinds, single effects together).
    pub categories: BTreeMap<String, Tally>,
    pub confusion: Confusion,
}

/// The category a trial counts in.
pub fn category(k: TrialKind) -> String {
    match k {
        TrialKind::Single(_) => "single effect".into(),
        TrialKind::BiasThermal(_) => "bias + thermal term (RLG chamber)".into(),
        TrialKind::Outside(_) => "outside the library".into(),
        TrialKind::Weak(_) => "weak (1.5 x floor)".into(),
        k => k.to_string(),
    }
}

fn confusion(outcomes: &[Outcome]) -> Confusion {
    let mut conf: Confusion = BTreeMap::new();
    for o in outcomes {
        let row = match o.kind {
            TrialKind::Single(_) => Effect::names(&o.expect, " + "),
            TrialKind::TwoHidden | TrialKind::Collinear => {
                format!("{} ({})", Effect::names(&o.expect, " + "), o.kind)
            }
            k => k.to_string(),
        };
        let r = conf.entry(row).or_default();
        *r.entry("trials".into()).or_default() += 1;
        *r.entry("right".into()).or_default() += usize::from(o.right);
        if o.named.is_empty() && o.ambiguous.is_empty() {
            *r.entry("nothing named".into()).or_default() += 1;
        }
        for n in &o.named {
            *r.entry(n.name().into()).or_default() += 1;
        }
        for g in &o.ambiguous {
            *r.entry(format!("ambiguous {}", Effect::names(g, "/")))
                .or_default() += 1;
        }
        if o.unexplained {
            *r.entry("unexplained".into()).or_default() += 1;
        }
        if o.terms > 0 {
            *r.entry("term".into()).or_default() += 1;
        }
        if o.gap_grew {
            *r.entry("gap grew".into()).or_default() += 1;
        }
    }
    conf
}

pub fn summarize(outcomes: &[Outcome]) -> Summary {
    let mut total = Tally::default();
    let mut categories: BTreeMap<String, Tally> = BTreeMap::new();
    for o in outcomes {
        total.add(o);
        categories.entry(category(o.kind)).or_default().add(o);
    }
    Summary {
        beyond: beyond(outcomes),
        total,
        categories,
        confusion: confusion(outcomes),
    }
}
