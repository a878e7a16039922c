//! Reading run and fringe files (docs/interfaces.md "Data files"): CSV, one header
//! row, `#` comment lines before it. Every cell the tool uses is checked: a
//! missing column, a cell that is not a finite number, time that does not
//! increase or too few rows give `file:line:column: message` (column = 1-based
//! field number, then its name). Unused columns are kept for write-back.

use crate::error::LabError;
use std::path::{Path, PathBuf};

/// A data file held as text cells, with the line number of every row.
pub struct Table {
    pub path: PathBuf,
    pub header: Vec<String>,
    header_line: u64,
    rows: Vec<(u64, Vec<String>)>,
}

impl Table {
    pub fn read(path: &Path) -> Result<Self, LabError> {
        let name = path.display().to_string();
        let text = std::fs::read_to_string(path)
            .map_err(|e| LabError::Input(format!("{name}: cannot read: {e}")))?;
        // Comment lines before the header are skipped by hand so that line
        // numbers stay those of the file.
        let mut skipped = 0u64;
        let mut offset = 0usize;
        for line in text.split_inclusive('\n') {
            let t = line.trim();
            if t.starts_with('#') || t.is_empty() {
                skipped += 1;
                offset += line.len();
            } else {
                break;
            }
        }
        let mut rdr = csv::ReaderBuilder::new()
            .has_headers(false)
            .flexible(true)
            .trim(csv::Trim::All)
            .from_reader(&text.as_bytes()[offset..]);
        let mut records = rdr.records();
        let header: Vec<String> = match records.next() {
            Some(Ok(r)) => r.iter().map(str::to_owned).collect(),
            Some(Err(e)) => return Err(LabError::Input(format!("{name}: {e}"))),
            None => return Err(LabError::Input(format!("{name}: no header row"))),
        };
        let header_line = skipped + 1;
        let mut rows = Vec::new();
        for rec in records {
            let rec = rec.map_err(|e| {
                let line = e.position().map_or(0, |p| p.line() + skipped);
                LabError::Input(format!("{name}:{line}: {e}"))
            })?;
            let line = rec.position().map_or(0, |p| p.line()) + skipped;
            if rec.iter().all(str::is_empty) {
                continue;
            }
            rows.push((line, rec.iter().map(str::to_owned).collect()));
        }
        Ok(Self {
            path: path.to_owned(),
            header,
            header_line,
            rows,
        })
    }

