//! Reading CSV data files by column name: one header row, `#` comment
//! lines before it, a byte-order mark before those, cells separated by a
//! comma, a semicolon or a tab (dialect.rs). Every row must have as many
//! cells as the header: a row with one more or one less would shift or
//! drop a column, and the answer would change without a word. Every cell a
//! caller uses is checked: missing columns (all of them, with the columns
//! the file has, at the header's own line), a cell that is not a finite
//! number or is outside its column's physical range, time that does not
//! increase or too few rows give an error at `file:line:column` (column =
//! 1-based field number, then its name). The user's names are mapped onto
//! ours and the units converted here (read_spec.rs); the file kinds
//! (run_file.rs, fringe_file.rs) name the columns and their rules; this
//! module knows none.
//!
//! Two readers: [`TextTable`] keeps the file as text cells (unused columns
//! are written back as read) and checks column by column; [`ColumnStream`]
//! reads long records in one pass without the text and checks row by row.

use super::dialect::{header_line, strip_bom, Dialect};
use super::header::{Header, Places};
use super::read_spec::{ColumnRule, ReadSpec, Rules};
use super::source::{Columns, Origin, Source};
use super::timestamp;
use crate::error::{ColumnRef, LabError};
use std::path::Path;

/// What a reader is asked for: the spec the user gave, the rules of the
/// file kind, and which column is time (its cells may be clock
/// timestamps, its unit is the spec's, and the stretch asked for is cut
/// on it).
#[derive(Clone, Copy)]
pub struct Plan<'a> {
    pub spec: &'a ReadSpec,
    pub rules: Option<Rules<'a>>,
    pub time: Option<&'a str>,
}

impl Plan<'static> {
    /// Read as written: no mapping, no units, no checks, no stretch.
    pub fn plain() -> Self {
        static PLAIN: std::sync::OnceLock<ReadSpec> = std::sync::OnceLock::new();
        Plan {
            spec: PLAIN.get_or_init(ReadSpec::default),
            rules: None,
            time: None,
        }
    }
}

/// What is wrong with a cell that should hold a number.
enum CellError<'a> {
    NotFinite(std::borrow::Cow<'a, str>),
    Empty,
    NotANumber(&'a str),
    OutOfRange(String),
}

impl std::fmt::Display for CellError<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            CellError::NotFinite(c) => write!(f, "`{c}` is not a finite number"),
            CellError::Empty => f.write_str("empty cell"),
            CellError::NotANumber(c) => write!(f, "cannot read `{c}` as a number"),
            CellError::OutOfRange(m) => f.write_str(m),
        }
    }
}

/// How one requested column's cells become numbers.
struct Reader {
    rule: ColumnRule,
    dialect: Dialect,
    /// The time column: numbers in the spec's unit, or clock timestamps
    /// (seconds since the first row's).
    time: Option<f64>,
    clock_origin: Option<f64>,
}

impl Reader {
    fn new(plan: &Plan, name: &str, dialect: Dialect) -> Self {
        let is_time = plan.time == Some(name);
        Self {
            rule: plan.rules.map_or_else(ColumnRule::plain, |r| r(name)),
            dialect,
            time: is_time.then(|| plan.spec.time_unit.unwrap_or_default().to_s()),
            clock_origin: None,
        }
    }

    fn read<'a>(&mut self, cell: &'a str) -> Result<f64, CellError<'a>> {
        let v = match self.dialect.parse(cell) {
            Ok(v) if v.is_finite() => match self.time {
                Some(unit) => v * unit,
                None => self.rule.scale * v + self.rule.offset,
            },
            Ok(_) => return Err(CellError::NotFinite(cell.into())),
            Err(_) if cell.is_empty() => return Err(CellError::Empty),
            Err(_) => match self.time.and_then(|_| timestamp::parse(cell)) {
                Some(s) => s - *self.clock_origin.get_or_insert(s),
                None => return Err(CellError::NotANumber(cell)),
            },
        };
        match self.rule.problem(v) {
            Some(m) => Err(CellError::OutOfRange(format!("`{cell}` {m}"))),
            None => Ok(v),
        }
    }

    /// A number held in memory, through the same unit and checks as a
    /// cell (its text, for messages, as Rust writes it).
    fn value(&mut self, x: f64) -> Result<f64, CellError<'static>> {
        if !x.is_finite() {
            return Err(CellError::NotFinite(x.to_string().into()));
        }
        let v = match self.time {
            Some(unit) => x * unit,
            None => self.rule.scale * x + self.rule.offset,
        };
        match self.rule.problem(v) {
            Some(m) => Err(CellError::OutOfRange(format!("`{x}` {m}"))),
            None => Ok(v),
        }
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

