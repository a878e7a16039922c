//! `residual.csv` of `discover` (docs/interfaces.md): the residual
//! (measured minus model, deg/s) before and after the found effects.

use super::csv_writer::{CellFormat, CsvWriter};
use super::run_file::Column;
use crate::error::LabError;
use std::path::Path;

/// The columns of residual.csv (time is the run file's).
pub const COLUMNS: [(&str, CellFormat); 3] = [
    (Column::Time.name(), CellFormat::Shortest),
    ("residual_before_dps", CellFormat::Shortest),
    ("residual_after_dps", CellFormat::Shortest),
];

pub fn write(path: &Path, t: &[f64], before: &[f64], after: &[f64]) -> Result<(), LabError> {
    let mut w = CsvWriter::create(path, "", &COLUMNS)?;
    for k in 0..t.len() {
        w.row(&[t[k], before[k], after[k]])?;
    }
    w.finish()
}
