//! Errors of the lab tool. Usage errors (bad option values) exit with status 2.

use std::fmt;

#[derive(Debug)]
pub enum LabError {
    /// Bad option value.
    Usage(String),
    /// Failure writing output.
    Io(String),
}

impl LabError {
    pub fn exit_code(&self) -> u8 {
        match self {
            LabError::Usage(_) => 2,
            LabError::Io(_) => 1,
        }
    }
}

impl fmt::Display for LabError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            LabError::Usage(m) | LabError::Io(m) => write!(f, "{m}"),
        }
    }
}

impl From<std::io::Error> for LabError {
    fn from(e: std::io::Error) -> Self {
        LabError::Io(e.to_string())
    }
}
