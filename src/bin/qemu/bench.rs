//! The closure's and the RLG update's timings, in SysTick ticks.

use crate::RELOAD;

/// SysTick ticks of timed sections: mean and worst.
#[derive(Clone, Copy, Default)]
pub struct Bench {
    pub(crate) ticks_sum: u64,
    pub(crate) ticks_max: u32,
    pub(crate) n: u32,
}

impl Bench {
    /// One timed section between two SysTick reads.
    pub(crate) fn record(&mut self, t0: u32, t1: u32) {
        self.add(ticks_between(t0, t1));
    }

    pub(crate) fn add(&mut self, ticks: u32) {
        self.ticks_sum += ticks as u64;
        self.ticks_max = self.ticks_max.max(ticks);
        self.n += 1;
    }

    /// (mean, max) in instructions.
    pub(crate) fn instructions(&self, ipt: f32) -> (u32, u32) {
        (
            (self.ticks_sum as f32 / self.n.max(1) as f32 * ipt) as u32,
            (self.ticks_max as f32 * ipt) as u32,
        )
    }
}

/// SysTick ticks from reading `t0` to reading `t1`: it counts down and
/// reloads at 0, so a reload in between adds RELOAD + 1.
pub(crate) fn ticks_between(t0: u32, t1: u32) -> u32 {
    if t1 <= t0 {
        t0 - t1
    } else {
        t0 + RELOAD + 1 - t1
    }
}

/// What the closure task measures.
#[derive(Clone, Copy, Default)]
pub struct ClosureBenches {
    /// The closure step (the FOG core alone).
    pub(crate) core: Bench,
    /// Scale-factor table per frame and per coil reading.
    pub(crate) sf_frame: Bench,
    pub(crate) sf_sensor: Bench,
    /// The overrun check (`overrun::judge` on the DMA's registers).
    pub(crate) overrun_check: Bench,
    /// Closures missed, and the closure at which the first was seen.
    pub(crate) missed: u32,
    pub(crate) missed_at: u32,
    /// SysTick wrap (the interrupt raised) to the closure's last DAC word,
    /// the simulated optics excluded: closures with the RLG update running
    /// or pending at entry, and those that found the idle loop busy.
    pub(crate) latency_under_rlg: Bench,
    pub(crate) latency_alone: Bench,
    /// Frames that ended without one RLG update's words (the update late),
    /// and the first such frame.
    pub(crate) rlg_late: u32,
    pub(crate) rlg_late_at: u32,
}
