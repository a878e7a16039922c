//! Reading CSV data files by column name: CSV, one header row, `#` comment
//! lines before it. Every row must have as many cells as the header: a row
//! with one more or one less would shift or drop a column, and the answer
//! would change without a word. Every cell a caller uses is checked: a
//! missing column (at the header's own line), a cell that is not a finite
//! number, time that does not increase or too few rows give an error at
//! `file:line:column` (column = 1-based field number, then its name). The
//! file kinds (run_file.rs, fringe_file.rs) name the columns; this module
//! knows none.
//!
//! Two readers: [`TextTable`] keeps the file as text cells (unused columns
//! are written back as read) and checks column by column; [`ColumnStream`]
//! reads long records in one pass without the text and checks row by row.

use crate::error::{ColumnRef, LabError};
use std::path::{Path, PathBuf};

/// The physical range of a column's values, looked up by its name (the
/// file kinds know their columns; this module knows none): `(lo, hi,
/// what)`, `what` naming the range in the error.
pub type Bounds = fn(&str) -> Option<(f64, f64, &'static str)>;

/// What is wrong with a cell that should hold a number.
enum CellError<'a> {
    NotFinite(&'a str),
    Empty,
    NotANumber(&'a str),
    OutOfRange(&'a str, &'static str),
}

impl std::fmt::Display for CellError<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            CellError::NotFinite(c) => write!(f, "`{c}` is not a finite number"),
            CellError::Empty => f.write_str("empty cell"),
            CellError::NotANumber(c) => write!(f, "cannot read `{c}` as a number"),
            CellError::OutOfRange(c, what) => write!(f, "`{c}` is outside {what}"),
        }
    }
}

/// A cell as a finite number, within `range` where the column has one.
fn number<'a>(
    cell: &'a str,
    range: Option<(f64, f64, &'static str)>,
) -> Result<f64, CellError<'a>> {
    match cell.parse::<f64>() {
        Ok(v) if v.is_finite() => match range {
            Some((lo, hi, what)) if !(lo..=hi).contains(&v) => {
                Err(CellError::OutOfRange(cell, what))
            }
            _ => Ok(v),
        },
        Ok(_) => Err(CellError::NotFinite(cell)),
        Err(_) if cell.is_empty() => Err(CellError::Empty),
        Err(_) => Err(CellError::NotANumber(cell)),
    }
}

/// A row whose cell count differs from the header's, at its line and the
/// first cell too many (or the first missing).
fn width_error(path: &Path, line: u64, cells: usize, header: usize) -> LabError {
    LabError::at(
        path,
        line,
        ColumnRef {
            index: cells.min(header) + 1,
            name: None,
        },
        format!(
            "{cells} cells where the header has {header}: a cell {} shifts the columns after it",
            if cells > header {
                "too many"
            } else {
                "missing"
            }
        ),
    )
}

/// Comment and blank lines before the header: their count and byte length.
fn leading_comments(text: &[u8]) -> (u64, usize) {
    let (mut lines, mut offset) = (0u64, 0usize);
    for line in text.split_inclusive(|&b| b == b'\n') {
        let t = line.trim_ascii();
        if t.starts_with(b"#") || t.is_empty() {
            lines += 1;
            offset += line.len();
        } else {
            break;
        }
    }
    (lines, offset)
}

fn column_ref(field: usize, name: &str) -> ColumnRef {
    ColumnRef {
        index: field,
        name: Some(name.to_owned()),
    }
}

/// A data file held as text cells, with the line number of every row.
pub struct TextTable {
    pub path: PathBuf,
    pub header: Vec<String>,
    header_line: u64,
    rows: Vec<(u64, Vec<String>)>,
    bounds: Option<Bounds>,
}

impl TextTable {
    pub fn read(path: &Path) -> Result<Self, LabError> {
        Self::read_bounded(path, None)
    }

    /// Reads, checking every numeric column's cells against `bounds`.
    pub fn read_bounded(path: &Path, bounds: Option<Bounds>) -> Result<Self, LabError> {
        let text = std::fs::read_to_string(path)
            .map_err(|e| LabError::input(path, format!("cannot read: {e}")))?;
        // Comment lines before the header are skipped by hand so that line
        // numbers stay those of the file.
        let (skipped, offset) = leading_comments(text.as_bytes());
        let mut rdr = csv::ReaderBuilder::new()
            .has_headers(false)
            .flexible(true)
            .trim(csv::Trim::All)
            .from_reader(&text.as_bytes()[offset..]);
        let mut records = rdr.records();
        let header: Vec<String> = match records.next() {
            Some(Ok(r)) => r.iter().map(str::to_owned).collect(),
            Some(Err(e)) => return Err(LabError::input(path, e.to_string())),
            None => return Err(LabError::input(path, "no header row")),
        };
        let header_line = skipped + 1;
        let mut rows = Vec::new();
        for rec in records {
            let rec = rec.map_err(|e| {
                let line = e.position().map_or(0, |p| p.line() + skipped);
                LabError::at_line(path, line, e.to_string())
            })?;
            let line = rec.position().map_or(0, |p| p.line()) + skipped;
            if rec.iter().all(str::is_empty) {
                continue;
            }
            if rec.len() != header.len() {
                return Err(width_error(path, line, rec.len(), header.len()));
            }
            rows.push((line, rec.iter().map(str::to_owned).collect()));
        }
        Ok(Self {
            path: path.to_owned(),
            header,
            header_line,
            rows,
            bounds,
        })
    }

