//! Errors of the lab tool. Bad input (options, data files) exits with status 2
//! and a one-line message naming the file, line and column where that applies.
//! The places are fields; the message `file:line:column: message` is made from
//! them in one place, `Display` below.

use std::fmt;
use std::path::PathBuf;

/// The column of an input error: a 1-based field (CSV) or character (TOML)
/// number, and the data column's name where the file names its columns.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct ColumnRef {
    pub index: usize,
    pub name: Option<String>,
}

#[derive(Debug)]
pub enum LabError {
    /// A bad option value.
    Usage(String),
    /// Bad input: the file, the line and column where known, what is wrong.
    Input {
        file: PathBuf,
        line: Option<u64>,
        column: Option<ColumnRef>,
        msg: String,
    },
    /// Bad input in columns a caller holds in memory (a notebook's
    /// arrays): what the caller calls them, the row (from 0, as numpy and
    /// pandas count) and the column where known, what is wrong.
    Memory {
        what: String,
        row: Option<u64>,
        column: Option<String>,
        msg: String,
    },
    /// An estimator failed on a benchmark's own simulated record.
    Bench(String),
    /// Failure writing output (the file where known).
    Io { file: Option<PathBuf>, msg: String },
}

impl LabError {
    /// Bad input in `file` as a whole.
    pub fn input(file: impl Into<PathBuf>, msg: impl Into<String>) -> Self {
        LabError::Input {
            file: file.into(),
            line: None,
            column: None,
            msg: msg.into(),
        }
    }

    /// Bad input on one line of `file`.
    pub fn at_line(file: impl Into<PathBuf>, line: u64, msg: impl Into<String>) -> Self {
        LabError::Input {
            file: file.into(),
            line: Some(line),
            column: None,
            msg: msg.into(),
        }
    }

    /// Bad input at one line and column of `file`.
    pub fn at(
        file: impl Into<PathBuf>,
        line: u64,
        column: ColumnRef,
        msg: impl Into<String>,
    ) -> Self {
        LabError::Input {
            file: file.into(),
            line: Some(line),
            column: Some(column),
            msg: msg.into(),
        }
    }

    /// A write to `file` that failed.
    pub fn io(file: impl Into<PathBuf>, e: impl fmt::Display) -> Self {
        LabError::Io {
            file: Some(file.into()),
            msg: e.to_string(),
        }
    }

    /// An input error of gyro-coeffs, which places its own messages as
    /// `file[:line:column]: message`: read back into the fields, so that
    /// the message is made here like every other.
    pub fn coeffs_input(file: impl Into<PathBuf>, placed: &str) -> Self {
        let file = file.into();
        let (line, column, msg) = unplace(&file, placed);
        LabError::Input {
            file,
            line,
            column: column.map(|index| ColumnRef { index, name: None }),
            msg,
        }
    }

    /// A write error of gyro-coeffs (`file: message`).
    pub fn coeffs_io(file: impl Into<PathBuf>, placed: &str) -> Self {
        let file = file.into();
        let (_, _, msg) = unplace(&file, placed);
        LabError::Io {
            file: Some(file),
            msg,
        }
    }

    /// 2 for every error: bad input, and an output that cannot be written
    /// (a user's path too) alike.
    pub fn exit_code(&self) -> u8 {
        2
    }
}

/// Line, column and message of `file[:line[:column]]: message`; a message
/// that does not start with the file is kept whole.
fn unplace(file: &std::path::Path, placed: &str) -> (Option<u64>, Option<usize>, String) {
    let name = file.display().to_string();
    let Some(rest) = placed.strip_prefix(&name) else {
        return (None, None, placed.to_owned());
    };
    let mut nums = vec![];
    let mut rest = rest;
    while let Some(r) = rest.strip_prefix(':') {
        let digits = r.len() - r.trim_start_matches(|c: char| c.is_ascii_digit()).len();
        match r[..digits].parse::<u64>() {
            Ok(v) if nums.len() < 2 => {
                nums.push(v);
                rest = &r[digits..];
            }
            _ => break,
        }
    }
    match rest.strip_prefix(": ") {
        Some(msg) => (
            nums.first().copied(),
            nums.get(1).map(|&c| c as usize),
            msg.to_owned(),
        ),
        None => (None, None, placed.to_owned()),
    }
}

impl fmt::Display for LabError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            LabError::Usage(m) | LabError::Bench(m) => write!(f, "{m}"),
            LabError::Input {
                file,
                line,
                column,
                msg,
            } => {
                write!(f, "{}", file.display())?;
                if let Some(l) = line {
                    write!(f, ":{l}")?;
                }
                if let Some(c) = column {
                    write!(f, ":{}", c.index)?;
                    if let Some(n) = &c.name {
                        write!(f, " (column `{n}`)")?;
                    }
                }
                write!(f, ": {msg}")
            }
            LabError::Memory {
                what,
                row,
                column,
                msg,
            } => {
                write!(f, "{what}")?;
                if let Some(r) = row {
                    write!(f, ": row {r}")?;
                }
                if let Some(c) = column {
                    write!(f, " (column `{c}`)")?;
                }
                write!(f, ": {msg}")
            }
            LabError::Io { file, msg } => match file {
                Some(p) => write!(f, "{}: {msg}", p.display()),
                None => write!(f, "{msg}"),
            },
        }
    }
}

impl std::error::Error for LabError {}

impl From<std::io::Error> for LabError {
    fn from(e: std::io::Error) -> Self {
        LabError::Io {
            file: None,
            msg: e.to_string(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn messages_are_made_from_the_fields() {
        let e = LabError::at(
            "fringe.csv",
            4,
            ColumnRef {
                index: 2,
                name: Some("signal".into()),
            },
            "empty cell",
        );
        assert_eq!(
            e.to_string(),
            "fringe.csv:4:2 (column `signal`): empty cell"
        );
        assert_eq!(e.exit_code(), 2);
        assert_eq!(
            LabError::at_line("a.csv", 1, "missing column `x`").to_string(),
            "a.csv:1: missing column `x`"
        );
        assert_eq!(
            LabError::input("a.csv", "no header row").to_string(),
            "a.csv: no header row"
        );
        let m = LabError::Memory {
            what: "run".into(),
            row: Some(17),
            column: Some("gyro_z".into()),
            msg: "`NaN` is not a finite number".into(),
        };
        assert_eq!(
            m.to_string(),
            "run: row 17 (column `gyro_z`): `NaN` is not a finite number"
        );
        let io = LabError::io("out/x.csv", "denied");
        assert_eq!(
            (io.to_string().as_str(), io.exit_code()),
            ("out/x.csv: denied", 2)
        );
    }

    #[test]
    fn coefficient_messages_read_back_into_fields() {
        let e = LabError::coeffs_input("c.toml", "c.toml:5:16: expected a number");
        let LabError::Input { line, column, .. } = &e else {
            panic!("{e:?}")
        };
        assert_eq!(
            (*line, column.as_ref().map(|c| c.index)),
            (Some(5), Some(16))
        );
        assert_eq!(e.to_string(), "c.toml:5:16: expected a number");
        for s in [
            "c.toml: unknown coefficient kind `x`",
            "c.toml: [a] out: 3:4",
        ] {
            assert_eq!(LabError::coeffs_input("c.toml", s).to_string(), s);
        }
        // A message that does not name the file stays whole after it.
        assert_eq!(
            LabError::coeffs_input("c.toml", "odd").to_string(),
            "c.toml: odd"
        );
    }
}