    fn name(&self) -> String {
        self.path.display().to_string()
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
            LabError::Input(format!(
                "{}:{}: missing column `{col}`",
                self.name(),
                self.header_line
            ))
        })
    }

    /// `file:line:column (column `name`)` of a column's header cell, for
    /// errors about the column as a whole.
    pub fn column_place(&self, col: &str) -> String {
        let i = self
            .header
            .iter()
            .position(|h| h == col)
            .map_or(0, |i| i + 1);
        format!("{}:{}:{i} (column `{col}`)", self.name(), self.header_line)
    }

    /// `file:line:column` of the cell of data row `row` (0-based) in `col`.
    pub fn cell_place(&self, row: usize, col: &str) -> String {
        let i = self
            .header
            .iter()
            .position(|h| h == col)
            .map_or(0, |i| i + 1);
        let line = self.rows.get(row).map_or(self.header_line, |r| r.0);
        format!("{}:{line}:{i} (column `{col}`)", self.name())
    }

    /// A numeric column: every cell a finite number.
    pub fn column(&self, col: &str) -> Result<Vec<f64>, LabError> {
        let i = self.index(col)?;
        self.rows
            .iter()
            .map(|(line, cells)| {
                let cell = cells.get(i).map(String::as_str).unwrap_or("");
                match cell.parse::<f64>() {
                    Ok(v) if v.is_finite() => Ok(v),
                    Ok(_) => Err(format!("`{cell}` is not a finite number")),
                    Err(_) if cell.is_empty() => Err("empty cell".to_owned()),
                    Err(_) => Err(format!("cannot read `{cell}` as a number")),
                }
                .map_err(|m| {
                    LabError::Input(format!(
                        "{}:{line}:{} (column `{col}`): {m}",
                        self.name(),
                        i + 1
                    ))
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

    /// The `t_s` column, strictly increasing, with at least `min_rows` rows.
    pub fn time(&self, min_rows: usize) -> Result<Vec<f64>, LabError> {
        if self.rows.len() < min_rows {
            return Err(LabError::Input(format!(
                "{}: {} data rows, at least {min_rows} needed",
                self.name(),
                self.rows.len()
            )));
        }
        let t = self.column("t_s")?;
        let i = self.index("t_s")?;
        for k in 1..t.len() {
            if t[k] <= t[k - 1] {
                return Err(LabError::Input(format!(
                    "{}:{}:{} (column `t_s`): time {} does not increase (previous {})",
                    self.name(),
                    self.rows[k].0,
                    i + 1,
                    t[k],
                    t[k - 1]
                )));
            }
        }
        Ok(t)
    }

    /// Writes the table back with extra numeric columns appended.
    pub fn write_with(&self, out: &Path, extra: &[(&str, &[f64])]) -> Result<(), LabError> {
        let io = |e: csv::Error| LabError::Io(format!("{}: {e}", out.display()));
        let mut w = csv::Writer::from_path(out).map_err(io)?;
        let mut head = self.header.clone();
        head.extend(extra.iter().map(|(n, _)| n.to_string()));
        w.write_record(&head).map_err(io)?;
        for (k, (_, cells)) in self.rows.iter().enumerate() {
            let mut rec = cells.clone();
            rec.extend(extra.iter().map(|(_, v)| format!("{:.9}", v[k])));
            w.write_record(&rec).map_err(io)?;
        }
        w.flush()
            .map_err(|e| LabError::Io(format!("{}: {e}", out.display())))
    }
}

/// Numeric columns of a long record, read in one pass without keeping the
/// text (a 10^7-row run file as a [`Table`] would be gigabytes of strings).
/// The same checks and messages as [`Table`]: a missing column, an empty or
/// non-numeric cell, NaN or infinity give `file:line:column`.
pub struct Columns {
    pub path: PathBuf,
    pub header_line: u64,
    /// One vector per requested column, in the order asked.
    pub data: Vec<Vec<f64>>,
    /// File line of every row.
    pub lines: Vec<u64>,
    /// 1-based field number of every requested column.
    pub fields: Vec<usize>,
}

impl Columns {
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
        let name = path.display().to_string();
        let file = std::fs::File::open(path)
            .map_err(|e| LabError::Input(format!("{name}: cannot read: {e}")))?;
        let mut rdr = csv::ReaderBuilder::new()
            .has_headers(false)
            .flexible(true)
            .comment(Some(b'#'))
            .trim(csv::Trim::All)
            .buffer_capacity(1 << 20)
            .from_reader(std::io::BufReader::with_capacity(1 << 20, file));
        let mut rec = csv::ByteRecord::new();
        let at = |e: csv::Error| {
            let line = e.position().map_or(0, |p| p.line());
            LabError::Input(format!("{name}:{line}: {e}"))
        };
        if !rdr.read_byte_record(&mut rec).map_err(at)? {
            return Err(LabError::Input(format!("{name}: no header row")));
        }
        let header_line = rec.position().map_or(1, |p| p.line());
        let header: Vec<String> = rec
            .iter()
            .map(|f| String::from_utf8_lossy(f).into_owned())
            .collect();
        let mut fields = Vec::new();
        let mut cols: Vec<&str> = required.to_vec();
        for c in required {
            let i = header.iter().position(|h| h == c).ok_or_else(|| {
                LabError::Input(format!("{name}:{header_line}: missing column `{c}`"))
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
        let mut data: Vec<Vec<f64>> = cols.iter().map(|_| Vec::new()).collect();
        let mut lines = Vec::new();
        while rdr.read_byte_record(&mut rec).map_err(at)? {
            let line = rec.position().map_or(0, |p| p.line());
            if rec.iter().all(|f| f.is_empty()) {
                continue;
            }
            for (k, &f) in fields.iter().enumerate() {
                let cell = rec.get(f - 1).unwrap_or(b"");
                let text = std::str::from_utf8(cell).unwrap_or("");
                let v = match text.parse::<f64>() {
                    Ok(v) if v.is_finite() => Ok(v),
                    Ok(_) => Err(format!("`{text}` is not a finite number")),
                    Err(_) if text.is_empty() => Err("empty cell".to_owned()),
                    Err(_) => Err(format!("cannot read `{text}` as a number")),
                }
                .map_err(|m| {
                    LabError::Input(format!("{name}:{line}:{f} (column `{}`): {m}", cols[k]))
                })?;
                data[k].push(v);
            }
            lines.push(line);
        }
        Ok((
            Self {
                path: path.to_owned(),
                header_line,
                data,
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

    /// `file:line:column (column `name`)` of row `row` in requested column `k`.
    pub fn place(&self, row: usize, k: usize, col: &str) -> String {
        let line = self.lines.get(row).copied().unwrap_or(self.header_line);
        format!(
            "{}:{line}:{} (column `{col}`)",
            self.path.display(),
            self.fields[k]
        )
    }
}
