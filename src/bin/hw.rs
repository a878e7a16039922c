//! `hw` board: the STM32F405 on the gyro electronics, on RTIC 2 and
//! stm32f4xx-hal.
//!
//! - Clocks: 8 MHz HSE -> PLL -> 168 MHz core, APB2 84 MHz, APB1 42 MHz.
//! - Detector: ADC1 on PA0, triggered by TIM2 TRGO at 800 kHz (4 samples per
//!   5 us half period; TIM2 is started by TIM1's compare at the sampling
//!   phase, docs/timing.md), DMA2 stream 0 circular over two closures; the
//!   half/complete interrupt runs the closure task on the closure just
//!   sampled (`sampling.rs`).
//! - Modulator: external 16-bit DAC on SPI1 (PA5 SCK, PA7 MOSI, PA4 NSS); TIM1
//!   update at 200 kHz requests one word per half period through DMA2 stream 5,
//!   circular over two closures. The closure writes the half the DMA is not
//!   reading, so its words are applied one closure later than on the host
//!   rigs (`dac_latency = 1`): the closure keeps the words in flight and
//!   closes the loop as a Smith predictor (docs/fog.md); the host rigs
//!   simulate the same ping-pong (host-tests `fog_latency`).
//! - Frames on USART1 (PA9) at 2 Mbaud; independent watchdog at 100 ms.
//! - Nothing lost silently: a closure that runs late (the DMA past the half
//!   it should read) is counted and flagged in the frame (`overrun.rs`,
//!   timed by the cycle counter); a DMA transfer error restarts the stream,
//!   flagged; a HardFault logs, leaves a mark in RAM and resets, and the
//!   first frame after any start says why it started (`reset_cause.rs`).
//! - RLG: the readout's quadrature pair on PC6/PC7 counts in TIM3's encoder
//!   mode (x4, input filter 8 samples); the dither pickoff's comparator (PC8
//!   and PA1) latches the count in TIM3's CCR3/CCR4 and its time in the
//!   free-running TIM5's CCR2 at each zero crossing (`rlg_timers.rs`). The
//!   latch task hands each crossing to the stripping; the RLG update task
//!   (TIM5's compare, 500 Hz) reads the counter, takes the stripped angle
//!   and runs the thermal compensation on sensor ticks. Both sit below the
//!   closure's priority; the frame words reach the closure through a
//!   lock-free queue, so the closure is never masked.
//! - Temperatures: TMP117s on I2C1 (PB8/PB9): 0x48 monoblock A, 0x49
//!   monoblock B, 0x4A case (10 Hz), 0x4B FOG coil (1 Hz). The idle loop
//!   reads them and queues the readings to the tasks, so no bus transfer runs
//!   in an interrupt; every wait on the bus is bounded and a bus held low is
//!   clocked free (`i2c.rs`), so a dead sensor never stalls the frames. Coefficients come from the build-time records
//!   (build.rs: `RLG_COEFFS`, `FOG_SF_COEFFS`) and are checked at start.

#![no_std]
#![no_main]

use core::sync::atomic::{AtomicU32, Ordering};
use cortex_m::peripheral::DWT;
use defmt_rtt as _;
use gyro_fw::app::{
    fog_params, FramePath, FrameQueue, RlgQueue, ADC_PER_CLOSURE, CLOSURES_PER_FRAME, CLOSURE_HZ,
    FOG_SF_RECORD, FRAME_QUEUE_LEN, HALF_PERIODS, RLG_HZ, RLG_QUEUE_LEN, RLG_RECORD, SENSOR_EVERY,
};
use gyro_fw::i2c::I2c1;
use gyro_fw::reset_cause::{reset_cause, HARD_FAULT_MARK, PANIC_MARK};
use gyro_fw::rlg_timers;
use gyro_fw::sampling::{self, AdcBuffer, DacBuffer, Sampling};
use gyro_fw::timing;
use gyro_sp::fog::scale_factor::ScaleFactorConfig;
use gyro_sp::fog::{Faults, FogConfig, FogLoop};
use gyro_sp::frame::{Frame, FrameBuilder, ResetCause};
use gyro_sp::rlg::thermal::{Temperatures, ThermalConfig};
use gyro_sp::rlg::{LatchSample, RlgChannel, RlgConfig, RlgWords, StripConfig};
use heapless::spsc::{Consumer, Producer, Queue};
use stm32f4xx_hal::{
    adc::{
        config::{
            AdcConfig, Align, Clock, Dma, ExternalTrigger, SampleTime, Sequence, TriggerMode,
        },
        Adc,
    },
    gpio::Speed,
    pac::{self, I2C1, TIM3, TIM5, USART1},
    prelude::*,
    rcc::{Config, Enable, Reset},
    serial::{config::Config as SerialConfig, Tx},
    spi::{Mode as SpiMode, Phase, Polarity, Spi},
    timer::CounterHz,
    watchdog::IndependentWatchdog,
};
use tmp117::Tmp117;

