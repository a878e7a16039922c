//! The `qemu` board's RLG: a mechanically dithered gyro ([`DitheredRlg`])
//! in the thermal chamber ([`Chamber`]), driven by the firmware's built-in
//! rate profile, one RLG update period at a time. The chamber gives the
//! sensor readings and the gyro's true rate (input, thermal bias, rate
//! noise); the dithered gyro turns that rate into the counter and the
//! pickoff's crossings.
//!
//! It runs on the host, not on the emulated CPU: the firmware's build
//! script records it ([`qemu_stimulus`]) as the pulse stream the board's
//! timers would latch (each crossing's time, counter and photodiodes, each
//! update's counter and temperatures), and the firmware under QEMU plays
//! that back through the channel's latch and update. On the board the gyro
//! costs the CPU nothing; simulated on-chip its integration through the
//! lock-in band took 150k to 440k instructions per 2 ms update and, beside
//! the FOG's simulated optics in the vibration segment, made the RLG
//! update miss frames. `cargo xtask` calls the same function for the truth
//! the frames are judged against.

use crate::rlg_dither::{Accuracy, DitherParams, DitheredRlg, Latch, Reading};
use crate::{Chamber, ChamberParams, ChamberSample, Profile};
use num_traits::Float;

/// The chamber air (constant), degC.
pub const AIR_C: f64 = 20.0;

/// The latch clock the stimulus's times are counted in (the hw board's
/// TIM5: 84 MHz), ticks/s. Times are wrapping u32 ticks, as TIM5 counts.
pub const LATCH_CLOCK_HZ: u32 = 84_000_000;

/// Sub-steps of an update over which the profile's rate is held: the rate
/// is sampled every 0.25 ms (at 500 Hz updates), so the ramps and the
/// 60 Hz vibration move the angle smoothly between the pickoff's latches
/// (a staircase at the update period put kinks of up to `dr h/4` between
/// them).
pub const SUBSTEPS: u32 = 8;

/// The dithered gyro of the `qemu` board: 400 Hz, 150 deg/s peak, 5 %
/// amplitude noise, lock-in 0.1 deg/s, the chamber's 8000 counts/deg;
/// `f_d` drifting by 1 % over 4 s (a thermal drift sped up, as the FOG's
/// coil sweep is, so the 2.4 s run sees it). It runs on the host (at
/// build time for the stimulus, in `cargo xtask` for the truth), so at the
/// host's accuracy.
pub fn qemu_dither_params(chamber: &ChamberParams) -> DitherParams {
    DitherParams {
        counts_per_deg: chamber.counts_per_deg,
        lock_in_dps: 0.1,
        dither_dps: 150.0,
        dither_hz: 400.0,
        noise_frac: 0.05,
        fd_drift_frac: 0.01,
        fd_drift_period_s: 4.0,
        accuracy: Accuracy::HOST,
        seed: 33,
        ..DitherParams::default()
    }
}

/// One update period of the rig.
#[derive(Clone, Copy, Debug, Default)]
pub struct RigStep {
    /// Sensor readings and the thermal truth (its counter is not the
    /// board's: the dithered gyro's is).
    pub chamber: ChamberSample,
    /// The counter at the update's instant, and the truth.
    pub gyro: Reading,
}

/// The dithered RLG in the chamber on a rate profile.
pub struct DitheredChamber<F: Float> {
    pub chamber: Chamber,
    pub gyro: DitheredRlg<F>,
    update_hz: u32,
    updates: u32,
}

impl<F: Float> DitheredChamber<F> {
    /// The `qemu` board's rig, updated at `update_hz`.
    pub fn qemu(update_hz: u32) -> Self {
        let p = ChamberParams::default();
        Self {
            chamber: Chamber::new(p, AIR_C),
            gyro: DitheredRlg::new(qemu_dither_params(&p)),
            update_hz: update_hz.max(1),
            updates: 0,
        }
    }

    /// Updates done.
    pub fn updates(&self) -> u32 {
        self.updates
    }

    /// The next update period. The chamber steps once, at the profile's
    /// rate at the update's middle; its thermal bias and rate noise are
    /// held over the update, the profile's rate is sampled at each of
    /// [`SUBSTEPS`]' middles. `on_latch` gets each pickoff crossing on the
    /// way. Returns the state at the update's end.
    pub fn step(&mut self, profile: &Profile<F>, mut on_latch: impl FnMut(&Latch)) -> RigStep {
        let dt = 1.0 / self.update_hz as f64;
        let t0 = self.updates as f64 * dt;
        let rate_dps = |t: f64| {
            profile
                .rate_at(F::from(t).unwrap_or(F::zero()))
                .to_f64()
                .unwrap_or(0.0)
                * (180.0 / core::f64::consts::PI)
        };
        let mid_dps = rate_dps(t0 + 0.5 * dt);
        let chamber = self.chamber.step(dt, AIR_C, mid_dps);
        let offset_dps = chamber.rate_true_dps - mid_dps;
        self.updates += 1;
        let t_end = self.updates as f64 * dt;
        let h = dt / SUBSTEPS as f64;
        let mut gyro = Reading::default();
        for k in 0..SUBSTEPS {
            let t_to = if k + 1 == SUBSTEPS {
                t_end
            } else {
                t0 + (k + 1) as f64 * h
            };
            let rate = rate_dps(t0 + (k as f64 + 0.5) * h) + offset_dps;
            gyro = self.gyro.advance(t_to, rate, &mut on_latch);
        }
        RigStep { chamber, gyro }
    }
}

/// The `qemu` board's RLG stimulus: `updates` updates at `update_hz` of
/// the rig (f64, the host's accuracy) on the built-in profile
/// ([`crate::profile::qemu_demo`]). `on_latch` gets each pickoff crossing,
/// `on_update` each update's end, in time order. The build script and
/// `cargo xtask` both call it: the same inputs give the same numbers.
pub fn qemu_stimulus(
    update_hz: u32,
    updates: u32,
    mut on_update: impl FnMut(&RigStep),
    mut on_latch: impl FnMut(&Latch),
) {
    let (profile, _) = crate::profile::qemu_demo::<f64>();
    let mut rig = DitheredChamber::<f64>::qemu(update_hz);
    for _ in 0..updates {
        let s = rig.step(&profile, &mut on_latch);
        on_update(&s);
    }
}
