//! The FOG's sampling on the hw board: ADC1 conversions into one ping-pong
//! buffer by DMA2 stream 0, DAC words out of another through SPI1 by DMA2
//! stream 5, each circular over two closures. The half/complete interrupt
//! hands the closure the half just filled and the DAC half just sent
//! (batch processing, as in quartiq's stabilizer).
//!
//! Named PAC fields, because the HAL has no word for these: the circular
//! half/complete DMA ping-pong, the ADC's analog watchdog, the SPI's 16-bit
//! TX DMA with the hardware NSS output, and the sampling timers' master/slave
//! link (register values from `timing.rs`).

use crate::app::{ADC_PER_CLOSURE, CLOSURE_HZ, HALF_PERIODS, SAMPLING_TIMERS};
use crate::overrun::{completion_time, judge, overtaken, periods_elapsed, BufferHalf, DmaState};
use crate::timing::{oc1m, TimerRegs};
use gyro_sp::fog::demod::{AWD_HIGH, AWD_LOW};
use stm32f4::stm32f405 as pac;

/// ADC samples of two closures (the ping-pong), ADC LSB left-aligned.
pub type AdcBuffer = [u16; 2 * ADC_PER_CLOSURE];
/// DAC words of two closures, one per half period.
pub type DacBuffer = [u16; 2 * HALF_PERIODS];

/// The running sampling: what the closure interrupt needs each time.
pub struct Sampling {
    dma: pac::DMA2,
    /// Only the analog watchdog's flag is touched here.
    adc: pac::ADC1,
    adc_buf: *const u16,
    dac_buf: *mut u16,
    /// Cycle count at which the DMA completed the half last taken.
    last_completion: u32,
}

// The buffers are 'static and only the closure task holds this.
unsafe impl Send for Sampling {}

/// One closure's share of the buffers.
pub struct Half<'a> {
    pub adc: &'a [u16],
    pub dac: &'a mut [u16],
    /// The ADC's analog watchdog fired since the last closure.
    pub adc_over_range: bool,
    /// Which half of the ping-pong this is.
    pub which: BufferHalf,
}

/// What one closure interrupt finds.
pub struct Sampled<'a> {
    /// The latest complete closure of samples, if there is one to use.
    pub half: Option<Half<'a>>,
    /// Closures whose samples were overwritten before this interrupt ran.
    pub missed: u32,
    /// The DMA stopped on a transfer error (restarted here).
    pub dma_error: bool,
}

/// Samples per closure, as the DMA counts them.
const PER_CLOSURE: u16 = ADC_PER_CLOSURE as u16;
/// Core cycles per ADC sample and per closure (168 MHz, 800 kHz, 12.5 kHz).
const CYCLES_PER_SAMPLE: u32 = 168_000_000 / (CLOSURE_HZ * ADC_PER_CLOSURE as u32);
const CYCLES_PER_CLOSURE: u32 = CYCLES_PER_SAMPLE * ADC_PER_CLOSURE as u32;
const _: () = assert!(CYCLES_PER_CLOSURE * CLOSURE_HZ == 168_000_000);

