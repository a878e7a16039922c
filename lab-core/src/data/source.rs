//! Where a table comes from: a data file, or columns a caller holds in
//! memory (a notebook's arrays, read where they lie). Both go through the
//! same readers and the same checks (table.rs); an error is placed in
//! either: the file, line and field, or the caller's name for the
//! columns, the row and the column.

use crate::error::{ColumnRef, LabError};
use std::borrow::Cow;
use std::path::{Path, PathBuf};

/// A table's source.
#[derive(Clone, Copy)]
pub enum Source<'a> {
    File(&'a Path),
    Columns(&'a Columns<'a>),
}

impl<'a> Source<'a> {
    /// Where the source's errors are placed.
    pub fn origin(&self) -> Origin {
        match self {
            Source::File(p) => Origin::File(p.to_path_buf()),
            Source::Columns(c) => Origin::Memory(c.label.clone()),
        }
    }

    /// The source as a user names it: the path, or the caller's name.
    pub fn name(&self) -> String {
        match self {
            Source::File(p) => p.display().to_string(),
            Source::Columns(c) => c.label.clone(),
        }
    }

    /// The file, where the source is one.
    pub fn path(&self) -> Option<&'a Path> {
        match self {
            Source::File(p) => Some(p),
            Source::Columns(_) => None,
        }
    }
}

/// Named columns of equal length held by the caller: borrowed where they
/// are already numbers of f64, owned where they had to be converted.
pub struct Columns<'a> {
    /// What the caller calls them (`run`, `fringe`): errors start with it.
    pub label: String,
    pub names: Vec<String>,
    pub values: Vec<Cow<'a, [f64]>>,
}

impl<'a> Columns<'a> {
    pub fn new(label: impl Into<String>) -> Self {
        Self {
            label: label.into(),
            names: vec![],
            values: vec![],
        }
    }

    /// Adds a column: its length must be the first column's, and its name
    /// new.
    pub fn push(&mut self, name: &str, values: Cow<'a, [f64]>) -> Result<(), LabError> {
        let origin = Origin::Memory(self.label.clone());
        if self.names.iter().any(|n| n == name) {
            return Err(origin.column(0, 0, name, "the column is given twice"));
        }
        if let (Some(first), Some(v)) = (self.names.first(), self.values.first()) {
            if v.len() != values.len() {
                return Err(origin.column(
                    0,
                    0,
                    name,
                    format!(
                        "{} rows where `{first}` has {}: every column needs one value per row",
                        values.len(),
                        v.len()
                    ),
                ));
            }
        }
        self.names.push(name.to_owned());
        self.values.push(values);
        Ok(())
    }

    /// The number of rows.
    pub fn len(&self) -> usize {
        self.values.first().map_or(0, |v| v.len())
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// A column by the caller's name.
    pub fn get(&self, name: &str) -> Option<&[f64]> {
        let i = self.names.iter().position(|n| n == name)?;
        Some(&self.values[i])
    }
}

/// Where a table's errors are placed.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Origin {
    /// A file: `file:line:field (column `name`)`.
    File(PathBuf),
    /// Columns in memory, by the caller's name for them: `run: row 17
    /// (column `gyro_z`)`, rows counted from 0.
    Memory(String),
}

impl Default for Origin {
    fn default() -> Self {
        Origin::File(PathBuf::new())
    }
}

impl Origin {
    /// An error about the source as a whole.
    pub fn whole(&self, msg: impl Into<String>) -> LabError {
        match self {
            Origin::File(p) => LabError::input(p, msg),
            Origin::Memory(w) => LabError::Memory {
                what: w.clone(),
                row: None,
                column: None,
                msg: msg.into(),
            },
        }
    }

    /// An error about the header (the column names): at its line in a
    /// file.
    pub fn header(&self, header_line: u64, msg: impl Into<String>) -> LabError {
        match self {
            Origin::File(p) => LabError::at_line(p, header_line, msg),
            Origin::Memory(_) => self.whole(msg),
        }
    }

    /// An error at one cell: a file's line and 1-based field, or the
    /// row in memory; `name` as the source names the column.
    pub fn cell(
        &self,
        line_or_row: u64,
        field: usize,
        name: &str,
        msg: impl Into<String>,
    ) -> LabError {
        match self {
            Origin::File(p) => LabError::at(
                p,
                line_or_row,
                ColumnRef {
                    index: field,
                    name: Some(name.to_owned()),
                },
                msg,
            ),
            Origin::Memory(w) => LabError::Memory {
                what: w.clone(),
                row: Some(line_or_row),
                column: Some(name.to_owned()),
                msg: msg.into(),
            },
        }
    }

    /// An error about a column as a whole: at its header cell in a file.
    pub fn column(
        &self,
        header_line: u64,
        field: usize,
        name: &str,
        msg: impl Into<String>,
    ) -> LabError {
        match self {
            Origin::File(_) => self.cell(header_line, field, name, msg),
            Origin::Memory(w) => LabError::Memory {
                what: w.clone(),
                row: None,
                column: Some(name.to_owned()),
                msg: msg.into(),
            },
        }
    }

    /// The path, for a file.
    pub fn path(&self) -> Option<&Path> {
        match self {
            Origin::File(p) => Some(p),
            Origin::Memory(_) => None,
        }
    }
}

impl std::fmt::Display for Origin {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Origin::File(p) => write!(f, "{}", p.display()),
            Origin::Memory(w) => f.write_str(w),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn columns_of_unequal_length_are_refused_with_both_named() {
        let mut c = Columns::new("run");
        c.push("time", Cow::Owned(vec![0.0, 1.0, 2.0])).unwrap();
        let e = c
            .push("gyro_z", Cow::Owned(vec![0.0, 1.0]))
            .unwrap_err()
            .to_string();
        assert_eq!(
            e,
            "run (column `gyro_z`): 2 rows where `time` has 3: every column needs one value per row"
        );
        assert!(c.push("time", Cow::Owned(vec![0.0; 3])).is_err());
    }

    #[test]
    fn memory_errors_name_the_row_and_column() {
        let o = Origin::Memory("run".into());
        assert_eq!(
            o.cell(4, 2, "gyro_z", "empty").to_string(),
            "run: row 4 (column `gyro_z`): empty"
        );
        assert_eq!(o.header(1, "missing").to_string(), "run: missing");
        let f = Origin::File("a.csv".into());
        assert_eq!(
            f.cell(5, 2, "gyro_z", "empty").to_string(),
            "a.csv:5:2 (column `gyro_z`): empty"
        );
    }
}
