//! Gyro signal processor: the hardware-free DSP core shared by the firmware,
//! the host tests and the `gyro-lab` tool.
//!
//! Everything here is `no_std`, allocation-free and free of defmt, so the code
//! the host tests exercise is the code that runs in the MCU's interrupts.
//!
//! Fixed-point conventions used throughout:
//! - [`Phase`]: `u32`, one full turn (2*pi rad) is 2^32 LSB, wrapping on purpose.
//! - ADC samples: `u16`, full scale 65 536 LSB (a 12-bit ADC is left-aligned).
//! - Modulator DAC codes: `u16`.
#![cfg_attr(not(test), no_std)]

pub mod derivative;
pub mod fog;
pub mod frame;
pub mod rlg;
pub mod sensor;

/// Phase with one turn = 2^32 LSB (wrapping arithmetic is the 2*pi reset).
pub type Phase = u32;

/// Radians per [`Phase`] LSB.
pub const RAD_PER_PHASE_LSB: f64 = core::f64::consts::TAU / 4_294_967_296.0;

/// Converts radians to phase LSB (rounded, wrapping to one turn).
pub fn phase_from_rad(rad: f64) -> Phase {
    let turns = rad / core::f64::consts::TAU;
    let frac = turns - libm_floor(turns);
    (frac * 4_294_967_296.0 + 0.5) as u64 as u32
}

fn libm_floor(x: f64) -> f64 {
    num_traits::float::Float::floor(x)
}
