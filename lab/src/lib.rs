//! `gyro-lab` as a library: the commands and the code behind them, so that
//! tests call the very code the tool runs.
//!
//! Layers, each using only those below it:
//! - `cli`: the commands (arguments, files, JSON, reports);
//! - `bench`: the estimators against the simulators' truth;
//! - `sim`: the simulators; `model`: the gyro model, its effects and the
//!   discovery; `calibration`: thermal, scale factor, lock-in;
//!   `noise`: the Allan analysis; `record`: what a record is (its
//!   units, its stationarity, its sampling), checked against the data;
//! - `data`: the data files; `report`: the HTML/SVG writer;
//!   `numerics`: what calibration, discovery and noise share; `error`.

// Numeric code walks parallel arrays (taus, estimates, terms) by index.
#![allow(clippy::needless_range_loop)]

pub mod bench;
pub mod calibration;
pub mod cli;
pub mod data;
pub mod error;
pub mod model;
pub mod noise;
pub mod numerics;
pub mod record;
pub mod report;
pub mod sim;
