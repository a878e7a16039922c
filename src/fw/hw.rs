//! `hw` board: the STM32F405 on the gyro electronics.
//!
//! - Clocks: 8 MHz HSE -> PLL -> 168 MHz core, APB2 84 MHz, APB1 42 MHz.
//! - Detector: ADC1 on PA0, triggered by TIM2 TRGO at 800 kHz (4 samples per
//!   5 us half period), DMA2 stream 0 circular over two closure steps; the
//!   half/complete interrupt runs the closure on the step just sampled (batch
//!   processing, as in quartiq's stabilizer).
//! - Modulator: external 16-bit DAC on SPI1 (PA5 SCK, PA7 MOSI, PA4 NSS); TIM1
//!   update at 200 kHz requests one word per half period through DMA2 stream 5,
//!   circular over two steps. The interrupt writes the half the DMA is not reading.
//!   This ping-pong delays the new step by one closure period (the QEMU and host
//!   rigs apply it on the next step); physics.md's coefficient must be re-derived
//!   for that loop before trusting the epsilon-squared correction on the board.
//! - Frames on USART1 (PA9) at 2 Mbaud; independent watchdog at 100 ms.
//!
//! Registers are written as whole words with the bit meaning in the comment.

use super::{stack, uart, FrameQueue, STEPS_PER_FRAME};
use core::cell::RefCell;
use cortex_m::interrupt::Mutex;
use defmt_rtt as _;
use gyro_sp::fog::demod::{AWD_HIGH, AWD_LOW};
use gyro_sp::fog::{Faults, FogConfig, FogLoop, FogParams};
use gyro_sp::frame::{Frame, FrameBuilder};
use heapless::spsc::Producer;
use stm32f4::stm32f405::{self as pac, interrupt, Interrupt};

const N_HALF: usize = 16;
const N_SAMPLES: usize = 64;

#[link_section = ".uninit.dma"]
static mut ADC_BUF: [u16; 2 * N_SAMPLES] = [0; 2 * N_SAMPLES];
#[link_section = ".uninit.dma"]
static mut DAC_BUF: [u16; 2 * N_HALF] = [0; 2 * N_HALF];

struct Ctx {
    cfg: FogConfig,
    fog: FogLoop,
    frames: FrameBuilder,
    tx: Producer<'static, Frame, 8>,
    counter: u32,
    dma: pac::DMA2,
    adc: pac::ADC1,
}

static CTX: Mutex<RefCell<Option<Ctx>>> = Mutex::new(RefCell::new(None));

