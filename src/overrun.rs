//! Did the closure keep up with the ADC's DMA ping-pong? A pure decision
//! over the register values (no PAC types), so it is tested on the host and
//! the QEMU board runs it on a simulated DMA.
//!
//! The DMA fills a circular buffer of two closures; its half-transfer and
//! transfer-complete flags each say "one closure's samples are complete",
//! and NDTR (remaining transfers) says where it writes now. A closure that
//! runs late finds both flags pending, or the DMA already past the half it
//! should read: the samples of at least one closure were overwritten, and
//! their angle is lost. Nothing here hides that: the verdict says which half
//! is complete, how many closures were missed, and whether the DMA failed.

/// What the closure interrupt reads from the ADC's DMA stream at entry.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct DmaState {
    /// Half-transfer flag (HTIF): the first half was filled.
    pub half_done: bool,
    /// Transfer-complete flag (TCIF): the second half was filled.
    pub full_done: bool,
    /// Transfer-error flag (TEIF); the hardware then stops the stream.
    pub error: bool,
    /// NDTR: transfers left before the buffer wraps (1..=2 closures of
    /// samples; 0 reads as a stopped stream).
    pub remaining: u16,
}

/// A half of the two-closure buffer.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BufferHalf {
    First,
    Second,
}

/// What the closure should do with this interrupt.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Verdict {
    /// The half holding the latest complete closure of samples; `None` when
    /// there is none to use (a spurious interrupt, or a transfer error).
    pub half: Option<BufferHalf>,
    /// Closures whose samples were overwritten before this interrupt ran.
    pub missed: u32,
    /// The DMA reported a transfer error (the stream must be restarted).
    pub dma_error: bool,
}

/// The verdict at the closure's entry. `per_closure`: samples in one half;
/// `periods`: closure periods between the last two completion times
/// ([`completion_time`], [`periods_elapsed`]) where the board has a cycle
/// counter (1 on time; 0 when unknown), which counts misses beyond the one
/// the flags can show.
pub const fn judge(s: DmaState, per_closure: u16, periods: u32) -> Verdict {
    let len = 2 * per_closure as u32;
    let remaining = if s.remaining == 0 || s.remaining as u32 > len {
        len
    } else {
        s.remaining as u32
    };
    // The DMA writes sample `len - remaining` now; the other half is the
    // latest complete one.
    let writing_first = len - remaining < per_closure as u32;
    let complete = if writing_first {
        BufferHalf::Second
    } else {
        BufferHalf::First
    };
    let by_flags = match (s.half_done, s.full_done) {
        (false, false) => 0,
        // One flag: on time if the DMA writes the other half; if it has
        // moved on into the half the flag announced, a closure went by.
        (true, false) => writing_first as u32,
        (false, true) => !writing_first as u32,
        // Both: two completions behind one interrupt.
        (true, true) => 1,
    };
    let by_time = periods.saturating_sub(1);
    let missed = if by_time > by_flags {
        by_time
    } else {
        by_flags
    };
    let half = if s.error || !(s.half_done || s.full_done) {
        None
    } else {
        Some(complete)
    };
    Verdict {
        half,
        // A transfer error loses the closure being sampled.
        missed: missed + s.error as u32,
        dma_error: s.error,
    }
}

/// After the closure has read `half`: true when the DMA (at `remaining`)
/// is already writing into it, so the samples may have changed while they
/// were read (the closure ran too long).
pub const fn overtaken(remaining: u16, half: BufferHalf, per_closure: u16) -> bool {
    let len = 2 * per_closure as u32;
    let remaining = if remaining == 0 || remaining as u32 > len {
        len
    } else {
        remaining as u32
    };
    let writing_first = len - remaining < per_closure as u32;
    matches!(
        (half, writing_first),
        (BufferHalf::First, true) | (BufferHalf::Second, false)
    )
}

/// The time (cycles) the DMA completed the half it is past: `now` less
/// the samples it has written into the half it writes (`remaining` as in
/// [`DmaState`]), so that intervals between completions are whole periods
/// however late the interrupt ran.
pub const fn completion_time(
    now: u32,
    remaining: u16,
    per_closure: u16,
    cycles_per_sample: u32,
) -> u32 {
    let len = 2 * per_closure as u32;
    let remaining = if remaining == 0 || remaining as u32 > len {
        len
    } else {
        remaining as u32
    };
    let into_half = (len - remaining) % per_closure as u32;
    now.wrapping_sub(into_half * cycles_per_sample)
}