/// RLG scale factor: encoder counts (quadrature edges, x4) per degree.
const RLG_COUNTS_PER_DEG: f64 = 8_000.0;
/// The gyro's dither frequency range (the pickoff's half periods outside
/// 0.8/f_max .. 1.25/f_min are refused or restart the stripping), Hz.
const DITHER_HZ: (f64, f64) = (250.0, 700.0);
/// TIM5 ticks per RLG update.
const RLG_PERIOD: u32 = rlg_timers::CLOCK_HZ / RLG_HZ;
/// The coil sensor is read every this many sensor cycles (1 Hz): a slower
/// derivative for the lag lead is a quieter one (its noise scales as
/// 1/sqrt(period)).
const COIL_EVERY: u32 = 10;

/// Readings from the idle loop to the RLG update task.
type TempQueue = Queue<Temperatures, 2>;
/// Coil readings (Q8 degC, None: failed) from the idle loop to the closure.
type CoilQueue = Queue<Option<i32>, 2>;
/// RLG updates so far (the idle loop times the sensor reads by it).
static RLG_TICKS: AtomicU32 = AtomicU32::new(0);
/// Left by the HardFault handler before it resets; in RAM that start-up
/// does not initialise, so the next start reads it (garbage after power-on,
/// which the cause ignores).
#[link_section = ".uninit.RESET_MARK"]
static RESET_MARK: AtomicU32 = AtomicU32::new(0);
/// Where the hard fault was (its PC and LR), left beside the mark and
/// logged by the next start: the fault handler itself logs nothing, so it
/// has no path to a panic (`cargo xtask isr-proof`) and cannot fault again
/// in the logger.
#[link_section = ".uninit.RESET_MARK"]
static FAULT_PC: AtomicU32 = AtomicU32::new(0);
#[link_section = ".uninit.RESET_MARK"]
static FAULT_LR: AtomicU32 = AtomicU32::new(0);

/// The closure task's state.
pub struct Closure {
    cfg: FogConfig,
    fog: FogLoop,
    sampling: Sampling,
    out: FramePath,
    rlg_words: Consumer<'static, RlgWords, RLG_QUEUE_LEN>,
    coil: Consumer<'static, Option<i32>, 2>,
}

/// The RLG update task's state.
pub struct RlgTask {
    cfg: RlgConfig,
    ch: RlgChannel,
    encoder: TIM3,
    clock: TIM5,
    temps: Consumer<'static, Temperatures, 2>,
    words: Producer<'static, RlgWords, RLG_QUEUE_LEN>,
}

/// The idle loop's: frames out, sensors read, watchdog fed.
pub struct Housekeeping {
    frames: Consumer<'static, Frame, FRAME_QUEUE_LEN>,
    usart: Tx<USART1>,
    i2c: I2c1,
    sensors: [Tmp117; 3],
    coil_sensor: Tmp117,
    temps: Producer<'static, Temperatures, 2>,
    coil: Producer<'static, Option<i32>, 2>,
    watchdog: IndependentWatchdog,
    /// The HAL's handles of the sampling peripherals, kept so nothing else
    /// can take them; the closure drives them through `Sampling`.
    _sampling: (
        Adc<pac::ADC1>,
        CounterHz<pac::TIM1>,
        CounterHz<pac::TIM2>,
        Spi<pac::SPI1, false, u16>,
    ),
}

