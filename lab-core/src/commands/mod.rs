//! The commands as functions: a run (a file, or columns a caller holds) in,
//! what the command found out, as the JSON object, the text and the report
//! every face of the lab gives. The CLI (lab/) adds the arguments and the
//! files it writes; Python (python/) the arrays and the notebook's view.
//! Both call these, so both give the same answer. Nothing here prints or
//! writes a file.

pub mod adev_plot;
pub mod allan;
pub mod checks;
pub mod compensate;
pub mod discover;
pub mod fit_scale_factor;
pub mod fit_thermal;
pub mod frames;
pub mod lockin;
pub mod model_file;
pub mod reports;
pub mod run_inputs;
pub mod simulate_run;
