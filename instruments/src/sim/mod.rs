//! Generators written apart from the lab's simulators (lab-core's sim/),
//! so that discovery is scored on records it was not built on.

pub mod heldout_run;
pub mod outside_run;
pub mod third_run;