#[rtic::app(device = stm32f4xx_hal::pac, peripherals = true)]
mod app {
    use super::*;

    #[shared]
    struct Shared {
        /// The RLG channel: the latch and update tasks share it at one
        /// priority (their locks cost nothing).
        rlg: RlgTask,
    }

    #[local]
    struct Local {
        closure: Closure,
        housekeeping: Housekeeping,
    }

    #[init(local = [
        adc_buf: AdcBuffer = [0; 2 * ADC_PER_CLOSURE],
        dac_buf: DacBuffer = [0; 2 * HALF_PERIODS],
        frame_queue: FrameQueue = FrameQueue::new(),
        rlg_queue: RlgQueue = RlgQueue::new(),
        temp_queue: TempQueue = TempQueue::new(),
        coil_queue: CoilQueue = CoilQueue::new(),
    ])]
    fn init(cx: init::Context) -> (Shared, Local) {
        gyro_fw::stack::paint();
        let dp = cx.device;
        let mut core = cx.core;
        let cause = reset_cause(
            dp.RCC.csr().read().bits(),
            RESET_MARK.swap(0, Ordering::Relaxed),
        );
        dp.RCC.csr().modify(|_, w| w.rmvf().set_bit());
        // The cycle counter times the closures (missed ones are counted).
        core.DCB.enable_trace();
        core.DWT.enable_cycle_counter();
        let mut rcc = dp.RCC.freeze(
            Config::hse(8.MHz())
                .sysclk(168.MHz())
                .pclk1(42.MHz())
                .pclk2(84.MHz()),
        );
        let gpioa = dp.GPIOA.split(&mut rcc);
        // GPIOB's clock on for the I2C driver (its pins are set up by it).
        let _gpiob = dp.GPIOB.split(&mut rcc);
        let gpioc = dp.GPIOC.split(&mut rcc);
        let Ok(usart) = dp.USART1.tx(
            gpioa.pa9,
            SerialConfig::default().baudrate(2_000_000.bps()),
            &mut rcc,
        ) else {
            reset()
        };
        // The bounded I2C driver (the HAL's waits have no bound): PB8/PB9
        // are set up by it, GPIOB's clock is on (split above).
        I2C1::enable(&mut rcc);
        // SAFETY: the driver touches only PB8/PB9's bits of GPIOB, which
        // nothing else uses (the HAL's split handles of PB8/PB9 are dropped).
        let mut i2c = I2c1::new(dp.I2C1, unsafe { pac::GPIOB::steal() });
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

        // RLG: encoder and count latch on TIM3 (PC6/PC7, pickoff PC8), the
        // latch clock and update compare on TIM5 (pickoff PA1).
        let _rlg_pins = (
            gpioc.pc6.into_alternate::<2>(),
            gpioc.pc7.into_alternate::<2>(),
            gpioc.pc8.into_alternate::<2>(),
            gpioa.pa1.into_alternate::<2>(),
        );
        TIM3::enable(&mut rcc);
        TIM3::reset(&mut rcc);
        TIM5::enable(&mut rcc);
        TIM5::reset(&mut rcc);
        let (encoder, clock) = (dp.TIM3, dp.TIM5);
        let thermal = ThermalConfig::from_record(&RLG_RECORD, SENSOR_EVERY as f64 / RLG_HZ as f64);
        if thermal.coeffs_default {
            defmt::warn!("RLG coefficient record refused: running without thermal compensation");
        }

        // FOG: the DMA ping-pong applies the words written now one closure late.
        let Ok(cfg) = FogConfig::new(fog_params(1)) else {
            reset()
        };
        if cfg.n_half != HALF_PERIODS || cfg.n_samples != ADC_PER_CLOSURE {
            reset()
        }
        let mut fog = FogLoop::new(&cfg);
        let coil_dt_s = (SENSOR_EVERY * COIL_EVERY) as f64 / RLG_HZ as f64;
        // Built in its static, not moved through the start-up stack.
        let Some(sf_cfg) = cortex_m::singleton!(: ScaleFactorConfig =
            ScaleFactorConfig::from_record(&FOG_SF_RECORD, &cfg, coil_dt_s))
        else {
            reset()
        };
        if sf_cfg.coeffs_refused {
            defmt::warn!(
                "FOG scale-factor record refused: running without temperature compensation"
            );
        }
        // Both DAC halves start with valid words.
        let dac_buf = cx.local.dac_buf;
        let (a, b) = dac_buf.split_at_mut(HALF_PERIODS);
        fog.start(&cfg, a);
        b.copy_from_slice(a);

        // SPI1 to the DAC: master, mode 0, 16-bit words at 21 MHz.
        let spi = Spi::new(
            dp.SPI1,
            (
                Some(gpioa.pa5.into_alternate().speed(Speed::VeryHigh)),
                None::<stm32f4xx_hal::gpio::PA6<stm32f4xx_hal::gpio::Alternate<5>>>,
                Some(gpioa.pa7.into_alternate().speed(Speed::VeryHigh)),
            ),
            SpiMode {
                polarity: Polarity::IdleLow,
                phase: Phase::CaptureOnFirstTransition,
            },
            21.MHz(),
            &mut rcc,
        )
        .frame_size_16bit();
        let _nss = gpioa.pa4.into_alternate::<5>().speed(Speed::VeryHigh);
        // ADC1 on PA0: 12 bit left-aligned, started by TIM2 TRGO, DMA in
        // circular mode; 21 MHz ADC clock, 3 + 12 cycles per conversion
        // (0.71 us, inside the 1.25 us sample period).
        let pa0 = gpioa.pa0.into_analog();
        let mut adc = Adc::new(
            dp.ADC1,
            true,
            AdcConfig::default()
                .clock(Clock::Pclk2_div_4)
                .align(Align::Left)
                .external_trigger(TriggerMode::RisingEdge, ExternalTrigger::Tim_2_trgo)
                .dma(Dma::Continuous),
            &mut rcc,
        );
        adc.configure_channel(&pa0, Sequence::One, SampleTime::Cycles_3);
        let adc_dr = adc.data_register_address();
        pac::DMA2::enable(&mut rcc);
        let mut sampling = Sampling::new(
            dp.DMA2,
            // SAFETY: the HAL's Adc configured the converter and is kept
            // (never used again, `Housekeeping::_sampling`); this handle
            // touches only the analog watchdog, which the HAL never writes.
            unsafe { pac::ADC1::steal() },
            adc_dr,
            // SAFETY: the NSS output and TX DMA bits, which the HAL's Spi
            // (kept, never used again) does not write after set-up.
            unsafe { &*pac::SPI1::ptr() },
            cx.local.adc_buf,
            dac_buf,
        );
        let tim1 = dp.TIM1.counter_hz(&mut rcc);
        let tim2 = dp.TIM2.counter_hz(&mut rcc);
        // The sampling timers' registers were computed for these clocks.
        if rcc.clocks.timclk2().raw() != timing::TIM1_CLK_HZ
            || rcc.clocks.timclk1().raw() != timing::TIM2_CLK_HZ
        {
            reset()
        }
        // SAFETY: the HAL's handles (kept, never started) reset both timers;
        // only these register writes configure them.
        sampling::configure_timers(unsafe { &*pac::TIM1::ptr() }, unsafe { &*pac::TIM2::ptr() });

        let (tx, frames) = cx.local.frame_queue.split();
        let (words, rlg_words) = cx.local.rlg_queue.split();
        let (temps_tx, temps_rx) = cx.local.temp_queue.split();
        let (coil_tx, coil_rx) = cx.local.coil_queue.split();
        // The first frame says why the board started.
        let out = FramePath::new(
            FrameBuilder::new(CLOSURES_PER_FRAME, cfg.n_half),
            tx,
            sf_cfg,
            cause,
        );
        if cause == ResetCause::HardFault {
            defmt::error!(
                "started after a HardFault at pc {=u32:#x}, lr {=u32:#x}",
                FAULT_PC.load(Ordering::Relaxed),
                FAULT_LR.load(Ordering::Relaxed)
            );
        } else if cause != ResetCause::PowerOn {
            defmt::warn!("started after a reset: {}", cause as u8);
        }
        let mut watchdog = IndependentWatchdog::new(dp.IWDG);
        watchdog.start(100.millis());

        // The sampling from one timebase: TIM1 starts, its compare starts TIM2
        // at the sampling phase; interrupts are enabled when init returns.
        // SAFETY: CEN of the timer configured above.
        sampling::start_timers(unsafe { &*pac::TIM1::ptr() });
        rlg_timers::configure_encoder(&encoder);
        rlg_timers::configure_clock(&clock, RLG_PERIOD);
        defmt::info!(
            "gyro-fw hw: FOG closure at {} Hz, RLG update at {} Hz",
            CLOSURE_HZ,
            RLG_HZ
        );
        // The DMA's first completion comes one closure period after the
        // timers started (a few hundred cycles ago: far below half a period).
        sampling.start_clock(DWT::cycle_count());
        (
            Shared {
                rlg: RlgTask {
                    cfg: RlgConfig::new(thermal, RLG_COUNTS_PER_DEG, RLG_HZ).with_dither(
                        StripConfig {
                            // No photodiode ADC on this board yet: each latch
                            // stands for its count's middle.
                            interpolate: false,
                            ..StripConfig::new(
                                rlg_timers::CLOCK_HZ,
                                DITHER_HZ.0,
                                DITHER_HZ.1,
                                [0, 0],
                            )
                        },
                    ),
                    ch: RlgChannel::default(),
                    encoder,
                    clock,
                    temps: temps_rx,
                    words,
                },
            },
            Local {
                closure: Closure {
                    cfg,
                    fog,
                    sampling,
                    out,
                    rlg_words,
                    coil: coil_rx,
                },
                housekeeping: Housekeeping {
                    frames,
                    usart,
                    i2c,
                    sensors,
                    coil_sensor,
                    temps: temps_tx,
                    coil: coil_tx,
                    watchdog,
                    _sampling: (adc, tim1, tim2, spi),
                },
            },
        )
    }

    /// Frames out, sensors read at 10 Hz (coil at 1 Hz), watchdog fed.
    #[idle(local = [housekeeping])]
    fn idle(cx: idle::Context) -> ! {
        let h = cx.local.housekeeping;
        let mut last_read = 0u32;
        let mut cycles = 0u32;
        loop {
            while let Some(f) = h.frames.dequeue() {
                // Blocking: 86 bytes at 2 Mbaud take 0.43 ms of the 2 ms frame.
                let _ = h.usart.bwrite_all(&f.encode());
            }
            let ticks = RLG_TICKS.load(Ordering::Relaxed);
            if ticks.wrapping_sub(last_read) >= SENSOR_EVERY {
                last_read = ticks;
                // A failed read is None: the compensation flags it and holds.
                let t = Temperatures {
                    mono_a_q8: h.sensors[0].read(&mut h.i2c),
                    mono_b_q8: h.sensors[1].read(&mut h.i2c),
                    case_q8: h.sensors[2].read(&mut h.i2c),
                };
                // Full only if the update task has stopped; the reading is
                // then stale anyway.
                let _ = h.temps.enqueue(t);
                if cycles.is_multiple_of(COIL_EVERY) {
                    let _ = h.coil.enqueue(h.coil_sensor.read(&mut h.i2c));
                }
                cycles = cycles.wrapping_add(1);
            }
            h.watchdog.feed();
            cortex_m::asm::wfi();
        }
    }

    /// The closure (highest priority), on the ADC DMA's half/complete
    /// interrupt: the FOG core on the closure just sampled, the DAC words
    /// for the half just sent, the frame.
    #[task(binds = DMA2_STREAM0, priority = 2, local = [closure])]
    fn closure(cx: closure::Context) {
        let c = cx.local.closure;
        let s = c.sampling.take_half(DWT::cycle_count());
        let mut faults = Faults::empty();
        faults.set(Faults::CLOSURE_OVERRUN, s.missed > 0);
        faults.set(Faults::DMA_ERROR, s.dma_error);
        // Safe path of a missed closure: its angle is lost, so the frame
        // counts it (and the time base moves on); the loop carries on.
        let (missed, half) = (s.missed, s.half);
        if !faults.is_empty() {
            c.out.lost(missed, faults);
        }
        let Some(half) = half else {
            // No complete closure to use (a transfer error): no new DAC
            // words, the DMA repeats the last ones (a valid square wave).
            return;
        };
        let which = half.which;
        let out = c
            .fog
            .process(&c.cfg, half.adc, half.adc_over_range, half.dac);
        if c.sampling.overtaken(which) {
            // The DMA entered the half while it was read: flag the closure.
            c.out.lost(0, Faults::CLOSURE_OVERRUN);
        }
        if c.out.frame_ends() {
            // The loop's slow side (the 2*pi loop's gear), once per frame.
            c.fog.supervise(&c.cfg, CLOSURES_PER_FRAME as u32);
            // The RLG words since the last frame.
            while let Some(w) = c.rlg_words.dequeue() {
                c.out.set_rlg(w);
            }
        }
        if let Some(read) = c.coil.dequeue() {
            c.out.coil_reading(read);
        }
        if let Some(mut f) = c.out.push(&out) {
            c.out.compensate(&mut f);
            c.out.send(f);
        }
    }

    /// RLG update (500 Hz, below the closure): counter read and
    /// differenced; on sensor ticks the readings advance the compensation.
    #[task(binds = TIM5, priority = 1, shared = [rlg])]
    fn rlg_update(mut cx: rlg_update::Context) {
        cx.shared.rlg.lock(|r| {
            let (time, counter) = rlg_timers::update_read(&r.clock, &r.encoder, RLG_PERIOD);
            let temps = r.temps.dequeue();
            r.ch.update(&r.cfg, time, counter, temps.as_ref());
            let span = r.ch.take_frame();
            // Full only if the closure has stopped; the counts stay for the next.
            if r.words.enqueue(r.ch.words(&r.cfg, &span)).is_err() {
                r.ch.restore_frame(span);
            }
        });
        RLG_TICKS.fetch_add(1, Ordering::Relaxed);
    }

    /// Dither pickoff zero crossing (the count and its time latched by
    /// TIM3 and TIM5): handed to the stripping.
    #[task(binds = TIM3, priority = 1, shared = [rlg])]
    fn rlg_latch(mut cx: rlg_latch::Context) {
        cx.shared.rlg.lock(|r| {
            let (time, latched) = rlg_timers::latch_read(&r.encoder, &r.clock);
            for l in latched.into_iter().flatten() {
                if l.overrun {
                    r.ch.latch_lost();
                }
                let sample = LatchSample {
                    time,
                    counter: l.counter,
                    rising: l.rising,
                    photodiodes: None,
                };
                r.ch.latch(&r.cfg, &sample);
            }
        });
    }
}

