//! Firmware of the gyro signal processor (STM32F405): the application both
//! boards share, and the thin glue to the chip. All signal processing is in
//! `gyro_sp`; one binary per board in `src/bin/`:
//! - `gyro-fw-qemu` (feature `qemu`): qemu-system-arm `netduinoplus2`, the
//!   gyro simulated on-chip (`gyro_sim`);
//! - `gyro-fw-hw` (feature `hw`): the gyro electronics, flashed with probe-rs.
//!
//! The features only pull in each board's crates (logger, simulator), so both
//! binaries build together (`--features qemu,hw`) and host builds skip them.
#![cfg_attr(not(test), no_std)]

pub mod app;
#[cfg(feature = "hw")]
pub mod i2c;
pub mod overrun;
pub mod reset_cause;
#[cfg(feature = "hw")]
pub mod rlg_timers;
#[cfg(feature = "hw")]
pub mod sampling;
#[cfg(feature = "board")]
pub mod stack;
pub mod timing;
#[cfg(feature = "qemu")]
pub mod uart;
