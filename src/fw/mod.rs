//! Thin hardware glue; all signal processing is in the library (`gyro_sp`).

pub mod stack;
pub mod uart;

#[cfg(feature = "qemu")]
pub mod qemu;

#[cfg(all(feature = "hw", not(feature = "qemu")))]
pub mod hw;
#[cfg(all(feature = "hw", not(feature = "qemu")))]
pub mod i2c;

use gyro_coeffs::fog_scale_factor::RECORD_LEN as FOG_SF_RECORD_LEN;
use gyro_sp::frame::Frame;
use gyro_sp::rlg::coeffs::RECORD_LEN;
use heapless::spsc::Queue;

/// Frames from the closure interrupt to the main loop (about 16 ms at 500 Hz).
pub type FrameQueue = Queue<Frame, 8>;

/// Steps per output frame: 25 at 12.5 kHz gives 500 frames/s (22 kB/s).
pub const STEPS_PER_FRAME: u16 = 25;

/// RLG update interrupt rate (counter read + compensation), Hz.
pub const RLG_HZ: u32 = 500;
/// Temperature sensors are read every this many RLG updates (10 Hz).
pub const SENSOR_EVERY: u32 = 50;

/// The RLG thermal coefficient record, built from the coefficient file by
/// build.rs (`RLG_COEFFS`); checked (CRC, version, ranges) at start.
pub static RLG_RECORD: [u8; RECORD_LEN] =
    *include_bytes!(concat!(env!("OUT_DIR"), "/rlg_coeffs.bin"));

/// The FOG scale-factor table's record, built from its coefficient file by
/// build.rs (`FOG_SF_COEFFS`); checked at start.
pub static FOG_SF_RECORD: [u8; FOG_SF_RECORD_LEN] =
    *include_bytes!(concat!(env!("OUT_DIR"), "/fog_sf_coeffs.bin"));