fn csv_reader<R: std::io::Read>(d: Dialect, r: R) -> csv::Reader<R> {
    csv::ReaderBuilder::new()
        .has_headers(false)
        .flexible(true)
        .delimiter(d.delimiter)
        .buffer_capacity(1 << 20)
        .from_reader(r)
}

/// A file kind's rules, owned by the table that reads columns later.
pub type OwnedRules = Box<dyn Fn(&str) -> ColumnRule + 'static>;

/// A table's cells: a file's text, or numbers a caller holds.
enum Cells<'a> {
    /// Each row's file line and its cells as text.
    Text(Vec<(u64, Vec<String>)>),
    /// Columns in memory, and the rows kept (the stretch asked for).
    Numbers {
        columns: &'a Columns<'a>,
        rows: Vec<usize>,
    },
}

/// A data table held whole: a file as text cells with the line number of
/// every row, or columns in memory.
pub struct TextTable<'a> {
    pub origin: Origin,
    pub header: Header,
    header_line: u64,
    cells: Cells<'a>,
    /// The comment lines before the header, as written.
    comments: Vec<String>,
    dialect: Dialect,
    spec: ReadSpec,
    rules: Option<OwnedRules>,
    /// The time column's name, and its values once read (cut to the
    /// stretch asked for).
    time_name: Option<String>,
    time: Option<Vec<f64>>,
}

impl TextTable<'static> {
    /// Reads as written (no mapping, units or stretch).
    pub fn read(path: &Path) -> Result<Self, LabError> {
        Self::read_with(path, &ReadSpec::default(), None, None)
    }

    /// Reads a file with the user's `spec`: the `time` column (if any) is
    /// read first, and the rows outside the stretch asked for are dropped;
    /// `rules` are the file kind's for every column read.
    pub fn read_with(
        path: &Path,
        spec: &ReadSpec,
        time: Option<&str>,
        rules: Option<OwnedRules>,
    ) -> Result<Self, LabError> {
        let bytes =
            std::fs::read(path).map_err(|e| LabError::input(path, format!("cannot read: {e}")))?;
        let (bytes, _) = strip_bom(&bytes);
        let text = String::from_utf8_lossy(bytes);
        let dialect = Dialect::of_header(header_line(text.as_bytes()));
        // Comment lines before the header are skipped by hand so that line
        // numbers stay those of the file.
        let (skipped, offset) = leading_comments(text.as_bytes());
        let comments: Vec<String> = text[..offset]
            .lines()
            .filter(|l| l.trim_start().starts_with('#'))
            .map(str::to_owned)
            .collect();
        let mut rdr = csv_reader(dialect, &text.as_bytes()[offset..]);
        let mut records = rdr.records();
        let names: Vec<String> = match records.next() {
            Some(Ok(r)) => r.iter().map(|c| c.trim().to_owned()).collect(),
            Some(Err(e)) => return Err(LabError::input(path, e.to_string())),
            None => return Err(LabError::input(path, "no header row")),
        };
        let header_line = skipped + 1;
        let header = Header::new(names, spec);
        let mut rows = Vec::new();
        for rec in records {
            let rec = rec.map_err(|e| {
                let line = e.position().map_or(0, |p| p.line() + skipped);
                LabError::at_line(path, line, e.to_string())
            })?;
            let line = rec.position().map_or(0, |p| p.line()) + skipped;
            if rec.iter().all(|c| c.trim().is_empty()) {
                continue;
            }
            if rec.len() != header.len() {
                return Err(width_error(path, line, rec.len(), header.len()));
            }
            rows.push((line, rec.iter().map(|c| c.trim().to_owned()).collect()));
        }
        let t = TextTable {
            origin: Origin::File(path.to_owned()),
            header,
            header_line,
            cells: Cells::Text(rows),
            comments,
            dialect,
            spec: spec.clone(),
            rules,
            time_name: time.map(str::to_owned),
            time: None,
        };
        t.cut(time)
    }
}