    pub fn len(&self) -> usize {
        self.rows.len()
    }

    pub fn is_empty(&self) -> bool {
        self.rows.is_empty()
    }

    pub fn has(&self, col: &str) -> bool {
        self.header.iter().any(|h| h == col)
    }

    fn index(&self, col: &str) -> Result<usize, LabError> {
        self.header.iter().position(|h| h == col).ok_or_else(|| {
            LabError::at_line(
                &self.path,
                self.header_line,
                format!("missing column `{col}`"),
            )
        })
    }

    /// An error about column `col` as a whole, placed at its header cell.
    pub fn column_error(&self, col: &str, msg: impl Into<String>) -> LabError {
        let i = self
            .header
            .iter()
            .position(|h| h == col)
            .map_or(0, |i| i + 1);
        LabError::at(&self.path, self.header_line, column_ref(i, col), msg)
    }

    /// A numeric column: every cell a finite number.
    pub fn column(&self, col: &str) -> Result<Vec<f64>, LabError> {
        let i = self.index(col)?;
        let range = self.bounds.and_then(|b| b(col));
        self.rows
            .iter()
            .map(|(line, cells)| {
                let cell = cells.get(i).map(String::as_str).unwrap_or("");
                number(cell, range).map_err(|m| {
                    LabError::at(&self.path, *line, column_ref(i + 1, col), m.to_string())
                })
            })
            .collect()
    }

    /// An optional numeric column.
    pub fn column_opt(&self, col: &str) -> Result<Option<Vec<f64>>, LabError> {
        if self.has(col) {
            self.column(col).map(Some)
        } else {
            Ok(None)
        }
    }

    /// The time column `col`, strictly increasing, with at least `min_rows`
    /// rows.
    pub fn time(&self, col: &str, min_rows: usize) -> Result<Vec<f64>, LabError> {
        if self.rows.len() < min_rows {
            return Err(LabError::input(
                &self.path,
                format!("{} data rows, at least {min_rows} needed", self.rows.len()),
            ));
        }
        let t = self.column(col)?;
        let i = self.index(col)?;
        for k in 1..t.len() {
            if t[k] <= t[k - 1] {
                return Err(LabError::at(
                    &self.path,
                    self.rows[k].0,
                    column_ref(i + 1, col),
                    format!("time {} does not increase (previous {})", t[k], t[k - 1]),
                ));
            }
        }
        Ok(t)
    }

    /// Writes the table back with extra numeric columns appended.
    pub fn write_with(&self, out: &Path, extra: &[(&str, &[f64])]) -> Result<(), LabError> {
        let io = |e: csv::Error| LabError::io(out, e);
        let mut w = csv::Writer::from_path(out).map_err(io)?;
        let mut head = self.header.clone();
        head.extend(extra.iter().map(|(n, _)| n.to_string()));
        w.write_record(&head).map_err(io)?;
        for (k, (_, cells)) in self.rows.iter().enumerate() {
            let mut rec = cells.clone();
            rec.extend(extra.iter().map(|(_, v)| format!("{:.9}", v[k])));
            w.write_record(&rec).map_err(io)?;
        }
        w.flush().map_err(|e| LabError::io(out, e))
    }
}

/// Numeric columns of a long record, read in one pass without keeping the
/// text (a 10^7-row run file as a [`TextTable`] would be gigabytes of
/// strings). The same checks and messages as [`TextTable`]: a missing
/// column, an empty or non-numeric cell, NaN or infinity give
/// `file:line:column`.
pub struct ColumnStream {
    pub path: PathBuf,
    pub header_line: u64,
    /// One vector per requested column, in the order asked.
    pub data: Vec<Vec<f64>>,
    /// The requested columns' names, in the order of `data`.
    pub names: Vec<String>,
    /// File line of every row.
    pub lines: Vec<u64>,
    /// 1-based field number of every requested column.
    pub fields: Vec<usize>,
}

/// Consumes the comment and blank lines before the header; returns their
/// count.
fn skip_leading_comments(r: &mut impl std::io::BufRead) -> std::io::Result<u64> {
    let mut n = 0;
    loop {
        let buf = r.fill_buf()?;
        if buf.is_empty() {
            return Ok(n);
        }
        let first = buf.iter().find(|b| !matches!(b, b' ' | b'\t' | b'\r'));
        if first.is_some_and(|&b| b != b'#' && b != b'\n') {
            return Ok(n);
        }
        let mut line = Vec::new();
        r.read_until(b'\n', &mut line)?;
        n += 1;
    }
}

