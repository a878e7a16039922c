//! The estimators against the simulators' truth, over seeds: lock-in
//! (lockin.rs), scale factor (scale_factor.rs), Allan terms and speed
//! (allan.rs), the eps^2 correction over the vibration envelope (eps2.rs),
//! discovery (discover_trials.rs, discover_categories.rs,
//! discover_summary.rs), the dithered RLG's random walk and rate error
//! (dither.rs). Each returns its figures; the bench command prints them.
//! The held-out benches (other generators) are instruments (instruments/).

pub mod allan;
pub mod discover_categories;
pub mod discover_summary;
pub mod discover_trials;
pub mod dither;
pub mod eps2;
pub mod lockin;
pub mod scale_factor;
