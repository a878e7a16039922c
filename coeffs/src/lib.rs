//! Calibration coefficients of the gyro signal processor, defined once.
//!
//! - The firmware loads each set as a versioned binary record with a CRC-32
//!   ([`record`]); a record that is corrupt, of another version or out of
//!   the range the fixed-point code holds is refused, and the firmware runs
//!   uncompensated with a flag set.
//! - With feature `std`, [`file`] reads and writes the TOML coefficient
//!   files that `gyro-lab fit` writes and the firmware build embeds.
#![cfg_attr(not(feature = "std"), no_std)]

pub mod fog_scale_factor;
pub mod record;
pub mod rlg_thermal;

#[cfg(feature = "std")]
pub mod file;

pub use fog_scale_factor::ScaleFactorTable;
pub use record::CoeffError;
pub use rlg_thermal::ThermalCoeffs;
