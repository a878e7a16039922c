//! What `compensate` is asked, and what it did.

use super::coeffs::CoeffSet;
use crate::data::read_spec::ReadSpec;
use crate::data::run_file::{Column, RunText};
use crate::data::source::Source;
use crate::report::document::Report;

/// What `compensate` is asked.
pub struct Request<'a> {
    pub coeffs: &'a CoeffSet,
    /// The coefficient set and the run as the user names them.
    pub coeffs_name: &'a str,
    pub source: Source<'a>,
    pub spec: &'a ReadSpec,
    /// A run to fit the classic cubic on, for comparison (RLG thermal).
    pub cubic_from: Option<Source<'a>>,
    /// Whether to make the report.
    pub report: bool,
}

/// What `compensate` did.
pub struct CompensateOutcome<'a> {
    /// The run as read.
    pub run: RunText<'a>,
    /// The compensated rate, deg/s, a value per row.
    pub comp_dps: Vec<f64>,
    pub json: serde_json::Value,
    pub text: Vec<String>,
    pub report: Option<Report>,
    /// The first comment line of the run written back.
    pub comment: String,
}

impl CompensateOutcome<'_> {
    /// The run as read with `rate_comp_dps` added, as a run file's text.
    pub fn run_text(&self) -> String {
        self.run
            .text_with(&self.comment, &[(Column::CompensatedRate, &self.comp_dps)])
    }
}
