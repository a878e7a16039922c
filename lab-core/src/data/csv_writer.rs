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
    /// The shortest text that reads back as the same number (an integer
    /// without a decimal point, as `{}` writes it; otherwise ryu's, which
    /// may take an exponent: 6.2e-5).
    Shortest,
}

pub struct CsvWriter {
    w: AtomicFile,
    path: PathBuf,
    formats: Vec<CellFormat>,
}

/// [`CellFormat::Shortest`]. ryu, not `{}`: a 10 Hz day's residual.csv
/// is 2.6 million numbers, and `{}` writes them at a third of the speed.
fn write_shortest(w: &mut impl Write, v: f64) -> std::io::Result<()> {
    // Integers (flags, whole seconds) as `{}` writes them: 3, not 3.0.
    if v.fract() == 0.0 && v.abs() < 1e15 && (v != 0.0 || v.is_sign_positive()) {
        return write!(w, "{}", v as i64);
    }
    let mut b = ryu::Buffer::new();
    w.write_all(b.format(v).as_bytes())
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
                CellFormat::Shortest => write_shortest(&mut self.w, *v)?,
            }
        }
        self.w.write_all(b"\n")
    }

    pub fn finish(self) -> Result<(), LabError> {
        self.w.commit()
    }
}

#[cfg(test)]
mod tests {
    use super::write_shortest;

    #[test]
    fn the_shortest_text_reads_back_as_the_same_number() {
        let mut x = 0x9e37_79b9_7f4a_7c15u64;
        let mut values = vec![
            0.0,
            -0.0,
            1.0,
            -3.0,
            0.1,
            1e-5,
            -6.2e-5,
            1e15,
            1.5e20,
            5e-324,
            f64::MAX,
            f64::MIN_POSITIVE,
            86_399.9,
            f64::INFINITY,
            f64::NEG_INFINITY,
        ];
        for _ in 0..10_000 {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            values.push(f64::from_bits(x));
        }
        for v in values {
            let mut s = vec![];
            write_shortest(&mut s, v).unwrap();
            let text = String::from_utf8(s).unwrap();
            let back: f64 = text.parse().unwrap();
            if v.is_nan() {
                assert!(back.is_nan(), "{text}");
            } else {
                assert_eq!(back.to_bits(), v.to_bits(), "{text}");
            }
        }
        let text = |v: f64| {
            let mut s = vec![];
            write_shortest(&mut s, v).unwrap();
            String::from_utf8(s).unwrap()
        };
        assert_eq!(text(3.0), "3");
        assert_eq!(text(0.25), "0.25");
    }
}
