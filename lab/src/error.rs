//! Errors of the lab tool: input errors (exit 2) name file, line and column.

use std::fmt;

#[derive(Debug)]
pub enum LabError {
    /// Bad input: one line, with the place where it applies.
    Input {
        file: String,
        line: Option<u64>,
        column: Option<String>,
        msg: String,
    },
    /// Bad option value.
    Usage(String),
    /// Failure writing output.
    Io(String),
}

impl LabError {
    pub fn exit_code(&self) -> u8 {
        match self {
            LabError::Input { .. } | LabError::Usage(_) => 2,
            LabError::Io(_) => 1,
        }
    }
}

impl fmt::Display for LabError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            LabError::Input {
                file,
                line,
                column,
                msg,
            } => {
                write!(f, "{file}")?;
                if let Some(l) = line {
                    write!(f, ":{l}")?;
                }
                if let Some(c) = column {
                    write!(f, ": column '{c}'")?;
                }
                write!(f, ": {msg}")
            }
            LabError::Usage(m) => write!(f, "{m}"),
            LabError::Io(m) => write!(f, "{m}"),
        }
    }
}

impl From<std::io::Error> for LabError {
    fn from(e: std::io::Error) -> Self {
        LabError::Io(e.to_string())
    }
}
