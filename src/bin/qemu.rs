//! `qemu` board: netduinoplus2 (STM32F405) in qemu-system-arm. The gyro is
//! simulated on-chip with the same model as on the host (in f32); SysTick at
//! 12.5 kHz runs one closure step per interrupt. Under `-icount shift=0` one
//! instruction is 1 ns of virtual time, so the run is deterministic and SysTick
//! (core clock) measures the closure's instruction count.
//!
//! The RLG channel runs at every frame boundary (500 Hz): a simulated chamber
//! (`sim::Chamber`, the same model as `gyro-lab simulate chamber`) turns the
//! profile's rate into encoder counts, and three simulated TMP117s answer on
//! a simulated I2C bus through the real driver. The case sensor stops
//! answering for a while to show the fault path. Coefficients come from the
//! build-time record (build.rs, `RLG_COEFFS`).
//!
//! The FOG's scale factor and bias vary with its coil temperature
//! (`sim::fog_thermal`, the gyro `gyro-lab simulate scale-factor` makes):
//! the coil sweeps at a constant rate from 30 degC across the knee at 48 degC
//! (and out of the calibrated range at 60 degC after 1.25 s, flagged), and a
//! fourth simulated TMP117 (0x4B) reads it with its lag. A 2.4 s run cannot
//! show minutes of chamber time, so the thermal model runs 1000 times faster
//! than the closure (one sensor read per frame stands for 2 s; the sweep is
//! 1.44 degC/min in that time), and the firmware's table is configured for
//! that sensor period. The frame path applies the table (`FOG_SF_COEFFS`).

#![no_std]
#![no_main]

use core::cell::RefCell;
use core::sync::atomic::{AtomicBool, Ordering};
use cortex_m::interrupt::Mutex;
use cortex_m::peripheral::{syst::SystClkSource, SYST};
use cortex_m_rt::exception;
use defmt_semihosting as _;
use gyro_fw::app::{
    FramePath, FrameQueue, CLOSURES_PER_FRAME, CLOSURE_HZ, FOG_SF_RECORD, RLG_HZ, RLG_RECORD,
    SENSOR_EVERY,
};
use gyro_fw::{stack, uart};
use gyro_sim::{
    profile::qemu_demo, Chamber, ChamberParams, CoilThermal, FogRig, OpticsParams, ScaleFactorTruth,
};
use gyro_sp::fog::scale_factor::ScaleFactorConfig;
use gyro_sp::fog::{Faults, FogConfig, FogParams};
use gyro_sp::frame::FrameBuilder;
use gyro_sp::rlg::thermal::{Temperatures, ThermalConfig};
use gyro_sp::rlg::{RlgChannel, RlgConfig};
use tmp117::Tmp117;

/// SysTick clock of the emulated STM32F405 (QEMU's SYSCLK).
const CORE_HZ: u32 = 168_000_000;
const RELOAD: u32 = CORE_HZ / CLOSURE_HZ - 1;
/// Optical power loss injected during these steps (the final rest segment).
const POWER_LOSS: core::ops::Range<u32> = 28_500..28_750;
/// The case sensor NACKs during these RLG updates (1.0 .. 1.3 s).
const CASE_NACK: core::ops::Range<u32> = 500..650;
/// Thermal seconds per closure second (see the module doc).
const THERMAL_TIME_SCALE: f64 = 1000.0;
/// Coil sweep: start, degC, and rate, degC per closure second.
const COIL_START_C: f64 = 30.0;
const COIL_RATE_C_PER_S: f64 = 24.0;
/// TMP117 address of the FOG coil sensor (the fourth ADD0 address).
const COIL_SENSOR: u8 = 0x4B;

/// Simulated TMP117s on one I2C bus: they answer temperature reads with the
/// chamber's readings; one address can be made to NACK.
struct SimI2c {
    /// 0x48 monoblock A, 0x49 monoblock B, 0x4A case, 0x4B FOG coil.
    temps_c: [f64; 4],
    nack: Option<u8>,
}

impl embedded_hal::i2c::ErrorType for SimI2c {
    type Error = embedded_hal::i2c::ErrorKind;
}

