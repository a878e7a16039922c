//! Gyro signal processor: the hardware-free DSP core shared by the firmware,
//! the host tests and the `gyro-lab` tool.
//!
//! Everything here is `no_std`, allocation-free and free of defmt, so the code
//! the host tests exercise is the code that runs in the MCU's interrupts.
//!
//! Fixed-point conventions used throughout:
//! - [`Phase`]: `u32`, one full turn (2*pi rad) is 2^32 LSB, wrapping on purpose
//!   ([`phase`]);
//! - ADC samples: `u16`, full scale 65 536 LSB (a 12-bit ADC is left-aligned);
//! - Modulator DAC codes: `u16`.
#![cfg_attr(not(test), no_std)]

pub mod derivative;
pub mod fixed;
pub mod fog;
pub mod frame;
pub mod phase;
pub mod rlg;
pub mod sensor;

pub use phase::{phase_from_rad, Phase, PHASE_LSB_PER_RAD, RAD_PER_PHASE_LSB};
