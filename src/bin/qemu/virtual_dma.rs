//! The ADC's DMA, which QEMU does not model, simulated on TIM2's count.

use crate::{ADC_PER_CLOSURE, RELOAD};
use gyro_fw::overrun::DmaState;

/// The hw board's ADC DMA ping-pong, simulated: one half completes at
/// every SysTick wrap (the closure's period), the first half first. It says
/// what the DMA's flags and NDTR would read when the closure enters, and
/// the periods between completions by a cycle counter (TIM2, free-running
/// on QEMU's virtual clock), as the hw board's cycle counter gives them.
/// A completion's time is the entry's less SysTick's count since its wrap.
/// QEMU's virtual clock is only faithful while the CPU runs: in WFI it
/// follows the host's clock and SysTick's count is skewed after the wake.
/// But an interrupt that wakes an idle CPU was held off by nothing, so such
/// an entry is one period, and its own time is the completion.
pub struct VirtualDma {
    /// TIM2 ticks per SysTick tick (measured at start).
    pub(crate) tim2_per_tick: f32,
    /// TIM2 count of the last completion seen, and completions seen.
    pub(crate) last: u32,
    pub(crate) completions: u64,
}

impl VirtualDma {
    pub(crate) fn new(tim2_per_tick: f32, now: u32) -> Self {
        Self {
            tim2_per_tick,
            last: now,
            completions: 0,
        }
    }

    /// The DMA registers at TIM2 count `now`, SysTick's count `current`
    /// and whether the CPU was asleep, and the periods since the last
    /// completion seen.
    pub(crate) fn read(&mut self, now: u32, current: u32, woke: bool) -> (DmaState, u32) {
        let since_wrap = if woke {
            0
        } else {
            RELOAD.saturating_sub(current)
        };
        let completed = now.wrapping_sub((since_wrap as f32 * self.tim2_per_tick) as u32);
        let period = (RELOAD + 1) as f32 * self.tim2_per_tick;
        let periods = if woke {
            1
        } else {
            // An interrupt means at least one completion.
            ((completed.wrapping_sub(self.last) as f32 / period + 0.5) as u32).max(1)
        };
        self.last = completed;
        self.completions += periods as u64;
        let c = ADC_PER_CLOSURE as u32;
        let into_half = since_wrap * c / (RELOAD + 1);
        // Completion k (from 1): odd fills the first half, even the second;
        // the DMA then writes the other.
        let last_first = self.completions % 2 == 1;
        let written = if last_first { c + into_half } else { into_half };
        let state = DmaState {
            half_done: periods >= 2 || (periods == 1 && last_first),
            full_done: periods >= 2 || (periods == 1 && !last_first),
            error: false,
            remaining: (2 * c - written) as u16,
        };
        (state, periods)
    }
}
