//! Numerics that calibration, discovery and the noise analysis share: the
//! one least-squares solver, the one 1-D search, dot products of long
//! columns, the distributions, and the RLG monoblock difference with its
//! filtered gradient as the firmware forms them. Nothing here knows a
//! command, a file or a gyro model.

pub mod dot;
pub mod lsq;
pub mod search;
pub mod stats;
pub mod thermal_difference;
