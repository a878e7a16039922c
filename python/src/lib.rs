//! `gyrolab._native`: the gyro lab's commands for Python, over the very
//! code the `gyro-lab` command line runs (gyro_lab_core's commands). The
//! Python half (python/gyrolab) turns what users hold (paths, dicts of
//! arrays, pandas DataFrames) into the columns read here, and the answers
//! into `gyrolab.Result`.
//!
//! Every call releases the GIL while it works, reads numpy's float64
//! arrays where they lie, and turns a bad input into `ValueError` with the
//! command line's message; a panic would be a bug, and comes back as
//! `RuntimeError`, never as a Rust panic through Python.

mod commands;
mod inputs;
mod outcome;

use pyo3::prelude::*;

#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<outcome::Native>()?;
    m.add_function(wrap_pyfunction!(commands::read_run, m)?)?;
    m.add_function(wrap_pyfunction!(commands::allan, m)?)?;
    m.add_function(wrap_pyfunction!(commands::discover, m)?)?;
    m.add_function(wrap_pyfunction!(commands::fit_thermal, m)?)?;
    m.add_function(wrap_pyfunction!(commands::fit_scale_factor, m)?)?;
    m.add_function(wrap_pyfunction!(commands::compensate, m)?)?;
    m.add_function(wrap_pyfunction!(commands::lockin, m)?)?;
    m.add_function(wrap_pyfunction!(commands::simulate_run, m)?)?;
    m.add_function(wrap_pyfunction!(commands::decode_frames, m)?)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
