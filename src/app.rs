//! The application both boards run: rates, coefficient records and the frame
//! path (closure output -> frame -> scale-factor table -> queue to the main
//! loop). The boards differ only in where samples come from and go to.

use gyro_coeffs::fog_scale_factor::RECORD_LEN as FOG_SF_RECORD_LEN;
use gyro_coeffs::rlg_thermal::RECORD_LEN as RLG_RECORD_LEN;
use gyro_sp::fog::scale_factor::{ScaleFactorComp, ScaleFactorConfig};
use gyro_sp::fog::Faults;
use gyro_sp::fog::{ClosureOutput, FogParams, MAX_HALF, MAX_SAMPLES_PER_HALF};
use gyro_sp::frame::{AngleTotals, Frame, FrameBuilder, ResetCause};
use gyro_sp::rlg::RlgWords;
use heapless::spsc::{Producer, Queue};

use crate::timing::{self, TimerRegs, TimingSpec, TIM1_CLK_HZ, TIM2_CLK_HZ};

/// Frames the main loop has not yet sent (about 16 ms at 500 Hz).
pub const FRAME_QUEUE_LEN: usize = 8;
/// Frames from the closure interrupt to the main loop.
pub type FrameQueue = Queue<Frame, FRAME_QUEUE_LEN>;

/// RLG frame words from the RLG update task to the closure: the RLG task
/// never takes a lock the closure needs.
pub const RLG_QUEUE_LEN: usize = 4;
pub type RlgQueue = Queue<RlgWords, RLG_QUEUE_LEN>;

/// FOG closure rate, Hz: one closure interrupt per modulation period.
pub const CLOSURE_HZ: u32 = 12_500;
/// The FOG layout, which also sizes the hw board's DMA buffers: half
/// periods of the bias modulation per closure (12.5 kHz x 16 = 200 kHz, tau
/// = 5 us, the reference coil's transit time) and ADC samples per half period.
pub const HALF_PERIODS: usize = 16;
pub const SAMPLES_PER_HALF: usize = 4;
/// ADC samples per closure.
pub const ADC_PER_CLOSURE: usize = HALF_PERIODS * SAMPLES_PER_HALF;
// Whole +-phi0 pairs in each half of a closure, within the core's buffers.
const _: () = assert!(
    HALF_PERIODS.is_multiple_of(4)
        && HALF_PERIODS <= MAX_HALF
        && SAMPLES_PER_HALF <= MAX_SAMPLES_PER_HALF
);
/// The hw board's sampling phase: TIM1 ticks (168 MHz, 5.95 ns) from a DAC
/// word's update to the compare that starts the ADC's sample train, whose
/// first sample of each half period is the skipped one. 233 ticks (1.387 us;
/// the ADC holds 0.274 us later) is the middle of the chain's window
/// 0.933..1.838 us (`timing::BOARD_CHAIN`, docs/timing.md): the first kept
/// sample after a 2*pi reset's transient has settled, the last before the next
/// edge. Trim it here (with the chain's measured delays).
pub const SAMPLING_PHASE_TICKS: u32 = 233;
/// TIM1 ticks per half period.
pub const TIM1_TICKS_PER_HALF: u32 = TIM1_CLK_HZ / (CLOSURE_HZ * HALF_PERIODS as u32);
const _: () = assert!(SAMPLING_PHASE_TICKS < TIM1_TICKS_PER_HALF);
/// Both sampling timers' register values (`timing::timer_regs`; a timing the
/// timers cannot make fails the build here).
pub const SAMPLING_TIMERS: TimerRegs = match timing::timer_regs(&TimingSpec {
    tim1_clk_hz: TIM1_CLK_HZ,
    tim2_clk_hz: TIM2_CLK_HZ,
    half_period_hz: CLOSURE_HZ * HALF_PERIODS as u32,
    samples_per_half: SAMPLES_PER_HALF as u32,
    phase_ticks: SAMPLING_PHASE_TICKS,
}) {
    Ok(r) => r,
    Err(_) => panic!("the sampling timers cannot make this timing"),
};

/// The FOG parameters of both boards: the reference instrument with this
/// layout, and `dac_latency` closures of DAC latency (the hw ping-pong: 1).
pub fn fog_params(dac_latency: u32) -> FogParams {
    FogParams {
        closure_hz: CLOSURE_HZ as f64,
        tau_s: 1.0 / (CLOSURE_HZ as f64 * HALF_PERIODS as f64),
        samples_per_half: SAMPLES_PER_HALF,
        dac_latency,
        ..FogParams::default()
    }
}

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
/// outputs, the scale-factor table applied to each, handed to the main loop
/// with cumulative angle words. A full queue loses no angle: the frame is
/// folded back into the next.
pub struct FramePath {
    frames: FrameBuilder,
    tx: Producer<'static, Frame, FRAME_QUEUE_LEN>,
    /// In its own static: a 64-node table (about 1.8 kB) is not moved
    /// through the start-up stack with the rest of the frame path.
    sf_cfg: &'static ScaleFactorConfig,
    sf: ScaleFactorComp,
    /// Closure periods since start, missed ones included: the frames' time base.
    closures: u32,
    /// The angle words of the frames sent so far.
    totals: AngleTotals,
}

impl FramePath {
    /// `reset_cause`: why the board started, said by the first frame.
    pub fn new(
        frames: FrameBuilder,
        tx: Producer<'static, Frame, FRAME_QUEUE_LEN>,
        sf_cfg: &'static ScaleFactorConfig,
        reset_cause: ResetCause,
    ) -> Self {
        let mut frames = frames;
        frames.set_reset_cause(reset_cause);
        Self {
            frames,
            tx,
            sf_cfg,
            sf: ScaleFactorComp::default(),
            closures: 0,
            totals: AngleTotals::default(),
        }
    }

    /// Closure periods the sampling overran (their samples overwritten,
    /// their angle lost) before the next closure: counted in the frame and
    /// in the time base, flagged with `faults`.
    pub fn lost(&mut self, missed: u32, faults: Faults) {
        self.closures = self.closures.wrapping_add(missed);
        self.frames.lost_closures(missed, faults);
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
        self.sf.update_temperature(self.sf_cfg, read);
    }

    /// Adds one closure's output; returns the frame it completes, not yet
    /// compensated.
    pub fn push(&mut self, out: &ClosureOutput) -> Option<Frame> {
        self.closures = self.closures.wrapping_add(1);
        self.frames.push(out, self.closures)
    }

    /// Applies the scale-factor table at the coil temperature to a frame.
    pub fn compensate(&self, f: &mut Frame) {
        f.compensate_fog(&self.sf, self.sf_cfg);
    }

    /// Queues a frame for the main loop with its angle words made
    /// cumulative, or folds it back into the next.
    pub fn send(&mut self, f: Frame) {
        let (wire, after) = self.totals.stamp(&f);
        match self.tx.enqueue(wire) {
            Ok(()) => self.totals = after,
            Err(_) => self.frames.restore(f),
        }
    }
}
