//! Which gyro a model or a run is of: the effects differ.

/// Which gyro a model or run is of.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum GyroKind {
    Fog,
    Rlg,
}

impl GyroKind {
    pub fn name(self) -> &'static str {
        match self {
            GyroKind::Fog => "fog",
            GyroKind::Rlg => "rlg",
        }
    }
}