pub fn run() -> ! {
    stack::paint();
    let Some(mut cp) = cortex_m::Peripherals::take() else {
        reset()
    };
    let Some(dp) = pac::Peripherals::take() else {
        reset()
    };
    let watchdog_reset = dp.RCC.csr().read().bits() & (1 << 29) != 0; // IWDGRSTF
    dp.RCC
        .csr()
        .modify(|r, w| unsafe { w.bits(r.bits() | (1 << 24)) }); // RMVF
    clocks(&dp);
    // GPIOA: PA0 analog; PA4/5/7 AF5 (SPI1); PA9 AF7 (USART1).
    dp.GPIOA
        .moder()
        .modify(|r, w| unsafe { w.bits((r.bits() & !0x000C_CF03) | 0x0008_8A03) });
    dp.GPIOA
        .ospeedr()
        .modify(|r, w| unsafe { w.bits(r.bits() | 0x000C_CF00) });
    dp.GPIOA
        .afrl()
        .modify(|r, w| unsafe { w.bits((r.bits() & 0x0F00_FFFF) | 0x5055_0000) });
    dp.GPIOA
        .afrh()
        .modify(|r, w| unsafe { w.bits((r.bits() & !0xF0) | 0x70) });
    uart::init(&dp.USART1, 42); // 84 MHz / 2 Mbaud = 42

    let params = FogParams::default();
    let Ok(cfg) = FogConfig::new(params) else {
        reset()
    };
    let mut fog = FogLoop::new(&cfg);
    // Both DAC halves start with valid words.
    let dac = unsafe { &mut *core::ptr::addr_of_mut!(DAC_BUF) };
    let (a, b) = dac.split_at_mut(N_HALF);
    fog.start(&cfg, a);
    b.copy_from_slice(a);

    // SPI1: master, 16-bit, fclk/4 = 21 MHz, NSS output, TX DMA.
    dp.SPI1
        .cr2()
        .write(|w| unsafe { w.bits((1 << 2) | (1 << 1)) }); // SSOE, TXDMAEN
    dp.SPI1
        .cr1()
        .write(|w| unsafe { w.bits((1 << 11) | (1 << 6) | (1 << 3) | (1 << 2)) }); // DFF, SPE, BR=/4, MSTR
                                                                                   // DMA2 stream 5 channel 6 (TIM1_UP): memory -> SPI1 DR, 16 bit, circular.
    let s5 = dp.DMA2.st(5);
    s5.par()
        .write(|w| unsafe { w.bits(dp.SPI1.dr().as_ptr() as u32) });
    s5.m0ar()
        .write(|w| unsafe { w.bits(core::ptr::addr_of!(DAC_BUF) as u32) });
    s5.ndtr().write(|w| unsafe { w.bits((2 * N_HALF) as u32) });
    s5.cr().write(|w| unsafe {
        w.bits((6 << 25) | (1 << 13) | (1 << 11) | (1 << 10) | (1 << 8) | (1 << 6) | 1)
    });
    // TIM1: 168 MHz / 840 = 200 kHz update, DMA request on update.
    dp.TIM1.arr().write(|w| unsafe { w.bits(839) });
    dp.TIM1.dier().write(|w| unsafe { w.bits(1 << 8) }); // UDE

    // ADC1: 12 bit left-aligned, external trigger TIM2 TRGO (EXTSEL 0110), DMA circular.
    dp.ADC1.smpr2().write(|w| unsafe { w.bits(0b001) }); // 15 cycles on IN0

    // Analog watchdog on every regular conversion: flags codes outside the core's
    // window [AWD_LOW, AWD_HIGH) (12-bit codes 1 ..= 0xFFD), so the closure does
    // not search 64 samples for rails.
    dp.ADC1
        .ltr()
        .write(|w| unsafe { w.bits(u32::from(AWD_LOW >> 4)) });
    dp.ADC1
        .htr()
        .write(|w| unsafe { w.bits(u32::from((AWD_HIGH >> 4) - 1)) });
    dp.ADC1.cr1().write(|w| unsafe { w.bits(1 << 23) }); // AWDEN, all channels
    dp.ADC1.sqr3().write(|w| unsafe { w.bits(0) });
    dp.ADC1.cr2().write(|w| unsafe {
        w.bits((1 << 28) | (0b0110 << 24) | (1 << 11) | (1 << 9) | (1 << 8) | 1)
    });
    // DMA2 stream 0 channel 0: ADC1 DR -> ADC_BUF, 16 bit, circular, HT + TC interrupts.
    let s0 = dp.DMA2.st(0);
    s0.par()
        .write(|w| unsafe { w.bits(dp.ADC1.dr().as_ptr() as u32) });
    s0.m0ar()
        .write(|w| unsafe { w.bits(core::ptr::addr_of!(ADC_BUF) as u32) });
    s0.ndtr()
        .write(|w| unsafe { w.bits((2 * N_SAMPLES) as u32) });
    s0.cr().write(|w| unsafe {
        w.bits((1 << 16) | (1 << 13) | (1 << 11) | (1 << 10) | (1 << 8) | (1 << 4) | (1 << 3) | 1)
    });
    // TIM2: 84 MHz / 105 = 800 kHz, TRGO on update.
    dp.TIM2.arr().write(|w| unsafe { w.bits(104) });
    dp.TIM2.cr2().write(|w| unsafe { w.bits(0b010 << 4) });

    let Some(queue) = cortex_m::singleton!(: FrameQueue = FrameQueue::new()) else {
        reset()
    };
    let (tx, mut rx) = queue.split();
    let mut frames = FrameBuilder::new(STEPS_PER_FRAME, cfg.n_half);
    if watchdog_reset {
        // Tell the host through the first frame that the board restarted.
        frames.restore(Frame {
            faults: Faults::RESET_RECOVERED,
            ..Frame::default()
        });
    }
    let iwdg = &dp.IWDG;
    iwdg.kr().write(|w| unsafe { w.bits(0x5555) });
    iwdg.pr().write(|w| unsafe { w.bits(3) }); // 32 kHz / 32
    iwdg.rlr().write(|w| unsafe { w.bits(100) }); // 100 ms
    iwdg.kr().write(|w| unsafe { w.bits(0xCCCC) });

    let usart = dp.USART1;
    let (tim1, tim2) = (dp.TIM1, dp.TIM2);
    cortex_m::interrupt::free(|cs| {
        CTX.borrow(cs).replace(Some(Ctx {
            cfg,
            fog,
            frames,
            tx,
            counter: 0,
            dma: dp.DMA2,
            adc: dp.ADC1,
        }))
    });
    unsafe {
        cp.NVIC.set_priority(Interrupt::DMA2_STREAM0, 0);
        cortex_m::peripheral::NVIC::unmask(Interrupt::DMA2_STREAM0);
    }
    // Start both timers together so DAC and ADC half periods stay aligned.
    tim1.cr1().write(|w| unsafe { w.bits(1) });
    tim2.cr1().write(|w| unsafe { w.bits(1) });
    defmt::info!("gyro-fw hw: FOG closure at 12.5 kHz");
    loop {
        while let Some(f) = rx.dequeue() {
            uart::write(&usart, &f.encode());
        }
        iwdg.kr().write(|w| unsafe { w.bits(0xAAAA) });
        cortex_m::asm::wfi();
    }
}