impl<'a> TextTable<'a> {
    /// A file, or columns in memory, read with the user's `spec` (see
    /// [`TextTable::read_with`]).
    pub fn read_source(
        source: Source<'a>,
        spec: &ReadSpec,
        time: Option<&str>,
        rules: Option<OwnedRules>,
    ) -> Result<Self, LabError> {
        let columns = match source {
            Source::File(p) => return TextTable::read_with(p, spec, time, rules),
            Source::Columns(c) => c,
        };
        let t = TextTable {
            origin: source.origin(),
            header: Header::new(columns.names.clone(), spec),
            header_line: 0,
            cells: Cells::Numbers {
                columns,
                rows: (0..columns.len()).collect(),
            },
            comments: vec![],
            dialect: Dialect::default(),
            spec: spec.clone(),
            rules,
            time_name: time.map(str::to_owned),
            time: None,
        };
        t.cut(time)
    }

    /// Reads the `time` column (if any) and drops the rows outside the
    /// stretch asked for.
    fn cut(mut self, time: Option<&str>) -> Result<Self, LabError> {
        if let Some(tc) = time {
            let v = self.column(tc)?;
            let keep: Vec<bool> = v.iter().map(|&x| self.spec.keeps(x)).collect();
            let mut k = keep.iter();
            match &mut self.cells {
                Cells::Text(rows) => rows.retain(|_| *k.next().unwrap_or(&false)),
                Cells::Numbers { rows, .. } => rows.retain(|_| *k.next().unwrap_or(&false)),
            }
            let v: Vec<f64> = v
                .into_iter()
                .zip(&keep)
                .filter(|p| *p.1)
                .map(|p| p.0)
                .collect();
            self.time = Some(v);
        }
        Ok(self)
    }

