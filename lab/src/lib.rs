//! `gyro-lab` as a library: the simulators, estimators and fits behind the
//! subcommands, so that tests call the very code the tool runs.

// Numeric code walks parallel arrays (taus, estimates, terms) by index.
#![allow(clippy::needless_range_loop)]

pub mod allan;
pub mod data;
pub mod discover;
pub mod effects;
pub mod error;
pub mod lockin;
pub mod model;
pub mod numerics;
pub mod report;
pub mod scale_factor;
pub mod simulate;
pub mod thermal;
