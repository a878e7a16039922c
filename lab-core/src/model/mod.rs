//! The behavioural gyro model: the named effects of docs/interfaces.md
//! (effects.rs, on the run's inputs of inputs.rs), a model as a gyro kind
//! with its effects (gyro_model.rs) and its file (file.rs), and the
//! discovery of what a model misses (discovery/); each parameter's domain
//! and physical range (ranges.rs), which follows the gyro's grade
//! (grade.rs).

pub mod discovery;
pub mod effects;
pub mod file;
pub mod grade;
pub mod gyro_kind;
pub mod gyro_model;
pub mod inputs;
pub mod proposal;
pub mod ranges;
pub mod term;
