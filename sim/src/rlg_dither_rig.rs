//! The `qemu` board's RLG: a mechanically dithered gyro ([`DitheredRlg`])
//! in the thermal chamber ([`Chamber`]), driven by the firmware's rate
//! profile, one RLG update period at a time. The chamber gives the sensor
//! readings and the gyro's true rate (input, thermal bias, rate noise); the
//! dithered gyro turns that rate into the counter and the pickoff's
//! crossings. The firmware runs it on-chip; `cargo xtask` replays it on the
//! host to rebuild the truth the frames are judged against, as it rebuilds
//! the FOG's truth from the profile (the same inputs give the same run:
//! the update's instants and rates are functions of the update's index).

use crate::rlg_dither::{Accuracy, DitherParams, DitheredRlg, Latch, Reading};
use crate::{Chamber, ChamberParams, ChamberSample, Profile};
use num_traits::Float;

/// The chamber air (constant), degC.
pub const AIR_C: f64 = 20.0;

/// The dithered gyro of the `qemu` board: 400 Hz, 150 deg/s peak, 5 %
/// amplitude noise, lock-in 0.1 deg/s, the chamber's 8000 counts/deg;
/// `f_d` drifting by 1 % over 4 s (a thermal drift sped up, as the FOG's
/// coil sweep is, so the 2.4 s run sees it); `Accuracy::QEMU` (f32 in the
/// crossing windows).
pub fn qemu_dither_params(chamber: &ChamberParams) -> DitherParams {
    DitherParams {
        counts_per_deg: chamber.counts_per_deg,
        lock_in_dps: 0.1,
        dither_dps: 150.0,
        dither_hz: 400.0,
        noise_frac: 0.05,
        fd_drift_frac: 0.01,
        fd_drift_period_s: 4.0,
        accuracy: Accuracy::QEMU,
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

    /// The next update period: the profile's rate at its middle (rad/s, in
    /// the profile's float) held over it; `on_latch` gets each pickoff
    /// crossing on the way. Returns the state at its end.
    pub fn step(&mut self, profile: &Profile<F>, on_latch: impl FnMut(&Latch)) -> RigStep {
        let dt = 1.0 / self.update_hz as f64;
        let t_mid = (self.updates as f64 + 0.5) * dt;
        let rate = profile
            .rate_at(F::from(t_mid).unwrap_or(F::zero()))
            .to_f64()
            .unwrap_or(0.0);
        let rate_dps = rate * (180.0 / core::f64::consts::PI);
        let chamber = self.chamber.step(dt, AIR_C, rate_dps);
        self.updates += 1;
        let t_end = self.updates as f64 * dt;
        let gyro = self.gyro.advance(t_end, chamber.rate_true_dps, on_latch);
        RigStep { chamber, gyro }
    }
}