fn reset() -> ! {
    cortex_m::peripheral::SCB::sys_reset()
}

/// Safe path of a hard fault: leave the mark and where it was, reset; the
/// next start logs where, and its first frame says `HardFault` (and
/// RESET_RECOVERED).
#[cortex_m_rt::exception]
unsafe fn HardFault(ef: &cortex_m_rt::ExceptionFrame) -> ! {
    FAULT_PC.store(ef.pc(), Ordering::Relaxed);
    FAULT_LR.store(ef.lr(), Ordering::Relaxed);
    RESET_MARK.store(HARD_FAULT_MARK, Ordering::Relaxed);
    cortex_m::peripheral::SCB::sys_reset()
}

/// Safe path of a panic, which only start-up and the idle loop can reach
/// (no interrupt handler has a path to one: `cargo xtask isr-proof`): stop
/// the interrupts (the modulator DMA keeps cycling the last words, a valid
/// square wave), log where, leave the mark and reset at once (before
/// start-up has armed the watchdog nothing else would). The first frame
/// after the restart says `Panic` and carries RESET_RECOVERED.
#[panic_handler]
fn panic(info: &core::panic::PanicInfo) -> ! {
    cortex_m::interrupt::disable();
    if let Some(l) = info.location() {
        defmt::error!("panic at {}:{}", l.file(), l.line());
    }
    RESET_MARK.store(PANIC_MARK, Ordering::Relaxed);
    cortex_m::peripheral::SCB::sys_reset()
}
