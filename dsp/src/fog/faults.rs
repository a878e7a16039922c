//! Fault flags carried in every output frame.

bitflags::bitflags! {
    /// Faults of the FOG closure and the frame path; each has a defined safe
    /// path (see `closure.rs`). Frame bytes 6..8.
    #[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
    pub struct Faults: u16 {
        /// Detector DC below a quarter of nominal: loop and gain held, output held.
        const OPTICAL_POWER_LOW = 1 << 0;
        /// Residual beyond pi/2 for several closures: loop keeps integrating to relock.
        const OUT_OF_LOCK = 1 << 1;
        /// The ADC's analog watchdog fired during the closure: the main loop keeps
        /// running on the error's sign; the 2*pi loop, the AGC and the
        /// epsilon-squared correction pause.
        const ADC_SATURATION = 1 << 2;
        /// Firmware: a frame could not be queued; its closures went into the next frame.
        const QUEUE_FULL = 1 << 3;
        /// Firmware: restarted after a watchdog reset or a hard fault (the
        /// frame's reset cause says which).
        const RESET_RECOVERED = 1 << 4;
        /// Firmware: the sampling overran (a closure ran too late, so the DMA
        /// passed the half it had to read): the frame counts the closures missed.
        const CLOSURE_OVERRUN = 1 << 5;
        /// Firmware: the ADC's DMA reported a transfer error; that closure's
        /// samples were not used.
        const DMA_ERROR = 1 << 6;
    }
}
