//! The fringe file (docs/interfaces.md "Fringe file"): an RLG photodiode
//! record, `t_s`, `signal` and optionally `signal_q`, the second photodiode
//! in quadrature.

use super::csv_writer::{CellFormat, CsvWriter};
use super::read_spec::ReadSpec;
use super::run_file::Column;
use super::source::Source;
use super::table::TextTable;
use crate::error::LabError;
use std::path::Path;

/// The fringe file's columns (time is the run file's).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FringeColumn {
    Time,
    /// One photodiode.
    Signal,
    /// The photodiode in quadrature.
    SignalQ,
}

impl FringeColumn {
    pub const fn name(self) -> &'static str {
        match self {
            FringeColumn::Time => Column::Time.name(),
            FringeColumn::Signal => "signal",
            FringeColumn::SignalQ => "signal_q",
        }
    }
}

pub struct FringeFile {
    pub t_s: Vec<f64>,
    pub signal: Vec<f64>,
    pub signal_q: Option<Vec<f64>>,
}

impl FringeFile {
    /// Reads a fringe file of at least `min_rows` rows (in the stretch
    /// asked for), time increasing, its columns mapped by `spec`.
    pub fn read(source: Source, spec: &ReadSpec, min_rows: usize) -> Result<Self, LabError> {
        for (ours, _) in &spec.rename {
            let names = [
                FringeColumn::Time,
                FringeColumn::Signal,
                FringeColumn::SignalQ,
            ]
            .map(FringeColumn::name);
            if !names.contains(&ours.as_str()) {
                return Err(LabError::Usage(format!(
                    "--columns: `{ours}` is not a fringe-file column ({})",
                    names.join(", ")
                )));
            }
        }
        let table = TextTable::read_source(source, spec, Some(FringeColumn::Time.name()), None)?;
        table.require(&[FringeColumn::Time.name(), FringeColumn::Signal.name()])?;
        Ok(Self {
            t_s: table.time(FringeColumn::Time.name(), min_rows)?,
            signal: table.column(FringeColumn::Signal.name())?,
            signal_q: table.column_opt(FringeColumn::SignalQ.name())?,
        })
    }
}

/// A fringe file written row by row (the quadrature channel when asked).
pub struct FringeWriter(CsvWriter);

impl FringeWriter {
    pub fn create(path: &Path, comment: &str, quadrature: bool) -> Result<Self, LabError> {
        let mut cols = vec![
            (FringeColumn::Time.name(), CellFormat::Fixed(8)),
            (FringeColumn::Signal.name(), CellFormat::Exp(6)),
        ];
        if quadrature {
            cols.push((FringeColumn::SignalQ.name(), CellFormat::Exp(6)));
        }
        CsvWriter::create(path, comment, &cols).map(Self)
    }

    /// One row: time, signal and, when written, the quadrature signal.
    pub fn row(&mut self, values: &[f64]) -> Result<(), LabError> {
        self.0.row(values)
    }

    pub fn finish(self) -> Result<(), LabError> {
        self.0.finish()
    }
}
