//! `qemu` board: netduinoplus2 (STM32F405) in qemu-system-arm, on RTIC 2 like
//! the hw board. The gyro is simulated on-chip with the same model as on the
//! host (in f32). The closure task is bound to SysTick at 12.5 kHz (highest
//! priority): QEMU models neither the ADC's DMA nor the RCC (its ready bits
//! read 0, so the HAL's clock setup would wait forever), so this board keeps
//! the reset clocks and a core timer. Under `-icount shift=0` one instruction
//! is 1 ns of virtual time, so the run is deterministic and SysTick (core
//! clock) counts instructions.
//!
//! The RLG update is a lower-priority task bound to TIM5, as on the hw board,
//! pended once per frame (500 Hz) by the idle loop at a phase that sweeps the
//! closure period, so some closures arrive while it runs: the closure's
//! latency (SysTick wrap to its last DAC word) is measured with and without
//! the RLG update in progress. The RLG is a mechanically dithered gyro in a
//! simulated chamber (`sim::DitheredChamber`: `sim::Chamber`, the model of
//! `gyro-lab simulate chamber`, gives the true rate and the temperatures;
//! `sim::DitheredRlg`, the model of `gyro-lab simulate dither`, turns it into
//! the encoder counter and the dither pickoff's zero crossings). The build
//! script records that gyro on the host (the pulse stream a board's timers
//! would latch: simulating it on the emulated CPU cost more than the FOG's
//! optics); the RLG task plays it back. Each crossing goes to the channel's
//! latch (the stripping the hw board's TIM3 interrupt runs, timed by the
//! bench), each update reads the counter and takes the stripped angle;
//! three simulated TMP117s answer on a simulated I2C bus through the real
//! driver. The case sensor stops
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
//!
//! Missed closures: QEMU has no ADC DMA, so the board keeps a simulated one
//! ([`VirtualDma`]) on TIM2's free-running count (QEMU's timer runs on
//! virtual time) and judges it with the hw board's `overrun::judge`. Once,
//! in the final rest segment, the idle loop masks interrupts for 2.2 closure
//! periods: the next closure's samples are overwritten before
//! it can run, the rig's optics run on without the core, and the frame
//! carries the fault and the count.

#![no_std]
#![no_main]

use core::sync::atomic::{AtomicBool, AtomicU32, Ordering};
use cortex_m::peripheral::{syst::SystClkSource, SYST};
use defmt_semihosting as _;
use gyro_fw::app::{
    fog_params, FramePath, FrameQueue, RlgQueue, CLOSURES_PER_FRAME, CLOSURE_HZ, FOG_SF_RECORD,
    RLG_HZ, RLG_RECORD, SAMPLES_PER_HALF, SENSOR_EVERY,
};
use gyro_fw::overrun::judge;
use gyro_fw::{stack, uart};
use gyro_sim::rlg_dither_rig::{qemu_dither_params, LATCH_CLOCK_HZ};
use gyro_sim::{
    profile::qemu_demo, ChamberParams, CoilThermal, FogRig, OpticsParams, ScaleFactorTruth,
};
use gyro_sp::fog::scale_factor::ScaleFactorConfig;
use gyro_sp::fog::{Faults, FogConfig};
use gyro_sp::frame::{FrameBuilder, ResetCause};
use gyro_sp::rlg::thermal::{Temperatures, ThermalConfig};
use gyro_sp::rlg::{LatchSample, RlgChannel, RlgConfig, StripConfig};
use heapless::spsc::{Consumer, Producer};
use tmp117::Tmp117;

mod bench;
mod sim_i2c;
mod virtual_dma;

use bench::{ticks_between, Bench, ClosureBenches};
use sim_i2c::SimI2c;
use virtual_dma::VirtualDma;

