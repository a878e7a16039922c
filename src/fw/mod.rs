//! Thin hardware glue; all signal processing is in the library (`gyro_sp`).

pub mod stack;
pub mod uart;

#[cfg(feature = "qemu")]
pub mod qemu;

#[cfg(all(feature = "hw", not(feature = "qemu")))]
pub mod hw;

use gyro_sp::frame::Frame;
use heapless::spsc::Queue;

/// Frames from the closure interrupt to the main loop (about 16 ms at 500 Hz).
pub type FrameQueue = Queue<Frame, 8>;

/// Steps per output frame: 25 at 12.5 kHz gives 500 frames/s (22 kB/s).
pub const STEPS_PER_FRAME: u16 = 25;