impl embedded_hal::i2c::I2c for SimI2c {
    fn transaction(
        &mut self,
        address: u8,
        operations: &mut [embedded_hal::i2c::Operation<'_>],
    ) -> Result<(), Self::Error> {
        let i = match address {
            0x48..=0x4B if self.nack != Some(address) => (address - 0x48) as usize,
            _ => return Err(tmp117::NACK_ADDRESS),
        };
        let reg = ((self.temps_c[i] * 128.0) as i16).to_be_bytes();
        for op in operations {
            if let embedded_hal::i2c::Operation::Read(buf) = op {
                for (b, r) in buf.iter_mut().zip(reg) {
                    *b = r;
                }
            }
        }
        Ok(())
    }
}

struct Rlg {
    cfg: RlgConfig,
    ch: RlgChannel,
    chamber: Chamber,
    bus: SimI2c,
    sensors: [Tmp117; 3],
    updates: u32,
}

/// The FOG's temperature: truth, coil sensor and the table's state.
struct FogThermal {
    truth: ScaleFactorTruth,
    coil: CoilThermal,
    sensor: Tmp117,
}

/// Coil temperature at closure time `t_s`, degC.
fn coil_at(t_s: f64) -> f64 {
    COIL_START_C + COIL_RATE_C_PER_S * t_s
}

struct Bench {
    ticks_sum: u64,
    ticks_max: u32,
    n: u32,
}

impl Bench {
    /// One timed section between two SysTick reads.
    fn record(&mut self, t0: u32, t1: u32) {
        // SysTick counts down and reloads at 0: a reload in between adds RELOAD + 1.
        let ticks = if t1 <= t0 {
            t0 - t1
        } else {
            t0 + RELOAD + 1 - t1
        };
        self.ticks_sum += ticks as u64;
        self.ticks_max = self.ticks_max.max(ticks);
        self.n += 1;
    }
}

struct Ctx {
    rig: FogRig<f32>,
    rlg: Rlg,
    rlg_bench: Bench,
    fog_thermal: FogThermal,
    sf_bench: Bench,
    sf_sensor_bench: Bench,
    out: FramePath,
    counter: u32,
    total: u32,
    bench: Bench,
}

static CTX: Mutex<RefCell<Option<Ctx>>> = Mutex::new(RefCell::new(None));
static DONE: AtomicBool = AtomicBool::new(false);

fn run() -> ! {
    stack::paint();
    let Some(mut cp) = cortex_m::Peripherals::take() else {
        fail()
    };
    let Some(dp) = stm32f4::stm32f405::Peripherals::take() else {
        fail()
    };
    uart::init(&dp.USART1, 42);
    let ipt = instructions_per_tick(&mut cp.SYST);

    let mut optics = OpticsParams::<f32>::nominal(5e-6, 4, 49_152);
    optics.adc_bits = 12;
    let params = optics.matched(FogParams::default());
    let Ok(cfg) = FogConfig::new(params) else {
        fail()
    };
    let (profile, _) = qemu_demo::<f32>();
    let total = (profile.total_duration() * CLOSURE_HZ as f32) as u32;
    let Some(queue) = cortex_m::singleton!(: FrameQueue = FrameQueue::new()) else {
        fail()
    };
    let (tx, mut rx) = queue.split();
    let thermal = ThermalConfig::from_record(&RLG_RECORD, SENSOR_EVERY as f64 / RLG_HZ as f64);
    if thermal.coeffs_default {
        defmt::warn!("RLG coefficient record refused: running without thermal compensation");
    }
    let chamber_p = ChamberParams::default();
    let rlg = Rlg {
        cfg: RlgConfig::new(thermal, chamber_p.counts_per_deg, RLG_HZ),
        ch: RlgChannel::default(),
        chamber: Chamber::new(chamber_p, 20.0),
        bus: SimI2c {
            temps_c: [20.0; 4],
            nack: None,
        },
        sensors: [Tmp117::new(0x48), Tmp117::new(0x49), Tmp117::new(0x4A)],
        updates: 0,
    };
    // One coil sensor read per frame, 2 s of thermal time.
    let sensor_dt_s = THERMAL_TIME_SCALE * CLOSURES_PER_FRAME as f64 / CLOSURE_HZ as f64;
    let fog_thermal = FogThermal {
        truth: ScaleFactorTruth::default(),
        coil: CoilThermal::new(COIL_START_C),
        sensor: Tmp117::new(COIL_SENSOR),
    };
    let sf_cfg = ScaleFactorConfig::from_record(&FOG_SF_RECORD, &cfg, sensor_dt_s);
    if sf_cfg.coeffs_refused {
        defmt::warn!("FOG scale-factor record refused: running without temperature compensation");
    }
    let bench = || Bench {
        ticks_sum: 0,
        ticks_max: 0,
        n: 0,
    };
    cortex_m::interrupt::free(|cs| {
        // The rig (2.6 kB) is built in place, not moved in from a local.
        CTX.borrow(cs).replace(Some(Ctx {
            rig: FogRig::new(cfg, optics, profile),
            rlg,
            rlg_bench: bench(),
            fog_thermal,
            sf_bench: bench(),
            sf_sensor_bench: bench(),
            out: FramePath::new(
                FrameBuilder::new(CLOSURES_PER_FRAME, cfg.n_half),
                tx,
                sf_cfg,
            ),
            counter: 0,
            total,
            bench: bench(),
        }));
        if let Some(c) = CTX.borrow(cs).borrow_mut().as_mut() {
            set_fog_truth(&mut c.rig, &c.fog_thermal.truth, 0.5 / RLG_HZ as f64);
        }
    });
    defmt::info!(
        "gyro-fw qemu: FOG closure at {} Hz, {} steps, frames every {} steps",
        CLOSURE_HZ,
        total,
        CLOSURES_PER_FRAME
    );

    let syst = &mut cp.SYST;
    syst.set_clock_source(SystClkSource::Core);
    syst.set_reload(RELOAD);
    syst.clear_current();
    syst.enable_interrupt();
    syst.enable_counter();

    let mut sent = 0u32;
    loop {
        while let Some(f) = rx.dequeue() {
            uart::write(&dp.USART1, &f.encode());
            sent += 1;
        }
        if DONE.load(Ordering::Acquire) && !rx.ready() {
            break;
        }
        cortex_m::asm::wfi();
    }
    syst.disable_interrupt();
    let [(sum, max, n), (rsum, rmax, rn), (fsum, fmax, fn_), (ssum, smax, sn)] =
        cortex_m::interrupt::free(|cs| {
            CTX.borrow(cs)
                .borrow()
                .as_ref()
                .map_or([(0, 0, 0); 4], |c| {
                    [&c.bench, &c.rlg_bench, &c.sf_bench, &c.sf_sensor_bench]
                        .map(|b| (b.ticks_sum, b.ticks_max, b.n))
                })
        });
    let mean_instr = sum as f32 / n.max(1) as f32 * ipt;
    defmt::info!("frames sent: {}", sent);
    defmt::info!(
        "bench: fog_closure_instructions={} max={} stack_bytes={}",
        mean_instr as u32,
        (max as f32 * ipt) as u32,
        stack::high_water()
    );
    defmt::info!(
        "bench: rlg_update_instructions={} rlg_max={}",
        (rsum as f32 / rn.max(1) as f32 * ipt) as u32,
        (rmax as f32 * ipt) as u32
    );
    defmt::info!(
        "bench: fog_sf_frame_instructions={} sf_frame_max={} fog_sf_sensor_instructions={} sf_sensor_max={}",
        (fsum as f32 / fn_.max(1) as f32 * ipt) as u32,
        (fmax as f32 * ipt) as u32,
        (ssum as f32 / sn.max(1) as f32 * ipt) as u32,
        (smax as f32 * ipt) as u32
    );
    cortex_m_semihosting::debug::exit(cortex_m_semihosting::debug::EXIT_SUCCESS);
    loop {
        cortex_m::asm::wfi();
    }
}

#[cortex_m_rt::entry]
fn main() -> ! {
    run()
}

#[exception]
fn SysTick() {
    cortex_m::interrupt::free(|cs| {
        if let Some(ctx) = CTX.borrow(cs).borrow_mut().as_mut() {
            closure(ctx);
        }
    });
}

fn closure(ctx: &mut Ctx) {
    if ctx.counter >= ctx.total {
        DONE.store(true, Ordering::Release);
        return;
    }
    ctx.rig.optics.p.power = if POWER_LOSS.contains(&ctx.counter) {
        0.05
    } else {
        1.0
    };
    let truth = ctx.rig.simulate_optics();
    let t0 = SYST::get_current();
    let out = ctx.rig.process_core();
    let t1 = SYST::get_current();
    ctx.bench.record(t0, t1);
    ctx.rig.finish_step(out, truth);
    ctx.counter += 1;
    if out.faults.has(Faults::OPTICAL_POWER_LOW) && ctx.counter == POWER_LOSS.start + 1 {
        defmt::warn!("optical power low at step {}", ctx.counter);
    }
    if ctx.out.frame_ends() {
        rlg_update(ctx);
        fog_thermal_update(ctx);
    }
    if let Some(mut f) = ctx.out.push(&out) {
        // The frame path's work: the scale-factor table at the coil
        // temperature, applied to the frame's angle.
        let t0 = SYST::get_current();
        ctx.out.compensate(&mut f);
        let t1 = SYST::get_current();
        ctx.sf_bench.record(t0, t1);
        ctx.out.send(f);
    }
}

/// One RLG update: the chamber advances one update period, the counter is
/// read; on sensor ticks the three TMP117s are read and the compensation runs
/// (what the bench times: counter read + compensation, the update interrupt's
/// work). The frame gets the RLG words.
fn rlg_update(ctx: &mut Ctx) {
    let r = &mut ctx.rlg;
    let dt = 1.0 / RLG_HZ as f64;
    let t_mid = (r.updates as f64 + 0.5) * dt;
    let rate_dps = ctx.rig.profile.rate_at(t_mid as f32) as f64 * (180.0 / core::f64::consts::PI);
    let s = r.chamber.step(dt, 20.0, rate_dps);
    r.bus.temps_c[..3].copy_from_slice(&[s.t_mono_a_c, s.t_mono_b_c, s.t_case_c]);
    r.bus.nack = CASE_NACK.contains(&r.updates).then_some(0x4A);
    let temps = r
        .updates
        .is_multiple_of(SENSOR_EVERY)
        .then(|| Temperatures {
            mono_a_q8: r.sensors[0].read(&mut r.bus),
            mono_b_q8: r.sensors[1].read(&mut r.bus),
            case_q8: r.sensors[2].read(&mut r.bus),
        });
    let t0 = SYST::get_current();
    r.ch.update(&r.cfg, s.counter, temps.as_ref());
    let t1 = SYST::get_current();
    if temps.is_some() {
        ctx.rlg_bench.record(t0, t1);
    }
    r.updates += 1;
    let (counts, n) = r.ch.take_frame();
    ctx.out.set_rlg(r.ch.words(&r.cfg, counts, n));
}

/// The rig's scale-factor error and bias for the frame centred on closure
/// time `t_mid`: the truth at the coil temperature then, for the rate's sign.
fn set_fog_truth(rig: &mut FogRig<f32>, truth: &ScaleFactorTruth, t_mid: f64) {
    let rate = rig.profile.rate_at(t_mid as f32);
    let sign = if rate > 0.0 {
        1.0
    } else if rate < 0.0 {
        -1.0
    } else {
        0.0
    };
    let t_c = coil_at(t_mid);
    rig.scale_error = (truth.sf_ppm(t_c, sign) * 1e-6) as f32;
    rig.bias_rad_s = (truth.bias_dph(t_c) / 3600.0 * core::f64::consts::PI / 180.0) as f32;
}

/// Once per frame: the coil sensor (lagging the coil) is read through the
/// TMP117 driver and the table's state advances (what the bench times);
/// the rig takes the truth for the next frame.
fn fog_thermal_update(ctx: &mut Ctx) {
    let frame_s = CLOSURES_PER_FRAME as f64 / CLOSURE_HZ as f64;
    let t = ctx.counter as f64 / CLOSURE_HZ as f64;
    let th = &mut ctx.fog_thermal;
    let sensor_c = th.coil.step_coil(frame_s * THERMAL_TIME_SCALE, coil_at(t));
    let bus = &mut ctx.rlg.bus;
    bus.temps_c[3] = sensor_c;
    let read = th.sensor.read(bus);
    let t0 = SYST::get_current();
    ctx.out.coil_reading(read);
    let t1 = SYST::get_current();
    ctx.sf_sensor_bench.record(t0, t1);
    set_fog_truth(&mut ctx.rig, &ctx.fog_thermal.truth, t + 0.5 * frame_s);
}

/// Instructions per SysTick tick, measured on a loop of known length
/// (2 instructions per turn), so the bench does not assume QEMU's clock.
fn instructions_per_tick(syst: &mut SYST) -> f32 {
    const TURNS: u32 = 20_000;
    syst.set_clock_source(SystClkSource::Core);
    syst.set_reload(0x00FF_FFFF);
    syst.clear_current();
    syst.enable_counter();
    let t0 = SYST::get_current();
    unsafe {
        core::arch::asm!("1:", "subs {0}, #1", "bne 1b", inout(reg) TURNS => _, options(nomem, nostack));
    }
    let t1 = SYST::get_current();
    syst.disable_counter();
    (2 * TURNS) as f32 / (t0.wrapping_sub(t1) & 0x00FF_FFFF).max(1) as f32
}

fn fail() -> ! {
    cortex_m_semihosting::debug::exit(cortex_m_semihosting::debug::EXIT_FAILURE);
    loop {
        cortex_m::asm::wfi();
    }
}

/// Safe path: log, then leave QEMU with a failure status (the host test sees it).
#[panic_handler]
fn panic(info: &core::panic::PanicInfo) -> ! {
    cortex_m::interrupt::disable();
    if let Some(l) = info.location() {
        defmt::error!("panic at {}:{}", l.file(), l.line());
    }
    fail()
}
