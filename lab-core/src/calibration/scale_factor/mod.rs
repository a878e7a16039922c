//! FOG scale factor over temperature from a calibration run (docs/fog.md).
//!
//! Model, per sample: `y - w = w * s(T) + b(T)`, with w the reference rate,
//! y the output (nominal scale factor), s the scale-factor error (relative),
//! b the bias. T is the coil temperature, estimated from the coil sensor by
//! the firmware's own blocks as `T_sensor + lag * dT_sensor/dt` (input.rs).
//!
//! - Continuous rotation (continuous.rs, on the model of
//!   continuous_model.rs over the bins of bins.rs, with the intervals of
//!   intervals.rs).
//! - Multi-point (multipoint.rs).
//!
//! fit.rs chooses between them; families.rs scores the continuous fit's
//! model families (knees, polynomial, polynomial with knees) by one
//! criterion; tabulate.rs makes any of them the firmware's table;
//! compensation.rs applies a table as the firmware does (validation.rs
//! judges the result on a run); residual.rs is
//! the figure both are judged by; warnings.rs what a fit warns about;
//! diagnostics.rs the figures a report plots.

pub mod bins;
pub mod compensation;
pub mod continuous;
pub mod continuous_model;
pub mod diagnostics;
pub mod families;
pub mod fit;
pub mod input;
pub mod intervals;
pub mod multipoint;
pub mod residual;
pub mod result;
pub mod tabulate;
pub mod validation;
pub mod warnings;
