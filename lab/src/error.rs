//! Errors of the lab tool. Bad input (options, data files) exits with status 2
//! and a one-line message naming the file, line and column where that applies.

use std::fmt;

#[derive(Debug)]
pub enum LabError {
    /// Bad option value.
    Usage(String),
    /// Bad input file: `file:line:column: message` (line/column where known).
    Input(String),
    /// Failure writing output.
    Io(String),
}

impl LabError {
    pub fn exit_code(&self) -> u8 {
        match self {
            LabError::Usage(_) | LabError::Input(_) => 2,
            LabError::Io(_) => 1,
        }
    }
}

impl fmt::Display for LabError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            LabError::Usage(m) | LabError::Input(m) | LabError::Io(m) => write!(f, "{m}"),
        }
    }
}

impl std::error::Error for LabError {}

impl From<std::io::Error> for LabError {
    fn from(e: std::io::Error) -> Self {
        LabError::Io(e.to_string())
    }
}