impl Sampling {
    /// Sets up both streams (not yet running the timers), the ADC's analog
    /// watchdog, and the SPI's and timers' DMA links. `adc_dr`/`spi_dr`:
    /// the data registers' addresses; the DAC buffer holds valid words.
    pub fn new(
        dma: pac::DMA2,
        adc: pac::ADC1,
        adc_dr: u32,
        spi: &pac::spi1::RegisterBlock,
        adc_buf: &'static mut AdcBuffer,
        dac_buf: &'static mut DacBuffer,
    ) -> Self {
        // SPI1: 16-bit frames were set by the HAL; the NSS output frames
        // each word for the DAC, TX DMA feeds it.
        spi.cr2()
            .modify(|_, w| w.ssoe().set_bit().txdmaen().set_bit());
        // Hardware NSS (the HAL manages NSS in software).
        spi.cr1().modify(|_, w| w.ssm().clear_bit());
        // Analog watchdog on every regular conversion: codes outside the
        // core's window [AWD_LOW, AWD_HIGH) flag the closure, so it does not
        // search 64 samples for rails.
        adc.ltr().write(|w| w.lt().set(AWD_LOW >> 4));
        adc.htr().write(|w| w.ht().set((AWD_HIGH >> 4) - 1));
        adc.cr1().modify(|_, w| w.awden().set_bit());
        // Stream 5 channel 6 (TIM1_UP): memory -> SPI1 DR, circular, one
        // word per half period.
        let s5 = dma.st(5);
        s5.par()
            .write(|w| unsafe { w.pa().bits(spi.dr().as_ptr() as u32) });
        s5.m0ar()
            .write(|w| unsafe { w.m0a().bits(dac_buf.as_ptr() as u32) });
        s5.ndtr().write(|w| w.ndt().set(dac_buf.len() as u16));
        s5.cr().write(|w| {
            w.chsel().set(6);
            w.msize().bits16().psize().bits16();
            w.minc().incremented().circ().enabled();
            w.dir().memory_to_peripheral().en().enabled()
        });
        // Stream 0 channel 0: ADC1 DR -> buffer, circular, half and
        // complete interrupts (one per closure).
        let s0 = dma.st(0);
        s0.par().write(|w| unsafe { w.pa().bits(adc_dr) });
        s0.m0ar()
            .write(|w| unsafe { w.m0a().bits(adc_buf.as_ptr() as u32) });
        s0.ndtr().write(|w| w.ndt().set(adc_buf.len() as u16));
        s0.cr().write(|w| {
            w.chsel().set(0).pl().high();
            w.msize().bits16().psize().bits16();
            w.minc().incremented().circ().enabled();
            w.htie().enabled().tcie().enabled();
            w.dir().peripheral_to_memory().en().enabled()
        });
        Self {
            dma,
            adc,
            adc_buf: adc_buf.as_ptr(),
            dac_buf: dac_buf.as_mut_ptr(),
            last_completion: 0,
        }
    }

    /// In the stream 0 interrupt: reads and clears the flags it saw, and
    /// returns the halves of the latest complete closure (half transfer:
    /// the first, transfer complete: the second), or none, with the
    /// closures missed (`overrun::judge`, with the periods between the
    /// DMA's completion times by the cycle counter `now`, read at entry).
    /// A transfer error stops the stream in hardware: it is restarted here.
    #[inline(always)]
    pub fn take_half(&mut self, now: u32) -> Sampled<'_> {
        // Flags first, then the position: a completion between the two
        // reads shows as the DMA past the announced half (counted).
        let lisr = self.dma.lisr().read();
        let state = DmaState {
            half_done: lisr.htif0().is_half(),
            full_done: lisr.tcif0().is_complete(),
            error: lisr.teif0().is_error(),
            remaining: self.dma.st(0).ndtr().read().ndt().bits(),
        };
        let completed = completion_time(now, state.remaining, PER_CLOSURE, CYCLES_PER_SAMPLE);
        let periods = periods_elapsed(
            completed.wrapping_sub(self.last_completion),
            CYCLES_PER_CLOSURE,
        );
        self.last_completion = completed;
        // Clear only what was seen: a flag set since stays for the next.
        self.dma.lifcr().write(|w| {
            if state.half_done {
                w.chtif0().clear();
            }
            if state.full_done {
                w.ctcif0().clear();
            }
            if state.error {
                w.cteif0().clear();
            }
            w.cdmeif0().clear().cfeif0().clear()
        });
        let v = judge(state, PER_CLOSURE, periods);
        if v.dma_error {
            let s0 = self.dma.st(0);
            s0.ndtr().write(|w| w.ndt().set(2 * PER_CLOSURE));
            s0.cr().modify(|_, w| w.en().enabled());
        }
        // The watchdog flag is sticky: read and cleared once per closure (a
        // conversion of the closure now sampling may count with this one;
        // that errs safe).
        let adc_over_range = self.adc.sr().read().awd().is_event();
        self.adc.sr().write(|w| w.awd().clear());
        let half = v.half.map(|which| {
            let (a, d) = match which {
                BufferHalf::First => (0, 0),
                BufferHalf::Second => (ADC_PER_CLOSURE, HALF_PERIODS),
            };
            // SAFETY: both buffers are 'static and the DMA is writing the
            // other half of the ADC buffer (the verdict's half is the
            // complete one) and reading the other half of the DAC buffer;
            // `overtaken` checks that this held while the samples were read.
            unsafe {
                Half {
                    adc: core::slice::from_raw_parts(self.adc_buf.add(a), ADC_PER_CLOSURE),
                    dac: core::slice::from_raw_parts_mut(self.dac_buf.add(d), HALF_PERIODS),
                    adc_over_range,
                    which,
                }
            }
        });
        Sampled {
            half,
            missed: v.missed,
            dma_error: v.dma_error,
        }
    }

    /// Starts the completion clock: `now`, the cycle count when the DMA
    /// starts (one period before its first completion).
    pub fn start_clock(&mut self, now: u32) {
        self.last_completion = now;
    }

    /// After the closure: the DMA has entered `which` (the samples may have
    /// changed while they were read).
    #[inline(always)]
    pub fn overtaken(&self, which: BufferHalf) -> bool {
        overtaken(
            self.dma.st(0).ndtr().read().ndt().bits(),
            which,
            PER_CLOSURE,
        )
    }
}