impl ColumnStream {
    pub fn read(path: &Path, cols: &[&str]) -> Result<Self, LabError> {
        Self::read_with(path, cols, &[]).map(|(c, _)| c)
    }

    /// `required` columns, and of `optional` those the file has: returns
    /// the columns (required first, then the optional ones present) and,
    /// per optional column, its index in `data` if present.
    pub fn read_with(
        path: &Path,
        required: &[&str],
        optional: &[&str],
    ) -> Result<(Self, Vec<Option<usize>>), LabError> {
        Self::read_bounded(path, required, optional, None)
    }

    /// [`Self::read_with`], every cell checked against `bounds`.
    pub fn read_bounded(
        path: &Path,
        required: &[&str],
        optional: &[&str],
        bounds: Option<Bounds>,
    ) -> Result<(Self, Vec<Option<usize>>), LabError> {
        let mut file = std::io::BufReader::with_capacity(
            1 << 20,
            std::fs::File::open(path)
                .map_err(|e| LabError::input(path, format!("cannot read: {e}")))?,
        );
        // The comment lines before the header are skipped by hand, so the
        // reader's line numbers are the file's plus their count (its own
        // comment skipping does not count them).
        let skipped = skip_leading_comments(&mut file)
            .map_err(|e| LabError::input(path, format!("cannot read: {e}")))?;
        let mut rdr = csv::ReaderBuilder::new()
            .has_headers(false)
            .flexible(true)
            .buffer_capacity(1 << 20)
            .from_reader(file);
        let mut rec = csv::ByteRecord::new();
        let at = |e: csv::Error| {
            let line = e.position().map_or(0, |p| p.line()) + skipped;
            LabError::at_line(path, line, e.to_string())
        };
        if !rdr.read_byte_record(&mut rec).map_err(at)? {
            return Err(LabError::input(path, "no header row"));
        }
        let header_line = rec.position().map_or(1, |p| p.line()) + skipped;
        let header: Vec<String> = rec
            .iter()
            .map(|f| String::from_utf8_lossy(f.trim_ascii()).into_owned())
            .collect();
        let mut fields = Vec::new();
        let mut cols: Vec<&str> = required.to_vec();
        for c in required {
            let i = header.iter().position(|h| h == c).ok_or_else(|| {
                LabError::at_line(path, header_line, format!("missing column `{c}`"))
            })?;
            fields.push(i + 1);
        }
        let mut present = vec![];
        for c in optional {
            match header.iter().position(|h| h == c) {
                Some(i) => {
                    present.push(Some(cols.len()));
                    cols.push(c);
                    fields.push(i + 1);
                }
                None => present.push(None),
            }
        }
        let ranges: Vec<_> = cols.iter().map(|c| bounds.and_then(|b| b(c))).collect();
        let mut data: Vec<Vec<f64>> = cols.iter().map(|_| Vec::new()).collect();
        let mut lines = Vec::new();
        while rdr.read_byte_record(&mut rec).map_err(at)? {
            let line = rec.position().map_or(0, |p| p.line()) + skipped;
            // Cells are trimmed here, only those read: the reader's own
            // trimming of every field cost a third of a long record's read.
            if rec.iter().all(|f| f.trim_ascii().is_empty()) {
                continue;
            }
            if rec.len() != header.len() {
                return Err(width_error(path, line, rec.len(), header.len()));
            }
            for (k, &f) in fields.iter().enumerate() {
                let cell = rec.get(f - 1).unwrap_or(b"").trim_ascii();
                let text = std::str::from_utf8(cell).unwrap_or("");
                let v = number(text, ranges[k])
                    .map_err(|m| LabError::at(path, line, column_ref(f, cols[k]), m.to_string()))?;
                data[k].push(v);
            }
            lines.push(line);
        }
        Ok((
            Self {
                path: path.to_owned(),
                header_line,
                data,
                names: cols.iter().map(|c| (*c).to_owned()).collect(),
                lines,
                fields,
            },
            present,
        ))
    }

    pub fn len(&self) -> usize {
        self.lines.len()
    }

    pub fn is_empty(&self) -> bool {
        self.lines.is_empty()
    }

    /// An error at row `row` of requested column `k`.
    pub fn cell_error(&self, row: usize, k: usize, msg: impl Into<String>) -> LabError {
        let line = self.lines.get(row).copied().unwrap_or(self.header_line);
        LabError::at(
            &self.path,
            line,
            column_ref(self.fields[k], &self.names[k]),
            msg,
        )
    }

    /// Requested column `k` strictly increasing (a time column).
    pub fn check_increasing(&self, k: usize) -> Result<(), LabError> {
        let t = &self.data[k];
        for i in 1..t.len() {
            if t[i] <= t[i - 1] {
                return Err(self.cell_error(
                    i,
                    k,
                    format!("time {} does not increase (previous {})", t[i], t[i - 1]),
                ));
            }
        }
        Ok(())
    }
}