/// SysTick clock of the emulated STM32F405 (QEMU's SYSCLK).
const CORE_HZ: u32 = 168_000_000;
const RELOAD: u32 = CORE_HZ / CLOSURE_HZ - 1;
/// Optical power loss injected during these closures (the final rest segment).
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
/// The idle loop holds the closure off for 2.2 periods once it has run
/// this many closures (in the final rest segment, after the power loss).
const OVERRUN_AT: u32 = 29_200;
/// ADC samples per closure, as the hw DMA counts them.
const ADC_PER_CLOSURE: u16 = (SAMPLES_PER_HALF * 16) as u16;

/// Set by the closure after its last closure; the idle loop then reports.
static DONE: AtomicBool = AtomicBool::new(false);
/// Set by the closure `RLG_LEAD` closures before a frame ends: the idle loop
/// pends the RLG update, which must deliver before the frame completes (the
/// simulated dithered gyro makes the task several closure periods long).
static RLG_DUE: AtomicBool = AtomicBool::new(false);
/// True while the RLG update task runs (the closure's latency is binned by it).
static RLG_RUNNING: AtomicBool = AtomicBool::new(false);
/// True while the idle loop sleeps: QEMU's wake from WFI skews SysTick's
/// count (it reads as if the wrap had just happened a period late), so
/// those closures' latency is not measured.
static SLEEPING: AtomicBool = AtomicBool::new(false);
/// Closures run so far: the RLG bench drops a timing a closure preempted.
static CLOSURES: AtomicU32 = AtomicU32::new(0);
/// Closures between pending the RLG update and the frame's end.
const RLG_LEAD: u32 = 12;
/// Closures before the frame's end at which the closure starts it itself.
const RLG_LAST_START: u32 = 6;

/// One update of the recorded dithered gyro: the encoder counter at the
/// update's instant (latch clock ticks), the end of its crossings in
/// `RLG_LATCHES`, and the three sensors' temperatures.
pub struct StimulusUpdate {
    time: u32,
    counter: u16,
    latches_end: u32,
    temps_c: [f32; 3],
}

// The recorded dithered gyro (build.rs): `RLG_UPDATES`, `RLG_LATCHES`.
include!(concat!(env!("OUT_DIR"), "/rlg_stimulus.rs"));
// build.rs records at the firmware's update rate.
const _: () = assert!(RLG_HZ == 500);

/// The RLG update task's state: the channel, the dithered gyro in the
/// simulated chamber on the same rate profile, and its three sensors.
pub struct Rlg {
    cfg: RlgConfig,
    ch: RlgChannel,
    bus: SimI2c,
    sensors: [Tmp117; 3],
    updates: u32,
    bench: Bench,
    /// One pickoff crossing through the channel's latch (the stripping).
    latch: Bench,
    /// Updates past the recorded gyro's end (its last state held).
    held: u32,
    /// The whole task, simulated chamber included (preemptions included).
    task: Bench,
    words: Producer<'static, gyro_sp::rlg::RlgWords, { gyro_fw::app::RLG_QUEUE_LEN }>,
}

/// The FOG's temperature: truth, coil and its sensor.
pub struct FogThermal {
    truth: ScaleFactorTruth,
    coil: CoilThermal,
    sensor: Tmp117,
    bus: SimI2c,
}

/// Coil temperature at closure time `t_s`, degC.
fn coil_at(t_s: f64) -> f64 {
    COIL_START_C + COIL_RATE_C_PER_S * t_s
}

#[rtic::app(device = stm32f4::stm32f405, peripherals = true)]
mod app {
    use super::*;

    #[shared]
    struct Shared {
        /// Filled once at the end, read by idle for the summary.
        closure_benches: Option<ClosureBenches>,
        rlg_bench: Option<(Bench, Bench, Bench, u32)>,
    }

    #[local]
    struct Local {
        rig: &'static mut FogRig<f32>,
        out: FramePath,
        rlg_words: Consumer<'static, gyro_sp::rlg::RlgWords, { gyro_fw::app::RLG_QUEUE_LEN }>,
        fog_thermal: FogThermal,
        benches: ClosureBenches,
        counter: u32,
        total: u32,
        rlg: Rlg,
        frames: Consumer<'static, gyro_sp::frame::Frame, { gyro_fw::app::FRAME_QUEUE_LEN }>,
        usart: stm32f4::stm32f405::USART1,
        ipt: f32,
        dma: VirtualDma,
        tim2: stm32f4::stm32f405::TIM2,
    }

