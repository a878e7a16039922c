//! The lab's data files (docs/interfaces.md "Data files"): CSV with one
//! header row and `#` comment lines before it, or the same columns held
//! in memory by a caller (source.rs). Each file kind names its columns
//! once, in its own module; reading checks every cell it uses and places
//! every error at its file, line and column (or row and column).

pub mod allan_file;
pub mod atomic;
pub mod csv_writer;
pub mod dialect;
pub mod fringe_file;
pub mod header;
pub mod read_spec;
pub mod residual_file;
pub mod run_file;
pub mod source;
pub mod table;
pub mod timestamp;
pub mod units;
