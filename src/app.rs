//! The application both boards run: rates, coefficient records and the frame
//! path (closure output -> frame -> scale-factor table -> queue to the main
//! loop). The boards differ only in where samples come from and go to.

use gyro_coeffs::fog_scale_factor::RECORD_LEN as FOG_SF_RECORD_LEN;
use gyro_coeffs::rlg_thermal::RECORD_LEN as RLG_RECORD_LEN;
use gyro_sp::fog::scale_factor::{ScaleFactorComp, ScaleFactorConfig};
use gyro_sp::fog::ClosureOutput;
use gyro_sp::frame::{Frame, FrameBuilder};
use gyro_sp::rlg::RlgWords;
use heapless::spsc::{Producer, Queue};

/// Frames the main loop has not yet sent (about 16 ms at 500 Hz).
pub const FRAME_QUEUE_LEN: usize = 8;
/// Frames from the closure interrupt to the main loop.
pub type FrameQueue = Queue<Frame, FRAME_QUEUE_LEN>;

/// FOG closure rate, Hz: one closure interrupt per modulation period.
pub const CLOSURE_HZ: u32 = 12_500;
/// Closures per output frame: 25 at 12.5 kHz gives 500 frames/s (22 kB/s).
pub const CLOSURES_PER_FRAME: u16 = 25;
/// RLG update interrupt rate (counter read + compensation), Hz: one per frame.
pub const RLG_HZ: u32 = 500;
const _: () = assert!(CLOSURE_HZ / CLOSURES_PER_FRAME as u32 == RLG_HZ);
/// Temperature sensors are read every this many RLG updates (10 Hz).
pub const SENSOR_EVERY: u32 = 50;

/// The RLG thermal coefficient record, built from the coefficient file by
/// build.rs (`RLG_COEFFS`); checked (CRC, version, ranges) at start.
pub static RLG_RECORD: [u8; RLG_RECORD_LEN] =
    *include_bytes!(concat!(env!("OUT_DIR"), "/rlg_coeffs.bin"));

/// The FOG scale-factor table's record, built from its coefficient file by
/// build.rs (`FOG_SF_COEFFS`); checked at start.
pub static FOG_SF_RECORD: [u8; FOG_SF_RECORD_LEN] =
    *include_bytes!(concat!(env!("OUT_DIR"), "/fog_sf_coeffs.bin"));

/// The closure interrupt's output side: frames assembled from the closure
/// outputs, the scale-factor table applied to each, handed to the main loop.
/// A full queue loses no angle: the frame is folded back into the next.
pub struct FramePath {
    frames: FrameBuilder,
    tx: Producer<'static, Frame, FRAME_QUEUE_LEN>,
    sf_cfg: ScaleFactorConfig,
    sf: ScaleFactorComp,
    closures: u32,
}

impl FramePath {
    pub fn new(
        frames: FrameBuilder,
        tx: Producer<'static, Frame, FRAME_QUEUE_LEN>,
        sf_cfg: ScaleFactorConfig,
    ) -> Self {
        Self {
            frames,
            tx,
            sf_cfg,
            sf: ScaleFactorComp::default(),
            closures: 0,
        }
    }

    /// True when the closure about to be pushed completes a frame: the
    /// caller then gives the frame its RLG words.
    pub fn frame_ends(&self) -> bool {
        self.frames.completes_next()
    }

    /// The RLG counts since the last frame, for the frame being completed.
    pub fn set_rlg(&mut self, w: RlgWords) {
        self.frames.set_rlg(w);
    }

    /// A coil temperature reading (Q8 degC; None: the read failed) advances
    /// the table's state.
    pub fn coil_reading(&mut self, read: Option<i32>) {
        self.sf.update_temperature(&self.sf_cfg, read);
    }

    /// Adds one closure's output; returns the frame it completes, not yet
    /// compensated.
    pub fn push(&mut self, out: &ClosureOutput) -> Option<Frame> {
        self.closures = self.closures.wrapping_add(1);
        self.frames.push(out, self.closures)
    }

    /// Applies the scale-factor table at the coil temperature to a frame.
    pub fn compensate(&self, f: &mut Frame) {
        f.compensate_fog(&self.sf, &self.sf_cfg);
    }

    /// Queues a frame for the main loop, or folds it back into the next.
    pub fn send(&mut self, f: Frame) {
        if let Err(f) = self.tx.enqueue(f) {
            self.frames.restore(f);
        }
    }

    /// A frame to go out first (the board restarted under the watchdog).
    pub fn restore(&mut self, f: Frame) {
        self.frames.restore(f);
    }
}
