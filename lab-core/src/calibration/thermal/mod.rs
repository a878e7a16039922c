//! RLG thermal calibration (docs/rlg.md): the bias model fitted on a
//! chamber run (fit.rs), the firmware's compensation applied to a run
//! (compensation.rs), and the drift figures both are judged by (figures.rs,
//! summary.rs), and what a fit warns about (warnings.rs).

pub mod compensation;
pub mod figures;
pub mod fit;
pub mod summary;
pub mod warnings;
