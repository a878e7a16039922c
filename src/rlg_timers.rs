//! The RLG's timers on the hw board (docs/rlg.md): the encoder counter with
//! its hardware latch at the dither pickoff's zero crossings, and the
//! free-running clock that times the latches and the updates.
//!
//! - TIM3 (16 bit): encoder mode 3 (x4 quadrature edges) on PC6/PC7 (TI1,
//!   TI2, AF2, input filter 8 samples). The pickoff comparator on PC8 (TI3,
//!   AF2) captures CNT into CCR3 on its rising edge (IC3 on TI3) and into
//!   CCR4 on its falling edge (IC4 on TI3, the pairing of PWM-input mode):
//!   the count at each crossing is latched by the hardware, whatever the
//!   interrupt's latency.
//! - TIM5 (32 bit, 84 MHz, free running: wraps every 51 s): the same
//!   pickoff on PA1 (TI2, AF2) captures the crossing's time into CCR2 on
//!   both edges; CH1 compares at the RLG update rate (CCR1 advanced by one
//!   period per update, so the updates do not drift with the interrupt's
//!   latency). One tick is 1/84 us.
//!
//! Pins: TIM4's CH3/CH4 (PB8/PB9, where a latch on the encoder's own timer
//! would sit) are I2C1's; TIM3 has all four channels on PC6..PC9, free on
//! the STM32F405.

use stm32f4::stm32f405 as pac;

/// TIM5's clock (APB1 timers: 2 x 42 MHz), Hz.
pub const CLOCK_HZ: u32 = 84_000_000;

/// One latch the interrupt found: the count at the crossing, its polarity
/// (rising: the pickoff went high), and whether the capture overran (a
/// crossing lost before this one was read).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Latched {
    pub counter: u16,
    pub rising: bool,
    pub overrun: bool,
}

/// Configures TIM3 as the encoder with its latch channels (the clock must be
/// on, the pins in AF2); starts counting. Latch interrupts enabled.
pub fn configure_encoder(tim3: &pac::tim3::RegisterBlock) {
    tim3.cr1().modify(|_, w| w.cen().clear_bit());
    tim3.arr().write(|w| w.arr().set(0xFFFF));
    tim3.ccmr1_input().write(|w| {
        w.cc1s()
            .ti1()
            .cc2s()
            .ti2()
            .ic1f()
            .set(0b0011)
            .ic2f()
            .set(0b0011)
    });
    tim3.ccmr2_input()
        .write(|w| w.cc3s().ti3().cc4s().ti3().ic3f().set(0b0011));
    // CC3: rising edges of TI3; CC4: falling (CC4P inverts TI3FP4).
    tim3.ccer().write(|w| {
        w.cc3e()
            .set_bit()
            .cc3p()
            .clear_bit()
            .cc4e()
            .set_bit()
            .cc4p()
            .set_bit()
    });
    tim3.smcr().modify(|_, w| w.sms().encoder_mode_3());
    tim3.sr().write(|w| unsafe { w.bits(0) });
    tim3.dier().write(|w| w.cc3ie().set_bit().cc4ie().set_bit());
    tim3.cr1().modify(|_, w| w.cen().set_bit());
}

/// Configures TIM5 as the free-running latch clock with the update
/// compare every `period` ticks; starts it. Update interrupt (CC1) enabled.
pub fn configure_clock(tim5: &pac::tim5::RegisterBlock, period: u32) {
    tim5.cr1().modify(|_, w| w.cen().clear_bit());
    tim5.psc().write(|w| w.psc().set(0));
    tim5.arr().write(|w| w.arr().set(u32::MAX));
    // CH1: frozen output compare (no pin); CH2: input capture of TI2.
    tim5.ccmr1_input()
        .write(|w| w.cc2s().ti2().ic2f().set(0b0011));
    tim5.ccer()
        .write(|w| w.cc2e().set_bit().cc2p().set_bit().cc2np().set_bit());
    tim5.egr().write(|w| w.ug().set_bit());
    tim5.ccr1().write(|w| w.ccr().set(period));
    tim5.sr().write(|w| unsafe { w.bits(0) });
    tim5.dier().write(|w| w.cc1ie().set_bit());
    tim5.cr1().modify(|_, w| w.cen().set_bit());
}

/// The update interrupt: clears its flag, schedules the next compare one
/// `period` after this one; returns the clock now and the encoder counter,
/// read back to back (the instant the update's count stands for).
#[inline(always)]
pub fn update_read(
    tim5: &pac::tim5::RegisterBlock,
    tim3: &pac::tim3::RegisterBlock,
    period: u32,
) -> (u32, u16) {
    tim5.sr().write(|w| unsafe { w.bits(!(1 << 1)) });
    let next = tim5.ccr1().read().ccr().bits().wrapping_add(period);
    tim5.ccr1().write(|w| w.ccr().set(next));
    let counter = tim3.cnt().read().cnt().bits();
    let time = tim5.cnt().read().cnt().bits();
    (time, counter)
}

/// The latch interrupt: the pending latches (rising first, then falling;
/// both pending means the interrupt came late and the second is refused by
/// the stripping as out of order or too soon, flagged) and the crossing's
/// time from TIM5's capture. Reading a CCR clears its flag.
#[inline(always)]
pub fn latch_read(
    tim3: &pac::tim3::RegisterBlock,
    tim5: &pac::tim5::RegisterBlock,
) -> (u32, [Option<Latched>; 2]) {
    let sr = tim3.sr().read();
    let time_overrun = tim5.sr().read().cc2of().bit_is_set();
    let time = tim5.ccr2().read().ccr().bits();
    let overrun3 = sr.cc3of().bit_is_set() || time_overrun;
    let overrun4 = sr.cc4of().bit_is_set() || time_overrun;
    if overrun3 || overrun4 {
        // Overcapture flags are cleared by writing 0 (rc_w0).
        tim3.sr()
            .write(|w| unsafe { w.bits(!((1 << 11) | (1 << 12))) });
        tim5.sr().write(|w| unsafe { w.bits(!(1 << 10)) });
    }
    let rise = sr.cc3if().bit_is_set().then(|| Latched {
        counter: tim3.ccr3().read().ccr().bits(),
        rising: true,
        overrun: overrun3,
    });
    let fall = sr.cc4if().bit_is_set().then(|| Latched {
        counter: tim3.ccr4().read().ccr().bits(),
        rising: false,
        overrun: overrun4,
    });
    (time, [rise, fall])
}
