//! Writing numeric CSV files row by row: `#` comment lines, the header, then
//! one row per call, each column with its own number format. Rows are
//! streamed (a long simulation's run file is never held whole). The file
//! kinds give the column names; this module knows none. The file appears
//! under its name only at [`CsvWriter::finish`] (atomic.rs).

use super::atomic::AtomicFile;
use crate::error::LabError;
use std::io::Write;
use std::path::{Path, PathBuf};

/// How a column's numbers are written.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CellFormat {
    /// `{:.N}`: N decimals.
    Fixed(usize),
    /// `{:.Ne}`: N decimals of the mantissa.
    Exp(usize),
    /// `{}`: the shortest text that reads back as the same number.
    Shortest,
}

pub struct CsvWriter {
    w: AtomicFile,
    path: PathBuf,
    formats: Vec<CellFormat>,
}

impl CsvWriter {
    /// Creates `path` with `comment` (each line as `# line`) and the header.
    pub fn create(
        path: &Path,
        comment: &str,
        columns: &[(&str, CellFormat)],
    ) -> Result<Self, LabError> {
        let io = |e: std::io::Error| LabError::io(path, e);
        let mut w = AtomicFile::create(path)?;
        for l in comment.lines() {
            writeln!(w, "# {l}").map_err(io)?;
        }
        let names: Vec<&str> = columns.iter().map(|c| c.0).collect();
        writeln!(w, "{}", names.join(",")).map_err(io)?;
        Ok(Self {
            w,
            path: path.to_owned(),
            formats: columns.iter().map(|c| c.1).collect(),
        })
    }

    /// One row, a value per column.
    pub fn row(&mut self, values: &[f64]) -> Result<(), LabError> {
        self.write_row(values)
            .map_err(|e| LabError::io(&self.path, e))
    }

    fn write_row(&mut self, values: &[f64]) -> std::io::Result<()> {
        for (k, (v, f)) in values.iter().zip(&self.formats).enumerate() {
            if k > 0 {
                self.w.write_all(b",")?;
            }
            match *f {
                CellFormat::Fixed(p) => write!(self.w, "{v:.p$}")?,
                CellFormat::Exp(p) => write!(self.w, "{v:.p$e}")?,
                CellFormat::Shortest => write!(self.w, "{v}")?,
            }
        }
        self.w.write_all(b"\n")
    }

    pub fn finish(self) -> Result<(), LabError> {
        self.w.commit()
    }
}
