//! The project's verification instruments, apart from what a user installs
//! (`cargo install --path lab`): generators written independently of the
//! lab's simulators, and the benches that score discovery on what they
//! write, against their truth.
//!
//! - `sim`: the second generator (heldout_run/, issue 22), a third
//!   written apart from both (third_run/, issue 31), and the outside
//!   generator of terms beyond discovery's library (outside_run/, issue
//!   35);
//! - `bench`: the scoring of discovery on them (discover_heldout.rs,
//!   discover_outside.rs);
//! - `cli`: `gyro-instruments simulate heldout|outside` and `gyro-instruments
//!   bench discover-heldout|discover-outside`.
//!
//! `compositions/generate.py` is a fifth generator, in Python, of
//! compositions of effects (issue 39).

// Numeric code walks parallel arrays by index.
#![allow(clippy::needless_range_loop)]

pub mod bench;
pub mod cli;
pub mod sim;