    #[init(local = [
        frame_queue: FrameQueue = FrameQueue::new(),
        rlg_queue: RlgQueue = RlgQueue::new(),
    ])]
    fn init(cx: init::Context) -> (Shared, Local) {
        stack::paint();
        let mut syst = cx.core.SYST;
        uart::init(&cx.device.USART1, 42);
        // TIM2 free-running on QEMU's virtual clock: the simulated DMA's time.
        let tim2 = cx.device.TIM2;
        tim2.psc().write(|w| w.psc().set(0));
        tim2.arr().write(|w| unsafe { w.bits(u32::MAX) });
        tim2.egr().write(|w| w.ug().set_bit());
        tim2.cr1().modify(|_, w| w.cen().set_bit());
        let (ipt, tim2_per_tick) = instructions_per_tick(&mut syst, &tim2);

        let params = fog_params(0);
        let mut optics =
            OpticsParams::<f32>::nominal(params.tau_s as f32, SAMPLES_PER_HALF, 49_152);
        optics.adc_bits = 12;
        let params = optics.matched(params);
        let Ok(cfg) = FogConfig::new(params) else {
            fail()
        };
        let (profile, _) = qemu_demo::<f32>();
        let total = (profile.total_duration() * CLOSURE_HZ as f32) as u32;
        let (tx, frames) = cx.local.frame_queue.split();
        let (words, rlg_words) = cx.local.rlg_queue.split();
        let thermal = ThermalConfig::from_record(&RLG_RECORD, SENSOR_EVERY as f64 / RLG_HZ as f64);
        if thermal.coeffs_default {
            defmt::warn!("RLG coefficient record refused: running without thermal compensation");
        }
        let chamber_p = ChamberParams::default();
        let gyro = qemu_dither_params(&chamber_p);
        let drift = 1.0 + gyro.fd_drift_frac;
        let pd = gyro.photodiodes.offset;
        let strip = StripConfig::new(
            LATCH_CLOCK_HZ,
            gyro.dither_hz / drift,
            gyro.dither_hz * drift,
            [pd[0] as i32, pd[1] as i32],
        );
        let rlg = Rlg {
            cfg: RlgConfig::new(thermal, chamber_p.counts_per_deg, RLG_HZ).with_dither(strip),
            ch: RlgChannel::default(),
            bus: SimI2c::new(),
            sensors: [Tmp117::new(0x48), Tmp117::new(0x49), Tmp117::new(0x4A)],
            updates: 0,
            bench: Bench::default(),
            latch: Bench::default(),
            held: 0,
            task: Bench::default(),
            words,
        };
        // One coil sensor read per frame, 2 s of thermal time.
        let sensor_dt_s = THERMAL_TIME_SCALE * CLOSURES_PER_FRAME as f64 / CLOSURE_HZ as f64;
        let fog_thermal = FogThermal {
            truth: ScaleFactorTruth::default(),
            coil: CoilThermal::new(COIL_START_C),
            sensor: Tmp117::new(COIL_SENSOR),
            bus: SimI2c::new(),
        };
        // Built in its static, as the rig is, not moved through the stack.
        let Some(sf_cfg) = cortex_m::singleton!(: ScaleFactorConfig =
            ScaleFactorConfig::from_record(&FOG_SF_RECORD, &cfg, sensor_dt_s))
        else {
            fail()
        };
        if sf_cfg.coeffs_refused {
            defmt::warn!(
                "FOG scale-factor record refused: running without temperature compensation"
            );
        }
        // The rig (2.6 kB) is built in its static, not moved through the stack.
        let Some(rig) = cortex_m::singleton!(: FogRig<f32> = FogRig::new(cfg, optics, profile))
        else {
            fail()
        };
        set_fog_truth(rig, &fog_thermal.truth, 0.5 / RLG_HZ as f64);
        defmt::info!(
            "gyro-fw qemu: FOG closure at {} Hz, {} steps, frames every {} steps",
            CLOSURE_HZ,
            total,
            CLOSURES_PER_FRAME
        );
        syst.set_clock_source(SystClkSource::Core);
        syst.set_reload(RELOAD);
        syst.clear_current();
        syst.enable_interrupt();
        let dma = VirtualDma::new(tim2_per_tick, tim2.cnt().read().bits());
        syst.enable_counter();
        (
            Shared {
                closure_benches: None,
                rlg_bench: None,
            },
            Local {
                rig,
                // A QEMU run always starts from power-on (QEMU models no
                // RCC reset flags to read).
                out: FramePath::new(
                    FrameBuilder::new(CLOSURES_PER_FRAME, cfg.n_half),
                    tx,
                    sf_cfg,
                    ResetCause::PowerOn,
                ),
                rlg_words,
                fog_thermal,
                benches: ClosureBenches::default(),
                counter: 0,
                total,
                rlg,
                frames,
                usart: cx.device.USART1,
                ipt,
                dma,
                tim2,
            },
        )
    }

    /// Sends the frames, pends the RLG update at a phase that sweeps the
    /// closure period (golden-ratio sequence), and reports at the end.
    #[idle(local = [frames, usart, ipt], shared = [closure_benches, rlg_bench])]
    fn idle(mut cx: idle::Context) -> ! {
        let mut sent = 0u32;
        let mut overrun_done = false;
        let mut phase = 0u32;
        // SysTick count at the last poll while an RLG update is due.
        let mut last = u32::MAX;
        loop {
            while let Some(f) = cx.local.frames.dequeue() {
                uart::write(cx.local.usart, &f.encode());
                sent += 1;
            }
            if RLG_DUE.load(Ordering::Acquire) {
                // Ticks left before the next closure at which the RLG
                // starts; a closure in between (the count went up) starts
                // it at once, so it still delivers before the frame ends.
                let target = ((phase as u64 * RELOAD as u64) >> 32) as u32 + 1;
                let now = SYST::get_current();
                if now <= target || now > last {
                    phase = phase.wrapping_add(0x9E37_79B9);
                    RLG_DUE.store(false, Ordering::Release);
                    rtic::pend(stm32f4::stm32f405::Interrupt::TIM5);
                    last = u32::MAX;
                } else {
                    last = now;
                }
                continue;
            }
            if !overrun_done && CLOSURES.load(Ordering::Relaxed) >= OVERRUN_AT {
                // Fault injection: the closure held off for 2.2 periods (a
                // long critical section), as a late DMA interrupt would be.
                // It starts just after a closure ends, so the closures it
                // blocks (and the count missed) do not depend on how long
                // the USART made the idle loop wait: a pty whose reader
                // lags must give the same run as a file.
                overrun_done = true;
                let turns = (2.2 * (RELOAD + 1) as f32 * *cx.local.ipt / 2.0) as u32;
                let before = CLOSURES.load(Ordering::Relaxed);
                while CLOSURES.load(Ordering::Relaxed) == before {}
                cortex_m::interrupt::free(|_| spin(turns));
            }
            if DONE.load(Ordering::Acquire) && !cx.local.frames.ready() {
                break;
            }
            SLEEPING.store(true, Ordering::Relaxed);
            cortex_m::asm::wfi();
            SLEEPING.store(false, Ordering::Relaxed);
        }
        let b = cx.shared.closure_benches.lock(|b| *b).unwrap_or_default();
        let (rlg, rlg_task, latch, held) = cx.shared.rlg_bench.lock(|b| *b).unwrap_or_default();
        let ipt = *cx.local.ipt;
        let (mean, max) = b.core.instructions(ipt);
        defmt::info!("frames sent: {}", sent);
        defmt::info!(
            "bench: fog_closure_instructions={} max={} stack_bytes={}",
            mean,
            max,
            stack::high_water()
        );
        let (rmean, rmax) = rlg.instructions(ipt);
        let (tmean, tmax) = rlg_task.instructions(ipt);
        defmt::info!(
            "bench: rlg_update_instructions={} rlg_max={} rlg_task_with_chamber={} rlg_task_max={}",
            rmean,
            rmax,
            tmean,
            tmax
        );
        let (amean, amax) = latch.instructions(ipt);
        defmt::info!(
            "bench: rlg_latch_instructions={} rlg_latch_max={} rlg_latches={} rlg_frames_late={} rlg_late_at={} rlg_stimulus_held={}",
            amean,
            amax,
            latch.n,
            b.rlg_late,
            b.rlg_late_at,
            held
        );
        let (fmean, fmax) = b.sf_frame.instructions(ipt);
        let (smean, smax) = b.sf_sensor.instructions(ipt);
        defmt::info!(
            "bench: fog_sf_frame_instructions={} sf_frame_max={} fog_sf_sensor_instructions={} sf_sensor_max={}",
            fmean,
            fmax,
            smean,
            smax
        );
        let (omean, omax) = b.overrun_check.instructions(ipt);
        defmt::info!(
            "bench: overrun_check_instructions={} overrun_check_max={} closures_missed={} missed_at={}",
            omean,
            omax,
            b.missed,
            b.missed_at
        );
        let (lmean, lmax) = b.latency_alone.instructions(ipt);
        let (rl_mean, rl_max) = b.latency_under_rlg.instructions(ipt);
        defmt::info!(
            "bench: closure_latency_instructions={} closure_latency_max={} closure_latency_under_rlg={} closure_latency_under_rlg_max={} closures_under_rlg={}",
            lmean,
            lmax,
            rl_mean,
            rl_max,
            b.latency_under_rlg.n
        );
        cortex_m_semihosting::debug::exit(cortex_m_semihosting::debug::EXIT_SUCCESS);
        loop {
            cortex_m::asm::wfi();
        }
    }

    /// The closure (highest priority): optics simulated, the FOG core run,
    /// the frame assembled. Shares nothing the RLG update locks.
    #[task(binds = SysTick, priority = 2,
           local = [rig, out, rlg_words, fog_thermal, benches, counter, total, dma, tim2],
           shared = [closure_benches])]
    fn closure(mut cx: closure::Context) {
        // Ticks since the SysTick wrap raised this interrupt.
        let entry = RELOAD.saturating_sub(SYST::get_current());
        // The DMA's registers, and the hw board's verdict on them.
        let woke = SLEEPING.load(Ordering::Relaxed);
        let (state, periods) =
            cx.local
                .dma
                .read(cx.local.tim2.cnt().read().bits(), SYST::get_current(), woke);
        let j0 = SYST::get_current();
        let verdict = judge(state, ADC_PER_CLOSURE, periods);
        let j1 = SYST::get_current();
        CLOSURES.fetch_add(1, Ordering::Relaxed);
        let rlg_busy = RLG_RUNNING.load(Ordering::Relaxed)
            || cortex_m::peripheral::NVIC::is_pending(stm32f4::stm32f405::Interrupt::TIM5);
        let l = cx.local;
        l.benches.overrun_check.record(j0, j1);
        if verdict.missed > 0 {
            // The missed closures' samples are gone: the optics run on, the
            // core does not see them, the frame counts them.
            // Bounded: a verdict can never stall the closure.
            for _ in 0..verdict.missed.min(64) {
                l.rig.skip_closure();
            }
            if l.benches.missed == 0 {
                l.benches.missed_at = *l.counter;
            }
            l.benches.missed += verdict.missed;
            l.out.lost(verdict.missed, Faults::CLOSURE_OVERRUN);
        }
        if *l.counter >= *l.total {
            if !DONE.swap(true, Ordering::AcqRel) {
                let b = *l.benches;
                cx.shared.closure_benches.lock(|s| *s = Some(b));
            }
            return;
        }
        l.rig.optics.p.power = if POWER_LOSS.contains(l.counter) {
            0.05
        } else {
            1.0
        };
        let truth = l.rig.simulate_optics();
        let t0 = SYST::get_current();
        let out = l.rig.process_core();
        let t1 = SYST::get_current();
        l.benches.core.record(t0, t1);
        let latency = entry + ticks_between(t0, t1);
        if woke || verdict.missed > 0 {
            // Not measured (see SLEEPING).
        } else if rlg_busy {
            l.benches.latency_under_rlg.add(latency);
        } else {
            l.benches.latency_alone.add(latency);
        }
        l.rig.finish_step(out, truth);
        *l.counter += 1;
        if out.faults.contains(Faults::OPTICAL_POWER_LOW) && *l.counter == POWER_LOSS.start + 1 {
            defmt::warn!("optical power low at step {}", *l.counter);
        }
        let to_frame_end = CLOSURES_PER_FRAME as u32 - *l.counter % CLOSURES_PER_FRAME as u32;
        if to_frame_end == RLG_LEAD {
            RLG_DUE.store(true, Ordering::Release);
        } else if to_frame_end == RLG_LAST_START && RLG_DUE.swap(false, Ordering::AcqRel) {
            // The idle loop has not started it: start it now, so it still
            // delivers before the frame ends.
            rtic::pend(stm32f4::stm32f405::Interrupt::TIM5);
        }
        if l.out.frame_ends() {
            let mut got = 0;
            while let Some(w) = l.rlg_words.dequeue() {
                l.out.set_rlg(w);
                got += 1;
            }
            if got != 1 {
                if l.benches.rlg_late == 0 {
                    l.benches.rlg_late_at = *l.counter / CLOSURES_PER_FRAME as u32;
                }
                l.benches.rlg_late += 1;
            }
            fog_thermal_update(
                l.rig,
                l.fog_thermal,
                l.out,
                &mut l.benches.sf_sensor,
                *l.counter,
            );
        }
        if let Some(mut f) = l.out.push(&out) {
            // The frame path's work: the scale-factor table at the coil
            // temperature, applied to the frame's angle.
            let t0 = SYST::get_current();
            l.out.compensate(&mut f);
            let t1 = SYST::get_current();
            l.benches.sf_frame.record(t0, t1);
            l.out.send(f);
        }
    }

    /// One RLG update (lower priority, preempted by the closure): the
    /// dithered gyro advances one update period, each pickoff crossing on
    /// the way goes to the channel's latch (as the hw board's TIM3
    /// interrupt does; the bench times each), then the counter is read; on
    /// sensor ticks the three TMP117s are read and the compensation runs
    /// (the bench times counter read + stripped angle + compensation, the
    /// hw update task's work). The frame words go to the closure through a
    /// lock-free queue.
    #[task(binds = TIM5, priority = 1, local = [rlg], shared = [rlg_bench])]
    fn rlg_update(mut cx: rlg_update::Context) {
        RLG_RUNNING.store(true, Ordering::Relaxed);
        let start = SYST::get_current();
        let r = &mut *cx.local.rlg;
        // The recorded gyro's update; past the record's end (it covers the
        // profile and 64 updates more) the gyro's last state holds.
        let k = (r.updates as usize).min(RLG_UPDATES.len() - 1);
        let u = &RLG_UPDATES[k];
        let first = k
            .checked_sub(1)
            .map_or(0, |p| RLG_UPDATES[p].latches_end as usize);
        let crossings = if r.updates as usize == k {
            RLG_LATCHES
                .get(first..u.latches_end as usize)
                .unwrap_or(&[])
        } else {
            r.held += 1;
            &[]
        };
        for sample in crossings {
            let closures = CLOSURES.load(Ordering::Relaxed);
            let t0 = SYST::get_current();
            r.ch.latch(&r.cfg, sample);
            let t1 = SYST::get_current();
            if CLOSURES.load(Ordering::Relaxed) == closures {
                r.latch.record(t0, t1);
            }
        }
        let [a, b, c] = u.temps_c;
        r.bus.temps_c[..3].copy_from_slice(&[a as f64, b as f64, c as f64]);
        r.bus.nack = CASE_NACK.contains(&r.updates).then_some(0x4A);
        let temps = r
            .updates
            .is_multiple_of(SENSOR_EVERY)
            .then(|| Temperatures {
                mono_a_q8: r.sensors[0].read(&mut r.bus),
                mono_b_q8: r.sensors[1].read(&mut r.bus),
                case_q8: r.sensors[2].read(&mut r.bus),
            });
        let closures = CLOSURES.load(Ordering::Relaxed);
        let t0 = SYST::get_current();
        r.ch.update(&r.cfg, u.time, u.counter, temps.as_ref());
        let t1 = SYST::get_current();
        if temps.is_some() && CLOSURES.load(Ordering::Relaxed) == closures {
            r.bench.record(t0, t1);
        }
        r.updates += 1;
        let span = r.ch.take_frame();
        // Full only if the closure has stopped taking them; the counts then
        // stay in the channel for the next update's words.
        if r.words.enqueue(r.ch.words(&r.cfg, &span)).is_err() {
            r.ch.restore_frame(span);
        }
        r.task.record(start, SYST::get_current());
        let b = (r.bench, r.task, r.latch, r.held);
        cx.shared.rlg_bench.lock(|s| *s = Some(b));
        RLG_RUNNING.store(false, Ordering::Relaxed);
    }
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
fn fog_thermal_update(
    rig: &mut FogRig<f32>,
    th: &mut FogThermal,
    out: &mut FramePath,
    bench: &mut Bench,
    counter: u32,
) {
    let frame_s = CLOSURES_PER_FRAME as f64 / CLOSURE_HZ as f64;
    let t = counter as f64 / CLOSURE_HZ as f64;
    let sensor_c = th.coil.step_coil(frame_s * THERMAL_TIME_SCALE, coil_at(t));
    th.bus.temps_c[3] = sensor_c;
    let read = th.sensor.read(&mut th.bus);
    let t0 = SYST::get_current();
    out.coil_reading(read);
    let t1 = SYST::get_current();
    bench.record(t0, t1);
    set_fog_truth(rig, &th.truth, t + 0.5 * frame_s);
}