    pub fn len(&self) -> usize {
        match &self.cells {
            Cells::Text(rows) => rows.len(),
            Cells::Numbers { rows, .. } => rows.len(),
        }
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Where row `k` is: its file line, or its row in memory.
    fn place(&self, k: usize) -> u64 {
        match &self.cells {
            Cells::Text(rows) => rows[k].0,
            Cells::Numbers { rows, .. } => rows[k] as u64,
        }
    }

    pub fn has(&self, col: &str) -> bool {
        self.header.find(col).is_some()
    }

    /// All of `cols` present, else one error listing every one missing.
    pub fn require(&self, cols: &[&str]) -> Result<(), LabError> {
        self.header
            .require(&self.origin, self.header_line, cols)
            .map(|_| ())
    }

    fn index(&self, col: &str) -> Result<usize, LabError> {
        self.header
            .require(&self.origin, self.header_line, &[col])
            .map(|v| v[0])
    }

    /// Where `cols` (ours) are: the source, the header's line, and per
    /// column present its field and the name the source gives it.
    pub fn places(&self, cols: &[&str]) -> Places {
        Places {
            origin: self.origin.clone(),
            header_line: self.header_line,
            fields: cols
                .iter()
                .filter_map(|c| {
                    self.header
                        .find(c)
                        .map(|i| (c.to_string(), i + 1, self.header.shown(c).to_owned()))
                })
                .collect(),
        }
    }

    /// An error about column `col` as a whole, placed at its header cell.
    pub fn column_error(&self, col: &str, msg: impl Into<String>) -> LabError {
        let i = self.header.find(col).map_or(0, |i| i + 1);
        self.origin
            .column(self.header_line, i, self.header.shown(col), msg)
    }

    /// A numeric column: every cell a finite number inside its range.
    pub fn column(&self, col: &str) -> Result<Vec<f64>, LabError> {
        if let (Some(name), Some(v)) = (&self.time_name, &self.time) {
            if name == col {
                return Ok(v.clone());
            }
        }
        let i = self.index(col)?;
        let plan = Plan {
            spec: &self.spec,
            rules: self.rules.as_deref(),
            time: self.time_name.as_deref(),
        };
        let mut reader = Reader::new(&plan, col, self.dialect);
        let at = |place: u64, m: CellError| {
            self.origin
                .cell(place, i + 1, self.header.shown(col), m.to_string())
        };
        match &self.cells {
            Cells::Text(rows) => rows
                .iter()
                .map(|(line, cells)| {
                    let cell = cells.get(i).map(String::as_str).unwrap_or("");
                    reader.read(cell).map_err(|m| at(*line, m))
                })
                .collect(),
            Cells::Numbers { columns, rows } => {
                let v = &columns.values[i];
                rows.iter()
                    .map(|&r| reader.value(v[r]).map_err(|m| at(r as u64, m)))
                    .collect()
            }
        }
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
    /// rows (in the stretch asked for).
    pub fn time(&self, col: &str, min_rows: usize) -> Result<Vec<f64>, LabError> {
        let t = self.column(col)?;
        if self.len() < min_rows {
            return Err(self.origin.whole(format!(
                "{} data rows{}, at least {min_rows} needed",
                self.len(),
                self.spec
                    .stretch()
                    .map_or(String::new(), |s| format!(" in the stretch {s}"))
            )));
        }
        let i = self.index(col)?;
        for k in 1..t.len() {
            if t[k] <= t[k - 1] {
                return Err(self.origin.cell(
                    self.place(k),
                    i + 1,
                    self.header.shown(col),
                    format!("time {} does not increase (previous {})", t[k], t[k - 1]),
                ));
            }
        }
        Ok(t)
    }

    /// The table's rows as text with extra numeric columns appended:
    /// `comment` as `#` lines first, then the file's own comment lines,
    /// the header and the rows in the file's separator (a table in memory
    /// as comma-separated numbers).
    pub fn text_with(&self, comment: &str, extra: &[(&str, &[f64])]) -> String {
        let d = self.dialect.delimiter as char;
        let mut s = String::with_capacity(64 * (self.len() + 1));
        for l in comment.lines() {
            s.push_str("# ");
            s.push_str(l);
            s.push('\n');
        }
        for l in &self.comments {
            s.push_str(l);
            s.push('\n');
        }
        let quote = |c: &str| {
            if c.contains(d) || c.contains('"') {
                format!("\"{}\"", c.replace('"', "\"\""))
            } else {
                c.to_owned()
            }
        };
        let mut head: Vec<String> = self.header.names().iter().map(|c| quote(c)).collect();
        head.extend(extra.iter().map(|(n, _)| n.to_string()));
        s.push_str(&head.join(&d.to_string()));
        s.push('\n');
        for k in 0..self.len() {
            let mut rec: Vec<String> = match &self.cells {
                Cells::Text(rows) => rows[k].1.iter().map(|c| quote(c)).collect(),
                Cells::Numbers { columns, rows } => columns
                    .values
                    .iter()
                    .map(|v| v[rows[k]].to_string())
                    .collect(),
            };
            rec.extend(extra.iter().map(|(_, v)| format!("{:.9}", v[k])));
            s.push_str(&rec.join(&d.to_string()));
            s.push('\n');
        }
        s
    }
}

/// Numeric columns of a long record, read in one pass without keeping the
/// text (a 10^7-row run file as a [`TextTable`] would be gigabytes of
/// strings). The same checks and messages as [`TextTable`].
pub struct ColumnStream {
    pub origin: Origin,
    pub header_line: u64,
    /// One vector per requested column, in the order asked.
    pub data: Vec<Vec<f64>>,
    /// The requested columns' names (ours), in the order of `data`.
    pub names: Vec<String>,
    /// The requested columns' names as the file has them.
    pub shown: Vec<String>,
    /// File line of every row (its row, for columns in memory).
    pub lines: Vec<u64>,
    /// 1-based field number of every requested column.
    pub fields: Vec<usize>,
}

/// Consumes a byte-order mark and the comment and blank lines before the
/// header; returns their count.
fn skip_leading_comments(r: &mut impl std::io::BufRead) -> std::io::Result<u64> {
    let buf = r.fill_buf()?;
    let bom = strip_bom(buf).1;
    r.consume(bom);
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
    /// `cols`, read as written.
    pub fn read(path: &Path, cols: &[&str]) -> Result<Self, LabError> {
        Self::read_plan(path, cols, &[], Plan::plain()).map(|(c, _)| c)
    }

    /// `required` columns, and of `optional` those the file has: returns
    /// the columns (required first, then the optional ones present) and,
    /// per optional column, its index in `data` if present. The rows
    /// outside the plan's stretch are dropped (their cells unread but for
    /// time).
    pub fn read_plan(
        path: &Path,
        required: &[&str],
        optional: &[&str],
        plan: Plan,
    ) -> Result<(Self, Vec<Option<usize>>), LabError> {
        Self::read_source(Source::File(path), required, optional, plan)
    }

    /// [`ColumnStream::read_plan`] of a file or of columns in memory.
    pub fn read_source(
        source: Source,
        required: &[&str],
        optional: &[&str],
        plan: Plan,
    ) -> Result<(Self, Vec<Option<usize>>), LabError> {
        let path = match source {
            Source::File(p) => p,
            Source::Columns(c) => return Self::from_columns(c, required, optional, plan),
        };
        use std::io::BufRead;
        let mut file = std::io::BufReader::with_capacity(
            1 << 20,
            std::fs::File::open(path)
                .map_err(|e| LabError::input(path, format!("cannot read: {e}")))?,
        );
        let cant = |e: std::io::Error| LabError::input(path, format!("cannot read: {e}"));
        // The comment lines before the header are skipped by hand, so the
        // reader's line numbers are the file's plus their count.
        let skipped = skip_leading_comments(&mut file).map_err(cant)?;
        let dialect = Dialect::of_header(header_line(file.fill_buf().map_err(cant)?));
        let mut rdr = csv_reader(dialect, file);
        let mut rec = csv::ByteRecord::new();
        let at = |e: csv::Error| {
            let line = e.position().map_or(0, |p| p.line()) + skipped;
            LabError::at_line(path, line, e.to_string())
        };
        if !rdr.read_byte_record(&mut rec).map_err(at)? {
            return Err(LabError::input(path, "no header row"));
        }
        let header_line = rec.position().map_or(1, |p| p.line()) + skipped;
        let header = Header::new(
            rec.iter()
                .map(|f| String::from_utf8_lossy(f.trim_ascii()).into_owned())
                .collect(),
            plan.spec,
        );
        let mut cols: Vec<&str> = required.to_vec();
        let mut fields: Vec<usize> = header
            .require(&Origin::File(path.to_owned()), header_line, required)?
            .into_iter()
            .map(|i| i + 1)
            .collect();
        let mut present = vec![];
        for c in optional {
            match header.find(c) {
                Some(i) => {
                    present.push(Some(cols.len()));
                    cols.push(c);
                    fields.push(i + 1);
                }
                None => present.push(None),
            }
        }
        let mut readers: Vec<Reader> = cols
            .iter()
            .map(|c| Reader::new(&plan, c, dialect))
            .collect();
        let time_k = plan.time.and_then(|t| cols.iter().position(|c| *c == t));
        let shown: Vec<String> = cols.iter().map(|c| header.shown(c).to_owned()).collect();
        let mut data: Vec<Vec<f64>> = cols.iter().map(|_| Vec::new()).collect();
        let mut lines = Vec::new();
        let width = header.len();
        while rdr.read_byte_record(&mut rec).map_err(at)? {
            let line = rec.position().map_or(0, |p| p.line()) + skipped;
            if rec.iter().all(|f| f.trim_ascii().is_empty()) {
                continue;
            }
            if rec.len() != width {
                return Err(width_error(path, line, rec.len(), width));
            }
            let cell = |k: usize, readers: &mut [Reader]| {
                let f = fields[k];
                let text =
                    std::str::from_utf8(rec.get(f - 1).unwrap_or(b"").trim_ascii()).unwrap_or("");
                readers[k]
                    .read(text)
                    .map_err(|m| LabError::at(path, line, column_ref(f, &shown[k]), m.to_string()))
            };
            if let Some(k) = time_k {
                let t = cell(k, &mut readers)?;
                if !plan.spec.keeps(t) {
                    continue;
                }
                data[k].push(t);
            }
            for k in (0..cols.len()).filter(|&k| Some(k) != time_k) {
                let v = cell(k, &mut readers)?;
                data[k].push(v);
            }
            lines.push(line);
        }
        Ok((
            Self {
                origin: Origin::File(path.to_owned()),
                header_line,
                data,
                names: cols.iter().map(|c| (*c).to_owned()).collect(),
                shown,
                lines,
                fields,
            },
            present,
        ))
    }

    /// The columns a caller holds, read as a file's would be: the same
    /// names through the spec, the same rules and messages, each value
    /// read where it lies.
    fn from_columns(
        columns: &Columns,
        required: &[&str],
        optional: &[&str],
        plan: Plan,
    ) -> Result<(Self, Vec<Option<usize>>), LabError> {
        let origin = Origin::Memory(columns.label.clone());
        let header = Header::new(columns.names.clone(), plan.spec);
        let mut cols: Vec<&str> = required.to_vec();
        let mut fields: Vec<usize> = header
            .require(&origin, 0, required)?
            .into_iter()
            .map(|i| i + 1)
            .collect();
        let mut present = vec![];
        for c in optional {
            match header.find(c) {
                Some(i) => {
                    present.push(Some(cols.len()));
                    cols.push(c);
                    fields.push(i + 1);
                }
                None => present.push(None),
            }
        }
        let shown: Vec<String> = cols.iter().map(|c| header.shown(c).to_owned()).collect();
        let dialect = Dialect::default();
        let at = |row: usize, k: usize, m: CellError| {
            origin.cell(row as u64, fields[k], &shown[k], m.to_string())
        };
        // Time first: it decides the rows kept (all of them, read in one
        // pass, where no stretch was asked for).
        let time_k = plan.time.and_then(|t| cols.iter().position(|c| *c == t));
        let n = columns.len();
        let whole = plan.spec.from_s.is_none() && plan.spec.to_s.is_none();
        let mut rows: Option<Vec<usize>> = None;
        let mut data: Vec<Vec<f64>> = vec![Vec::new(); cols.len()];
        let read = |k: usize, rows: Option<&[usize]>| -> Result<Vec<f64>, LabError> {
            let mut reader = Reader::new(&plan, cols[k], dialect);
            let v = &columns.values[fields[k] - 1];
            let mut out = Vec::with_capacity(rows.map_or(n, |r| r.len()));
            match rows {
                None => {
                    for (r, &x) in v.iter().enumerate() {
                        out.push(reader.value(x).map_err(|m| at(r, k, m))?);
                    }
                }
                Some(rows) => {
                    for &r in rows {
                        out.push(reader.value(v[r]).map_err(|m| at(r, k, m))?);
                    }
                }
            }
            Ok(out)
        };
        if let Some(k) = time_k {
            let t = read(k, None)?;
            if whole {
                data[k] = t;
            } else {
                let kept: Vec<usize> = (0..n).filter(|&r| plan.spec.keeps(t[r])).collect();
                data[k] = kept.iter().map(|&r| t[r]).collect();
                rows = Some(kept);
            }
        }
        for k in (0..cols.len()).filter(|&k| Some(k) != time_k) {
            data[k] = read(k, rows.as_deref())?;
        }
        let lines: Vec<u64> = match &rows {
            None => (0..n as u64).collect(),
            Some(r) => r.iter().map(|&r| r as u64).collect(),
        };
        Ok((
            Self {
                origin,
                header_line: 0,
                data,
                names: cols.iter().map(|c| (*c).to_owned()).collect(),
                shown,
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
        self.origin.cell(line, self.fields[k], &self.shown[k], msg)
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
