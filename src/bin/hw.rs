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
//!   This ping-pong delays the new step by one closure period
//!   (`dac_latency_steps = 1`): the closure keeps the words in flight and
//!   closes the loop as a Smith predictor, and the host rigs simulate the same
//!   ping-pong (host-tests `fog_latency`).
//! - Frames on USART1 (PA9) at 2 Mbaud; independent watchdog at 100 ms.
//! - RLG: the readout's quadrature pair on PB6/PB7 (TIM4 CH1/CH2, AF2, digital
//!   filter 8 samples) counts in encoder mode 3 (every edge of both inputs,
//!   x4); TIM5 interrupts at 500 Hz (below the closure's priority) and runs
//!   the RLG update: counter read and wrapping difference, thermal
//!   compensation on sensor ticks. The three TMP117s (0x48 monoblock A, 0x49
//!   monoblock B, 0x4A case) sit on I2C1 (PB8/PB9, `i2c.rs`); the main loop
//!   reads them at 10 Hz and hands the readings to the update interrupt
//!   through a queue, so no bus transfer runs in an interrupt. The closure
//!   interrupt puts the RLG words into each frame. Coefficients come from the
//!   build-time record (build.rs, `RLG_COEFFS`) and are checked at start.
//! - FOG coil temperature: a fourth TMP117 (0x4B) on the same bus, read by
//!   the main loop at 1 Hz and queued to the closure interrupt, which
//!   advances the scale-factor table's state; each completed frame gets the
//!   table applied (build-time record, `FOG_SF_COEFFS`).
//!
//! Registers are written as whole words with the bit meaning in the comment.

#![no_std]
#![no_main]

use core::cell::RefCell;
use core::sync::atomic::{AtomicU32, Ordering};
use cortex_m::interrupt::Mutex;
use defmt_rtt as _;
use gyro_fw::app::{
    FramePath, FrameQueue, CLOSURES_PER_FRAME, FOG_SF_RECORD, RLG_HZ, RLG_RECORD, SENSOR_EVERY,
};
use gyro_fw::i2c::I2c1;
use gyro_fw::{stack, uart};
use gyro_sp::fog::demod::{AWD_HIGH, AWD_LOW};
use gyro_sp::fog::scale_factor::ScaleFactorConfig;
use gyro_sp::fog::{Faults, FogConfig, FogLoop, FogParams};
use gyro_sp::frame::{Frame, FrameBuilder};
use gyro_sp::rlg::thermal::{Temperatures, ThermalConfig};
use gyro_sp::rlg::{RlgChannel, RlgConfig};
use heapless::spsc::{Consumer, Queue};
use stm32f4::stm32f405::{self as pac, interrupt, Interrupt};
use tmp117::Tmp117;

/// RLG scale factor: encoder counts (quadrature edges, x4) per degree.
const RLG_COUNTS_PER_DEG: f64 = 8_000.0;
/// Readings from the main loop to the RLG update interrupt.
type TempQueue = Queue<Temperatures, 2>;
/// Coil readings (Q8 degC, None: failed) from the main loop to the closure.
type CoilQueue = Queue<Option<i32>, 2>;
/// The coil sensor is read every this many sensor cycles (1 Hz): a slower
/// derivative for the lag lead is a quieter one (its noise scales as
/// 1/sqrt(period)).
const COIL_EVERY: u32 = 10;
/// RLG updates so far (the main loop times the sensor reads by it).
static RLG_TICKS: AtomicU32 = AtomicU32::new(0);

const N_HALF: usize = 16;
const N_SAMPLES: usize = 64;

#[link_section = ".uninit.dma"]
static mut ADC_BUF: [u16; 2 * N_SAMPLES] = [0; 2 * N_SAMPLES];
#[link_section = ".uninit.dma"]
static mut DAC_BUF: [u16; 2 * N_HALF] = [0; 2 * N_HALF];

struct Ctx {
    cfg: FogConfig,
    fog: FogLoop,
    out: FramePath,
    dma: pac::DMA2,
    adc: pac::ADC1,
    rlg_cfg: RlgConfig,
    rlg: RlgChannel,
    encoder: pac::TIM4,
    rlg_timer: pac::TIM5,
    temps: Consumer<'static, Temperatures, 2>,
    coil: Consumer<'static, Option<i32>, 2>,
}