/// Instructions per SysTick tick, measured on a loop of known length
/// (2 instructions per turn), so the bench does not assume QEMU's clock;
/// and TIM2 ticks per SysTick tick over the same loop (the simulated DMA's
/// period).
fn instructions_per_tick(syst: &mut SYST, tim2: &stm32f4::stm32f405::TIM2) -> (f32, f32) {
    const TURNS: u32 = 20_000;
    syst.set_clock_source(SystClkSource::Core);
    syst.set_reload(0x00FF_FFFF);
    syst.clear_current();
    syst.enable_counter();
    let t0 = SYST::get_current();
    let c0 = tim2.cnt().read().bits();
    spin(TURNS);
    let t1 = SYST::get_current();
    let c1 = tim2.cnt().read().bits();
    syst.disable_counter();
    let ticks = (t0.wrapping_sub(t1) & 0x00FF_FFFF).max(1) as f32;
    (
        (2 * TURNS) as f32 / ticks,
        c1.wrapping_sub(c0) as f32 / ticks,
    )
}

/// A loop of `turns` x 2 instructions.
fn spin(turns: u32) {
    if turns == 0 {
        return;
    }
    unsafe {
        core::arch::asm!("1:", "subs {0}, #1", "bne 1b", inout(reg) turns => _, options(nomem, nostack));
    }
}

fn fail() -> ! {
    cortex_m_semihosting::debug::exit(cortex_m_semihosting::debug::EXIT_FAILURE);
    loop {
        cortex_m::asm::wfi();
    }
}

/// A hard fault under QEMU: log where, then leave with a failure status
/// (the hw board resets instead and says so in its first frame).
#[cortex_m_rt::exception]
unsafe fn HardFault(ef: &cortex_m_rt::ExceptionFrame) -> ! {
    defmt::error!("HardFault at pc {=u32:#x}, lr {=u32:#x}", ef.pc(), ef.lr());
    fail()
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
