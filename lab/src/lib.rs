//! `gyro-lab`, the command line: arguments, files in and out, text and
//! JSON on stdout. What each command finds is gyro_lab_core's
//! (lab-core/), which the Python package calls too.

pub mod cli;
