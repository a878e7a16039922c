//! The calibrations' reports (`fit scale-factor`, `fit thermal`, `lockin`,
//! `compensate`), each on the lab's one report writer (report/): a verdict
//! paragraph first (what was fitted, from how much data, how good the fit
//! is against its noise, the warnings), then the plots and tables a person
//! checks a fit by. The CLI writes them beside its output file.

pub mod compensate;
pub mod lockin;
pub mod scale_factor;
pub mod thermal;

use crate::calibration::warning::Warning;
use crate::report::verdict::Verdict;

/// At most this many points per plotted series.
pub const MAX_POINTS: usize = 2000;

/// How a figure compares with its noise floor, in words.
pub fn against_floor(ratio: f64) -> &'static str {
    if !ratio.is_finite() {
        "(no noise floor could be estimated)"
    } else if ratio <= 1.3 {
        "at the noise floor"
    } else if ratio <= 2.0 {
        "somewhat above the noise floor"
    } else {
        "well above the noise floor"
    }
}

/// The warnings at the end of a verdict, or that there are none.
pub fn warnings(v: &mut Verdict, ws: &[Warning]) {
    if ws.is_empty() {
        v.text(" No warnings.");
    }
    for w in ws {
        v.warning(&w.kind, &w.message);
    }
}