/// The sampling timers from one timebase (docs/timing.md, `timing.rs`): TIM1
/// requests one DAC word per update (UDE) and, at the sampling phase after each
/// update, its compare 1 raises OC1REF, its TRGO; that edge starts TIM2 (trigger
/// mode on ITR0 = TIM1_TRGO), whose updates are the ADC's trigger. Register
/// values: `app::SAMPLING_TIMERS`. Call on timers fresh from the HAL (reset
/// through the RCC, not started); `start_timers` then starts both.
pub fn configure_timers(tim1: &pac::tim1::RegisterBlock, tim2: &pac::tim2::RegisterBlock) {
    const R: TimerRegs = SAMPLING_TIMERS;
    // The RCC reset left both prescalers' active registers at 0, so PSC = 0
    // needs no update event to load. Another prescaler would, and an update
    // event is a DAC word request on TIM1 (UDE) and an ADC trigger on TIM2
    // (its TRGO): the buffers' framing would slip by one.
    const _: () = assert!(R.tim1.psc == 0 && R.tim2.psc == 0);
    // TIM1 first, while TIM2 ignores its trigger.
    tim1.psc().write(|w| w.psc().set(R.tim1.psc));
    tim1.arr().write(|w| w.arr().set(R.tim1.arr));
    tim1.cnt().write(|w| w.cnt().set(R.tim1.cnt));
    tim1.ccr1().write(|w| w.ccr().set(R.tim1.ccr1));
    // OC1REF low, then set by the first match and held: TRGO's one edge.
    tim1.ccmr1_output()
        .modify(|_, w| w.oc1m().set(oc1m::FORCE_INACTIVE));
    tim1.ccmr1_output().modify(|_, w| w.oc1m().set(R.tim1.oc1m));
    tim1.cr2().modify(|_, w| w.mms().set(R.tim1.mms));
    tim1.dier().modify(|_, w| w.ude().bit(R.tim1.ude));
    tim2.psc().write(|w| w.psc().set(R.tim2.psc));
    tim2.arr().write(|w| w.arr().set(R.tim2.arr));
    tim2.cnt().write(|w| w.cnt().set(R.tim2.cnt));
    tim2.cr2().modify(|_, w| w.mms().set(R.tim2.mms));
    // SAFETY: TS from timer_regs is ITR0 (0b000), a defined selection.
    tim2.smcr().modify(|_, w| unsafe { w.ts().bits(R.tim2.ts) });
    // Last: from here TIM1's TRGO starts TIM2.
    tim2.smcr().modify(|_, w| w.sms().set(R.tim2.sms));
}

/// Starts the sampling: TIM1 counts (first update, DAC word 0, one tick
/// later); its compare starts TIM2 at the sampling phase. No instruction
/// timing enters the phase.
pub fn start_timers(tim1: &pac::tim1::RegisterBlock) {
    tim1.cr1().modify(|_, w| w.cen().set_bit());
}
