//! Which fit a run takes, and whether a run can be calibrated at all.

use super::continuous::fit_continuous;
use super::input::{rotating, SfInput, MIN_SPAN_C};
use super::multipoint::{fit_multipoint, plateaus, Plateau};
use super::result::{SfFit, SfFitError};

/// Rotating rows a scale factor needs.
pub const MIN_ROTATING_ROWS: usize = 30;

/// Why a run cannot calibrate a scale factor over temperature.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum RunCheck {
    /// Too few rotating rows (this many).
    NoRotation(usize),
    /// The rotating rows' temperature span, degC, under [`MIN_SPAN_C`].
    Span(f64),
}

/// A run checked before the fit: rotation present, a temperature span the
/// model can use (over the rotating rows of the coil sensor `temp_c`).
pub fn check_run(w: &[f64], temp_c: &[f64]) -> Result<(), RunCheck> {
    let rot = rotating(w);
    if rot.len() < MIN_ROTATING_ROWS {
        return Err(RunCheck::NoRotation(rot.len()));
    }
    let (lo, hi) = rot
        .iter()
        .map(|&k| temp_c[k])
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| {
            (a.min(x), b.max(x))
        });
    if hi - lo < MIN_SPAN_C {
        return Err(RunCheck::Span(hi - lo));
    }
    Ok(())
}

/// Fits either kind of run: a multi-point run where the rotating rows fall
/// on temperature plateaus (then with its plateaus), else a continuous one.
pub fn fit(inp: &SfInput) -> Result<(SfFit, Option<Vec<Plateau>>), SfFitError> {
    let rot = rotating(&inp.w);
    match plateaus(inp, &rot) {
        Some(groups) => fit_multipoint(inp, &groups).map(|(f, p)| (f, Some(p))),
        None => fit_continuous(inp).map(|f| (f, None)),
    }
}
