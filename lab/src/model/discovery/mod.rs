//! Discovery (docs/discovery.md): where a model and the measured data
//! disagree, the named effect that is missing, the model with it added,
//! and the gap shrinking. The run flows down, once:
//!
//! 1. The model (gyro_model.rs) is evaluated on the run's inputs; the
//!    residual is measured minus model.
//! 2. The noise floor comes from the residual itself (noise_floor.rs), and
//!    the stretches where the residual, smoothed over 60 s, stands out.
//! 3. Every applicable effect of the library (effects.rs) is a candidate;
//!    select.rs chooses among them by BIC on the windowed problem of
//!    design.rs, names ambiguous groups; estimates.rs gives the
//!    parameters with intervals.
//! 4. The model with the found effects added, and its residual.

pub mod design;
pub mod estimates;
pub mod noise_floor;
pub mod select;
pub mod windows;

use crate::data::run_file::Column;
use crate::model::effects::Effect;
use crate::model::gyro_kind::GyroKind;
use crate::model::gyro_model::{Model, ModelEffect};
use crate::model::inputs::Inputs;
use crate::noise::analysis::Allan;
use design::{Design, Term};
use estimates::{estimates, Estimate};
use noise_floor::{allan_of, disagreements, gap, noise_floor, Disagreement};
use select::{select, Selection};
use std::collections::BTreeMap;
use windows::Windows;

/// The gap's averaging, s.
pub const WINDOW_S: f64 = 1.0;
/// Smoothing of the disagreement search, s.
pub const SMOOTH_S: f64 = 60.0;

/// A run's inputs and measured rate (deg/s).
pub struct Run {
    pub inputs: Inputs,
    pub rate: Vec<f64>,
}

pub struct Discovery {
    pub gyro: GyroKind,
    pub found: Vec<Estimate>,
    pub selection: Selection,
    /// Effects of the library the run lacks the inputs for, with the
    /// columns missing.
    pub skipped: Vec<(Effect, &'static [Column])>,
    pub residual_before: Vec<f64>,
    pub residual_after: Vec<f64>,
    pub windows: Windows,
    pub gap_before_dph: f64,
    pub gap_after_dph: f64,
    pub noise_floor_dph: f64,
    pub disagreements: Vec<Disagreement>,
    pub model_after: Model,
    pub allan_before: Option<Allan>,
    pub allan_after: Option<Allan>,
}

/// Measured minus the model's output, deg/s.
fn residual(model: &Model, run: &Run) -> Vec<f64> {
    let sim = model.evaluate(&run.inputs);
    run.rate.iter().zip(&sim).map(|(y, s)| y - s).collect()
}

/// The library's effects of this gyro the run can show, and those it
/// lacks the inputs for.
type Candidates = (Vec<Effect>, Vec<(Effect, &'static [Column])>);

fn candidates(gyro: GyroKind, inp: &Inputs) -> Candidates {
    let of_gyro = || Effect::ALL.into_iter().filter(move |e| e.applies_to(gyro));
    (
        of_gyro().filter(|e| e.available(inp)).collect(),
        of_gyro()
            .filter(|e| !e.available(inp))
            .map(|e| (e, e.needs()))
            .collect(),
    )
}

/// Two passes: the residual correlation of the first selection sets the
/// variance inflation of the second.
fn select_twice(design: &Design, candidates: &[Effect]) -> Selection {
    let first = select(design, candidates, 1.0);
    let terms: Vec<Term> = first.terms();
    let phi = design.inflation(&terms);
    select(design, candidates, phi)
}

/// `model` with the effects found added.
fn with_found(model: &Model, found: &[Estimate]) -> Model {
    let mut after = model.clone();
    for e in found {
        let params: BTreeMap<String, f64> =
            e.params.iter().map(|p| (p.0.to_owned(), p.1)).collect();
        after.effects.push(ModelEffect {
            effect: e.effect,
            params,
        });
    }
    after
}

/// What `model` misses of `run`: the effects found, the model with them
/// added, and the residual before and after.
pub fn discover(model: &Model, run: &Run) -> Discovery {
    let inp = &run.inputs;
    let r = residual(model, run);
    let win = Windows::new(&inp.t, WINDOW_S);
    let allan_before = allan_of(&inp.t, &r);
    let floor = noise_floor(&win, allan_before.as_ref(), &inp.t, &r, WINDOW_S);
    let disagreements = disagreements(&inp.t, &r, allan_before.as_ref(), SMOOTH_S);
    let (candidates, skipped) = candidates(model.gyro, inp);
    let design = Design {
        inp,
        win: &win,
        r: win.mean(&r),
    };
    let selection = select_twice(&design, &candidates);
    let found = estimates(&design, &selection);
    let model_after = with_found(model, &found);
    let r_after = residual(&model_after, run);
    let allan_after = allan_of(&inp.t, &r_after);
    Discovery {
        gyro: model.gyro,
        found,
        selection,
        skipped,
        gap_before_dph: gap(&win, &r),
        gap_after_dph: gap(&win, &r_after),
        noise_floor_dph: floor,
        disagreements,
        residual_before: r,
        residual_after: r_after,
        windows: win,
        model_after,
        allan_before,
        allan_after,
    }
}
