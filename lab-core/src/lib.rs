//! The gyro lab's library: what the `gyro-lab` command line (lab/) and the
//! `gyrolab` Python package (python/) both run, so that both give the
//! same answer.
//!
//! Layers, each using only those below it:
//! - `commands`: the commands as functions (a run in; the JSON, text and
//!   report out), the record checks every command makes;
//! - `bench`: the estimators against the simulators' truth;
//! - `sim`: the simulators; `model`: the gyro model, its effects and the
//!   discovery; `calibration`: thermal, scale factor, lock-in;
//!   `noise`: the Allan analysis; `record`: what a record is (its
//!   units, its stationarity, its sampling), checked against the data;
//! - `data`: the data files and columns in memory; `report`: the HTML/SVG
//!   writer; `numerics`: what calibration, discovery and noise share;
//!   `error`.

// Numeric code walks parallel arrays (taus, estimates, terms) by index.
#![allow(clippy::needless_range_loop)]

pub mod bench;
pub mod calibration;
pub mod commands;
pub mod data;
pub mod error;
pub mod model;
pub mod noise;
pub mod numerics;
pub mod record;
pub mod report;
pub mod sim;
