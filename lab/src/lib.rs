//! `gyro-lab` as a library: the simulators, estimators and fits behind the
//! subcommands, so that tests call the very code the tool runs.

pub mod error;
pub mod lockin;
pub mod lsq;
pub mod scale_factor;
pub mod simulate;
pub mod table;
pub mod thermal;
