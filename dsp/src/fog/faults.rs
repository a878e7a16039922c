//! Fault flags carried in every output frame.

/// Bit set of faults; each bit has a defined safe path (see `closure.rs`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Faults(pub u16);

impl Faults {
    /// Detector DC below a quarter of nominal: loop and gain held, output held.
    pub const OPTICAL_POWER_LOW: u16 = 1 << 0;
    /// Residual beyond pi/2 for several closures: loop keeps integrating to relock.
    pub const OUT_OF_LOCK: u16 = 1 << 1;
    /// The ADC's analog watchdog fired during the closure: the main loop keeps
    /// running on the error's sign; the 2*pi loop, the AGC and the
    /// epsilon-squared correction pause.
    pub const ADC_SATURATION: u16 = 1 << 2;
    /// Firmware: a frame could not be queued; its closures went into the next frame.
    pub const QUEUE_FULL: u16 = 1 << 3;
    /// Firmware: recovered from a panic or watchdog reset.
    pub const RESET_RECOVERED: u16 = 1 << 4;

    pub fn set(&mut self, bit: u16, on: bool) {
        if on {
            self.0 |= bit;
        } else {
            self.0 &= !bit;
        }
    }
    pub fn has(self, bit: u16) -> bool {
        self.0 & bit != 0
    }
}
