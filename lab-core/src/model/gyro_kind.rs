//! Which gyro a model or a run is of: the effects differ.

/// Which gyro a model or run is of.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum GyroKind {
    /// Closed-loop fibre-optic gyro (physics.md 1): a coil sensor `temp_c`.
    Fog,
    /// Ring laser gyro (physics.md 2): monoblock and case sensors.
    Rlg,
    /// A MEMS rate gyro with one temperature sensor `temp_c`.
    Mems,
}

impl GyroKind {
    pub const ALL: [GyroKind; 3] = [GyroKind::Fog, GyroKind::Rlg, GyroKind::Mems];

    pub fn name(self) -> &'static str {
        match self {
            GyroKind::Fog => "fog",
            GyroKind::Rlg => "rlg",
            GyroKind::Mems => "mems",
        }
    }

    pub fn from_name(s: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|g| g.name() == s)
    }
}