static CTX: Mutex<RefCell<Option<Ctx>>> = Mutex::new(RefCell::new(None));

#[cortex_m_rt::entry]
fn main() -> ! {
    stack::paint();
    run()
}

fn run() -> ! {
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
                                // PB6/PB7: AF2 (TIM4 CH1/CH2), the RLG quadrature pair.
    dp.GPIOB
        .moder()
        .modify(|r, w| unsafe { w.bits((r.bits() & !(0xF << 12)) | (0xA << 12)) });
    dp.GPIOB
        .afrl()
        .modify(|r, w| unsafe { w.bits((r.bits() & !(0xFF << 24)) | (0x22 << 24)) });
    let mut i2c = I2c1::new(dp.I2C1, &dp.GPIOB);
    let sensors = [Tmp117::new(0x48), Tmp117::new(0x49), Tmp117::new(0x4A)];
    let coil_sensor = Tmp117::new(0x4B);
    for s in sensors.iter().chain([&coil_sensor]) {
        if s.init(&mut i2c).is_err() {
            defmt::warn!(
                "TMP117 at {=u8:#x} does not answer: its reads will be flagged",
                s.addr
            );
        }
    }
    let thermal = ThermalConfig::from_record(&RLG_RECORD, SENSOR_EVERY as f64 / RLG_HZ as f64);
    if thermal.coeffs_default {
        defmt::warn!("RLG coefficient record refused: running without thermal compensation");
    }
    let rlg_cfg = RlgConfig::new(thermal, RLG_COUNTS_PER_DEG, RLG_HZ);
    // TIM4 encoder: CC1S = CC2S = 01 (TI1, TI2), IC1F = IC2F = 0011 (8 samples
    // at fCK_INT), both polarities non-inverted, SMS = 011 (x4), full 16-bit range.
    dp.TIM4.ccmr1_input().write(|w| unsafe { w.bits(0x3131) });
    dp.TIM4.ccer().write(|w| unsafe { w.bits(0) });
    dp.TIM4.smcr().write(|w| unsafe { w.bits(0b011) });
    dp.TIM4.arr().write(|w| unsafe { w.bits(0xFFFF) });
    dp.TIM4.cr1().write(|w| unsafe { w.bits(1) }); // CEN
                                                   // TIM5: 84 MHz / 84 = 1 MHz, / 2000 = 500 Hz update interrupt.
    dp.TIM5.psc().write(|w| unsafe { w.bits(83) });
    dp.TIM5
        .arr()
        .write(|w| unsafe { w.bits(1_000_000 / RLG_HZ - 1) });
    dp.TIM5.dier().write(|w| unsafe { w.bits(1) }); // UIE
    let Some(temp_queue) = cortex_m::singleton!(: TempQueue = TempQueue::new()) else {
        reset()
    };
    let (mut temps_tx, temps_rx) = temp_queue.split();
    let Some(coil_queue) = cortex_m::singleton!(: CoilQueue = CoilQueue::new()) else {
        reset()
    };
    let (mut coil_tx, coil_rx) = coil_queue.split();

    // The DMA ping-pong applies the words written now the step after next.
    let params = FogParams {
        dac_latency_steps: 1,
        ..FogParams::default()
    };
    let Ok(cfg) = FogConfig::new(params) else {
        reset()
    };
    let mut fog = FogLoop::new(&cfg);
    let coil_dt_s = (SENSOR_EVERY * COIL_EVERY) as f64 / RLG_HZ as f64;
    let sf_cfg = ScaleFactorConfig::from_record(&FOG_SF_RECORD, &cfg, coil_dt_s);
    if sf_cfg.coeffs_refused {
        defmt::warn!("FOG scale-factor record refused: running without temperature compensation");
    }
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
    let mut out = FramePath::new(
        FrameBuilder::new(CLOSURES_PER_FRAME, cfg.n_half),
        tx,
        sf_cfg,
    );
    if watchdog_reset {
        // Tell the host through the first frame that the board restarted.
        out.restore(Frame {
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
    let (tim1, tim2, tim5) = (dp.TIM1, dp.TIM2, dp.TIM5);
    // Counting from here; its interrupt stays masked until the context exists.
    tim5.cr1().write(|w| unsafe { w.bits(1) }); // CEN
    cortex_m::interrupt::free(|cs| {
        CTX.borrow(cs).replace(Some(Ctx {
            cfg,
            fog,
            out,
            dma: dp.DMA2,
            adc: dp.ADC1,
            rlg_cfg,
            rlg: RlgChannel::default(),
            encoder: dp.TIM4,
            rlg_timer: tim5,
            temps: temps_rx,
            coil: coil_rx,
        }))
    });
    unsafe {
        cp.NVIC.set_priority(Interrupt::DMA2_STREAM0, 0);
        cp.NVIC.set_priority(Interrupt::TIM5, 0x40);
        cortex_m::peripheral::NVIC::unmask(Interrupt::DMA2_STREAM0);
        cortex_m::peripheral::NVIC::unmask(Interrupt::TIM5);
    }
    // Start both timers together so DAC and ADC half periods stay aligned.
    tim1.cr1().write(|w| unsafe { w.bits(1) });
    tim2.cr1().write(|w| unsafe { w.bits(1) });
    defmt::info!(
        "gyro-fw hw: FOG closure at 12.5 kHz, RLG update at {} Hz",
        RLG_HZ
    );
    let mut last_read = 0u32;
    let mut cycles = 0u32;
    loop {
        while let Some(f) = rx.dequeue() {
            uart::write(&usart, &f.encode());
        }
        let ticks = RLG_TICKS.load(Ordering::Relaxed);
        if ticks.wrapping_sub(last_read) >= SENSOR_EVERY {
            last_read = ticks;
            // A failed read is None: the compensation flags it and holds.
            let t = Temperatures {
                mono_a_q8: sensors[0].read(&mut i2c),
                mono_b_q8: sensors[1].read(&mut i2c),
                case_q8: sensors[2].read(&mut i2c),
            };
            // Full only if the update interrupt has stopped; the reading is
            // then stale anyway.
            let _ = temps_tx.enqueue(t);
            if cycles.is_multiple_of(COIL_EVERY) {
                let _ = coil_tx.enqueue(coil_sensor.read(&mut i2c));
            }
            cycles = cycles.wrapping_add(1);
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
        .modify(|r, w| unsafe { w.bits(r.bits() | (1 << 22) | 0b11) }); // DMA2, GPIOB, GPIOA
    rcc.apb2enr()
        .modify(|r, w| unsafe { w.bits(r.bits() | (1 << 12) | (1 << 8) | (1 << 4) | 1) }); // SPI1, ADC1, USART1, TIM1
    rcc.apb1enr()
        .modify(|r, w| unsafe { w.bits(r.bits() | (1 << 21) | (1 << 3) | (1 << 2) | 1) });
    // I2C1, TIM5, TIM4, TIM2
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
        let closure = ctx.fog.process(&ctx.cfg, adc, over_range, dac);
        if ctx.out.frame_ends() {
            // The frame this closure completes carries the RLG counts since the last.
            let (counts, n) = ctx.rlg.take_frame();
            ctx.out.set_rlg(ctx.rlg.words(&ctx.rlg_cfg, counts, n));
        }
        if let Some(read) = ctx.coil.dequeue() {
            ctx.out.coil_reading(read);
        }
        if let Some(mut f) = ctx.out.push(&closure) {
            ctx.out.compensate(&mut f);
            ctx.out.send(f);
        }
    });
}

/// RLG update interrupt (500 Hz): encoder counter read and differenced; on
/// sensor ticks the readings the main loop queued advance the compensation.
#[interrupt]
fn TIM5() {
    cortex_m::interrupt::free(|cs| {
        let mut guard = CTX.borrow(cs).borrow_mut();
        let Some(ctx) = guard.as_mut() else { return };
        ctx.rlg_timer.sr().write(|w| unsafe { w.bits(!1) }); // clear UIF
        let raw = ctx.encoder.cnt().read().bits() as u16;
        let temps = ctx.temps.dequeue();
        ctx.rlg.update(&ctx.rlg_cfg, raw, temps.as_ref());
        RLG_TICKS.fetch_add(1, Ordering::Relaxed);
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