/// Closure periods in `elapsed` cycles of `period` cycles each, rounded
/// (between completion times the error is a few register reads).
pub const fn periods_elapsed(elapsed: u32, period: u32) -> u32 {
    match elapsed.saturating_add(period / 2).checked_div(period) {
        Some(n) => n,
        None => 0,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const C: u16 = 64;

    fn state(half_done: bool, full_done: bool, written: u16) -> DmaState {
        DmaState {
            half_done,
            full_done,
            error: false,
            remaining: 2 * C - written,
        }
    }

    /// On time: the half-transfer interrupt finds the DMA in the second
    /// half and takes the first; the complete interrupt the reverse.
    #[test]
    fn on_time_closures_take_the_completed_half() {
        for written in C..2 * C {
            let v = judge(state(true, false, written), C, 1);
            assert_eq!(v.half, Some(BufferHalf::First));
            assert_eq!((v.missed, v.dma_error), (0, false));
        }
        for written in 0..C {
            let v = judge(state(false, true, written), C, 1);
            assert_eq!(v.half, Some(BufferHalf::Second));
            assert_eq!(v.missed, 0);
        }
        // NDTR reads 2C right after the reload.
        let v = judge(state(false, true, 0), C, 0);
        assert_eq!((v.half, v.missed), (Some(BufferHalf::Second), 0));
    }

    /// A late interrupt: both flags pending, or one flag with the DMA past
    /// the half it announced. One closure missed; the latest complete half
    /// is taken.
    #[test]
    fn late_closures_are_counted() {
        // Half-transfer then complete both pending: the DMA refills the
        // first half, the second is the latest complete.
        let v = judge(state(true, true, 10), C, 0);
        assert_eq!((v.half, v.missed), (Some(BufferHalf::Second), 1));
        let v = judge(state(true, true, C + 3), C, 0);
        assert_eq!((v.half, v.missed), (Some(BufferHalf::First), 1));
        // Only the half flag, but the DMA already wrapped into the first half.
        let v = judge(state(true, false, 5), C, 0);
        assert_eq!((v.half, v.missed), (Some(BufferHalf::Second), 1));
        let v = judge(state(false, true, C + 5), C, 0);
        assert_eq!((v.half, v.missed), (Some(BufferHalf::First), 1));
    }

    /// The cycle counter counts what the flags cannot: a closure three
    /// periods late missed two.
    #[test]
    fn periods_count_long_stalls() {
        let v = judge(state(true, true, 10), C, 3);
        assert_eq!(v.missed, 2);
        let v = judge(state(true, false, C + 1), C, 1);
        assert_eq!(v.missed, 0);
        assert_eq!(periods_elapsed(13_440, 13_440), 1);
        assert_eq!(periods_elapsed(13_440 * 5 / 2 - 1, 13_440), 2);
        assert_eq!(periods_elapsed(40_320, 13_440), 3);
        assert_eq!(periods_elapsed(123, 0), 0);
    }

    /// A transfer error: no half to use, the closure counted as missed.
    /// A spurious interrupt (no flag): nothing to do, nothing missed.
    #[test]
    fn errors_and_spurious_interrupts() {
        let v = judge(
            DmaState {
                error: true,
                ..state(true, false, C + 1)
            },
            C,
            1,
        );
        assert_eq!((v.half, v.missed, v.dma_error), (None, 1, true));
        let v = judge(state(false, false, 7), C, 1);
        assert_eq!((v.half, v.missed, v.dma_error), (None, 0, false));
        // A stopped stream (NDTR 0) or a nonsense count reads as position 0.
        for remaining in [0, 2 * C + 1, u16::MAX] {
            let s = DmaState {
                remaining,
                ..state(false, true, 0)
            };
            assert_eq!(judge(s, C, 1).half, Some(BufferHalf::Second));
        }
    }

    /// Completion times are whole periods apart however late the
    /// interrupt enters: an entry 2.5 periods after the last completion
    /// with the DMA a half period into its half is 2 periods (one missed).
    #[test]
    fn completion_times_ignore_entry_latency() {
        let (p, per_sample) = (13_440u32, 210u32);
        let last = completion_time(1_000 + 5 * per_sample, 2 * C - (C + 5), C, per_sample);
        assert_eq!(last, 1_000);
        let now = 1_000 + 2 * p + p / 2;
        let t = completion_time(now, 2 * C - C / 2, C, per_sample);
        assert_eq!(t, 1_000 + 2 * p);
        assert_eq!(periods_elapsed(t.wrapping_sub(last), p), 2);
        // Across the counter's wrap.
        let t = completion_time(5, C, C, per_sample);
        assert_eq!(t, 5u32.wrapping_sub(0));
        assert_eq!(
            completion_time(5, C - 1, C, per_sample),
            5u32.wrapping_sub(per_sample)
        );
    }

    #[test]
    fn overtaken_when_the_dma_enters_the_half_read() {
        assert!(!overtaken(2 * C - (C + 10), BufferHalf::First, C));
        assert!(overtaken(2 * C - 3, BufferHalf::First, C));
        assert!(!overtaken(2 * C - 3, BufferHalf::Second, C));
        assert!(overtaken(2 * C - (C + 1), BufferHalf::Second, C));
    }
}