fn clocks(dp: &pac::Peripherals) {
    let rcc = &dp.RCC;
    rcc.cr()
        .modify(|r, w| unsafe { w.bits(r.bits() | (1 << 16)) }); // HSEON
    while rcc.cr().read().bits() & (1 << 17) == 0 {} // HSERDY
                                                     // PLL: M=8, N=336, P=2 (168 MHz), Q=7, source HSE.
    rcc.pllcfgr()
        .write(|w| unsafe { w.bits(8 | (336 << 6) | (1 << 22) | (7 << 24)) });
    rcc.cr()
        .modify(|r, w| unsafe { w.bits(r.bits() | (1 << 24)) }); // PLLON
    while rcc.cr().read().bits() & (1 << 25) == 0 {}
    dp.FLASH
        .acr()
        .write(|w| unsafe { w.bits((1 << 10) | (1 << 9) | (1 << 8) | 5) }); // caches, prefetch, 5 WS
    rcc.cfgr()
        .write(|w| unsafe { w.bits((0b100 << 13) | (0b101 << 10) | 0b10) }); // APB2 /2, APB1 /4, SW = PLL
    while rcc.cfgr().read().bits() & 0b1100 != 0b1000 {}
    rcc.ahb1enr()
        .modify(|r, w| unsafe { w.bits(r.bits() | (1 << 22) | 1) }); // DMA2, GPIOA
    rcc.apb2enr()
        .modify(|r, w| unsafe { w.bits(r.bits() | (1 << 12) | (1 << 8) | (1 << 4) | 1) }); // SPI1, ADC1, USART1, TIM1
    rcc.apb1enr().modify(|r, w| unsafe { w.bits(r.bits() | 1) }); // TIM2
}

/// Closure interrupt: half transfer -> step in the first half of ADC_BUF is
/// complete; transfer complete -> the second half.
#[interrupt]
fn DMA2_STREAM0() {
    cortex_m::interrupt::free(|cs| {
        let mut guard = CTX.borrow(cs).borrow_mut();
        let Some(ctx) = guard.as_mut() else { return };
        let isr = ctx.dma.lisr().read().bits();
        ctx.dma.lifcr().write(|w| unsafe { w.bits(0x3D) }); // clear stream 0 flags
        let half = if isr & (1 << 5) != 0 { 1 } else { 0 }; // TCIF0 -> second half
                                                            // SAFETY: the DMA is writing the other half of ADC_BUF and reading the
                                                            // other half of DAC_BUF while we touch these.
        let adc = unsafe { &*core::ptr::addr_of!(ADC_BUF) };
        let dac = unsafe { &mut *core::ptr::addr_of_mut!(DAC_BUF) };
        let (Some(adc), Some(dac)) = (
            adc.get(half * N_SAMPLES..(half + 1) * N_SAMPLES),
            dac.get_mut(half * N_HALF..(half + 1) * N_HALF),
        ) else {
            return;
        };
        // AWD is sticky: read and clear it once per step (a conversion of the
        // step now sampling may be counted with this one; that errs safe).
        let over_range = ctx.adc.sr().read().bits() & 1 != 0;
        ctx.adc.sr().write(|w| unsafe { w.bits(!1) });
        let out = ctx.fog.process(&ctx.cfg, adc, over_range, dac);
        ctx.counter = ctx.counter.wrapping_add(1);
        if let Some(f) = ctx.frames.push(&out, ctx.counter) {
            if let Err(f) = ctx.tx.enqueue(f) {
                ctx.frames.restore(f);
            }
        }
    });
}

fn reset() -> ! {
    cortex_m::peripheral::SCB::sys_reset()
}

/// Safe path: stop the interrupts (the modulator DMA keeps cycling the last
/// words, a valid square wave), log, and let the watchdog restart the board;
/// the first frame after restart carries RESET_RECOVERED.
#[panic_handler]
fn panic(info: &core::panic::PanicInfo) -> ! {
    cortex_m::interrupt::disable();
    if let Some(l) = info.location() {
        defmt::error!("panic at {}:{}", l.file(), l.line());
    }
    loop {
        cortex_m::asm::nop();
    }
}
