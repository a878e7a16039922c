//! `qemu` board: netduinoplus2 (STM32F405) in qemu-system-arm. The gyro is
//! simulated on-chip with the same model as on the host (in f32); SysTick at
//! 12.5 kHz runs one closure step per interrupt. Under `-icount shift=0` one
//! instruction is 1 ns of virtual time, so the run is deterministic and SysTick
//! (core clock) measures the closure's instruction count.

use super::{stack, uart, FrameQueue, STEPS_PER_FRAME};
use core::cell::RefCell;
use core::sync::atomic::{AtomicBool, Ordering};
use cortex_m::interrupt::Mutex;
use cortex_m::peripheral::{syst::SystClkSource, SYST};
use cortex_m_rt::exception;
use defmt_semihosting as _;
use gyro_sp::fog::{Faults, FogConfig, FogParams};
use gyro_sp::frame::{Frame, FrameBuilder};
use gyro_sp::sim::{profile::qemu_demo, FogRig, OpticsParams};
use heapless::spsc::Producer;

/// SysTick clock of the emulated STM32F405 (QEMU's SYSCLK).
const CORE_HZ: u32 = 168_000_000;
const CLOSURE_HZ: u32 = 12_500;
const RELOAD: u32 = CORE_HZ / CLOSURE_HZ - 1;
/// Optical power loss injected during these steps (the final rest segment).
const POWER_LOSS: core::ops::Range<u32> = 28_500..28_750;

struct Bench {
    ticks_sum: u64,
    ticks_max: u32,
    n: u32,
}

struct Ctx {
    rig: FogRig<f32>,
    frames: FrameBuilder,
    tx: Producer<'static, Frame, 8>,
    counter: u32,
    total: u32,
    bench: Bench,
}

static CTX: Mutex<RefCell<Option<Ctx>>> = Mutex::new(RefCell::new(None));
static DONE: AtomicBool = AtomicBool::new(false);

pub fn run() -> ! {
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
    cortex_m::interrupt::free(|cs| {
        CTX.borrow(cs).replace(Some(Ctx {
            rig: FogRig::new(cfg, optics, profile),
            frames: FrameBuilder::new(STEPS_PER_FRAME, cfg.n_half),
            tx,
            counter: 0,
            total,
            bench: Bench {
                ticks_sum: 0,
                ticks_max: 0,
                n: 0,
            },
        }))
    });
    defmt::info!(
        "gyro-fw qemu: FOG closure at {} Hz, {} steps, frames every {} steps",
        CLOSURE_HZ,
        total,
        STEPS_PER_FRAME
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
    let (sum, max, n) = cortex_m::interrupt::free(|cs| {
        CTX.borrow(cs).borrow().as_ref().map_or((0, 0, 0), |c| {
            (c.bench.ticks_sum, c.bench.ticks_max, c.bench.n)
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
    cortex_m_semihosting::debug::exit(cortex_m_semihosting::debug::EXIT_SUCCESS);
    loop {
        cortex_m::asm::wfi();
    }
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
    // SysTick counts down and reloads at 0: a reload in between adds RELOAD + 1.
    let ticks = if t1 <= t0 {
        t0 - t1
    } else {
        t0 + RELOAD + 1 - t1
    };
    ctx.bench.ticks_sum += ticks as u64;
    ctx.bench.ticks_max = ctx.bench.ticks_max.max(ticks);
    ctx.bench.n += 1;
    ctx.rig.finish_step(out, truth);
    ctx.counter += 1;
    if out.faults.has(Faults::OPTICAL_POWER_LOW) && ctx.counter == POWER_LOSS.start + 1 {
        defmt::warn!("optical power low at step {}", ctx.counter);
    }
    if let Some(f) = ctx.frames.push(&out, ctx.counter) {
        if let Err(f) = ctx.tx.enqueue(f) {
            ctx.frames.restore(f);
        }
    }
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
