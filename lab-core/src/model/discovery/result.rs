//! What a discovery gives: the run it reads, the options, and the
//! discovery itself (the effects found and carried, the terms outside the
//! library, the residual before and after, what is left). Apart from the
//! passes that make it (mod.rs) and the terms beyond the library
//! (outside.rs), which both build it.

use super::estimates::Estimate;
use super::noise_floor::Disagreement;
use super::noise_model::NoiseModel;
use super::select::{Ambiguous, Implausible};
use super::terms::Kind;
use super::unexplained::Unexplained;
use super::windows::Windows;
use crate::data::run_file::Column;
use crate::model::effects::Effect;
use crate::model::grade::{Grade, GradeChoice};
use crate::model::gyro_kind::GyroKind;
use crate::model::gyro_model::Model;
use crate::model::inputs::Inputs;
use crate::model::proposal::{Tried, Validation};
use crate::model::term::Term;
use crate::noise::analysis::Allan;
use std::collections::BTreeMap;

/// A run's inputs and measured rate (deg/s).
pub struct Run {
    pub inputs: Inputs,
    pub rate: Vec<f64>,
}

/// What the user sets.
#[derive(Clone, Copy, Debug, Default)]
pub struct Options {
    /// The gyro's grade (`--grade`); judged from the run's white noise
    /// when None.
    pub grade: Option<Grade>,
    /// Effects the library is not to offer (a bit per `Effect as u32`):
    /// the discovery's own, when it asks whether a name beside a proposed
    /// term pays its way (outside.rs).
    pub exclude: u64,
}

impl Options {
    /// The grade given, nothing excluded.
    pub fn with_grade(grade: Option<Grade>) -> Self {
        Self { grade, exclude: 0 }
    }

    pub fn excludes(&self, e: crate::model::effects::Effect) -> bool {
        self.exclude & (1u64 << e as u32) != 0
    }

    /// These options with `e` excluded too.
    pub fn excluding(self, e: crate::model::effects::Effect) -> Self {
        Self {
            exclude: self.exclude | (1u64 << e as u32),
            ..self
        }
    }
}

/// An effect of the library the run cannot show, and why.
#[derive(Clone, Debug)]
pub struct Skipped {
    pub effect: Effect,
    /// The columns it needs that the run lacks (empty: another reason).
    pub missing: &'static [Column],
    pub reason: String,
}

/// An effect carried in the model without being named, and why.
#[derive(Clone, Debug)]
pub struct Carried {
    pub estimate: Estimate,
    pub why: String,
}

pub struct Discovery {
    pub gyro: GyroKind,
    pub grade: GradeChoice,
    /// Named effects, in the order they came in (a bias first).
    pub found: Vec<Estimate>,
    pub carried: Vec<Carried>,
    pub ambiguous: Vec<Ambiguous>,
    pub implausible: Vec<Implausible>,
    pub unexplained: Option<Unexplained>,
    /// Effects the backward steps removed after they came in.
    pub dropped: Vec<String>,
    /// Effects, terms no effect explains, and the constant (as
    /// `Kind::Constant`) that paid on the selection's noise but not once
    /// the noise was re-fitted without them (confirm.rs), with what they
    /// gained then (below the threshold).
    pub not_confirmed: Vec<(Kind, f64)>,
    pub skipped: Vec<Skipped>,
    pub residual_before: Vec<f64>,
    pub residual_after: Vec<f64>,
    /// The fit's windows (1 s, or longer on a long record: mod.rs's
    /// `fit_window_s`), and the gap's (1 s).
    pub windows: Windows,
    pub gap_windows: Windows,
    pub gap_before_dph: f64,
    pub gap_after_dph: f64,
    /// The gap the noise alone leaves (noise_floor.rs's `expected_gap`,
    /// slow levels capped at the grade's), its upper bound (slow levels at
    /// their 95 % bounds, three standard deviations), and the white floor
    /// of 1 s means the first pass starts from, deg/h.
    pub noise_floor_dph: f64,
    pub noise_floor_hi_dph: f64,
    pub noise_floor_white_dph: f64,
    pub noise: NoiseModel,
    pub passes: usize,
    /// Set when the joint fit's parameters would have widened the gap and
    /// the model written was re-fitted without the unexplained terms.
    pub fallback: Option<String>,
    /// Set on a record too short for its intervals (fewer than
    /// [`MIN_COLOUR_WINDOWS`] windows): why they are not to be relied on.
    pub short: Option<String>,
    pub disagreements: Vec<Disagreement>,
    pub model_after: Model,
    pub allan_before: Option<Allan>,
    pub allan_after: Option<Allan>,
    /// The windows the final fit used (transients left out).
    pub keep: Vec<bool>,
    /// The model's terms outside the library (outside.rs): a user's,
    /// fitted, and those proposed.
    pub terms: Vec<TermFound>,
    pub proposals: Proposals,
    /// The mean of the residual after the model over the record, deg/h,
    /// and its standard deviation from the stationary part of the noise
    /// (centre.rs), and how far the model's constant was moved for it.
    pub residual_mean_dph: f64,
    pub residual_mean_sd_dph: f64,
    pub centred_by_dph: f64,
}

/// Why an effect whose interval holds zero is carried, not named.
pub const NOT_SIGNIFICANT: &str =
    "its 95 % interval holds zero (or the record gives it none), so the data do not show it";

/// A term of the model written that is not a library effect.
#[derive(Clone, Debug)]
pub struct TermFound {
    /// What a gyro engineer would call it ("written in the model" for a
    /// user's own).
    pub label: String,
    pub term: Term,
    /// 95 % intervals of its parameters.
    pub intervals: BTreeMap<String, (f64, f64)>,
    pub validation: Validation,
    /// Proposed by discover; false: written in the model given.
    pub proposed: bool,
    /// Why it is carried and not named (None: named).
    pub carried: Option<String>,
    /// The library effect whose shape it is, with what keeps that effect
    /// from being named.
    pub disguise: Option<String>,
    /// A proposed term's effect on the gap after: without it, with it
    /// (deg/h), and the share of the excess over the floor it closed.
    pub closure: Option<(f64, f64, f64)>,
    /// A proposed shape of time alone: the candidate built from the run's
    /// inputs that predicted as much of the record (proposal/mod.rs).
    pub rival: Option<Tried>,
}

impl TermFound {
    /// What a shape of time alone could not be told from, said plainly.
    pub fn rival_text(&self) -> Option<String> {
        self.rival.as_ref().map(|r| format!(
            "{} is a shape of time alone: {} ({}) predicts this record as well (held-out gain {:.1}, within the scatter of the term's); a shape of time carries to no other run, so a second run (--validate) tells them apart",
            self.term.formula, r.label, r.formula, r.held_out_gain
        ))
    }
}

/// What the proposal tried on the run (the last attempt), and why it
/// stopped where it did.
#[derive(Clone, Debug, Default)]
pub struct Proposals {
    pub tried: Vec<Tried>,
    pub note: Option<String>,
    /// The candidate columns searched and the held-out gain they had to
    /// pass (0 where no proposal was searched).
    pub space: usize,
    pub threshold: f64,
}
