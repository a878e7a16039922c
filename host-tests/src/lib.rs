//! Helpers shared by the host tests: the firmware core closed around the
//! simulated gyro, with the truth alongside.

use gyro_sp::fog::{ClosureOutput, FogConfig, FogParams};
use gyro_sp::sim::{FogRig, OpticsParams, Profile, Segment};

pub const DEG: f64 = std::f64::consts::PI / 180.0;
pub const DPH: f64 = 3600.0 / DEG;

/// A rig with the reference instrument, detector matched to phi0.
pub fn rig(
    params: FogParams,
    tweak: impl FnOnce(&mut OpticsParams<f64>),
    profile: Profile<f64>,
) -> FogRig<f64> {
    let mut optics = OpticsParams::<f64>::nominal(
        params.tau_s,
        params.samples_per_half,
        params.dac_codes_per_turn,
    );
    tweak(&mut optics);
    let params = optics.matched(params);
    let cfg = FogConfig::new(params).expect("valid parameters");
    FogRig::new(cfg, optics, profile)
}

/// Mean of (output - truth) in deg/h over steps [from, to), corrected and raw.
pub struct Means {
    pub corrected_dph: f64,
    pub raw_dph: f64,
    pub last: ClosureOutput,
    pub faults_seen: u16,
}

pub fn mean_error(rig: &mut FogRig<f64>, from: u64, to: u64) -> Means {
    let lsb = rig.cfg.rad_s_per_step_lsb();
    let (mut c, mut r, mut n, mut faults) = (0.0, 0.0, 0.0, 0u16);
    let mut last = ClosureOutput::default();
    while rig.step_index() < to {
        let k = rig.step_index();
        let s = rig.step();
        if k >= from {
            c += s.out.step_corrected as f64 * lsb - s.true_rate;
            r += s.out.step as f64 * lsb - s.true_rate;
            n += 1.0;
            faults |= s.out.faults.0;
        }
        last = s.out;
    }
    Means {
        corrected_dph: c / n * DPH,
        raw_dph: r / n * DPH,
        last,
        faults_seen: faults,
    }
}

/// Oscillation at `freq` Hz with peak acceleration `eps_dps2`.
pub fn vibration(eps_dps2: f64, freq: f64) -> Profile<f64> {
    Profile::new(&[Segment::Oscillation {
        offset: 0.0,
        eps_peak: eps_dps2 * DEG,
        freq_hz: freq,
        duration: f64::INFINITY,
    }])
}

/// Steps covering a whole number of oscillation periods (within half a step) after `settle` steps.
pub fn whole_periods(cfg: &FogConfig, freq: f64, settle: u64, min_s: f64) -> (u64, u64) {
    let dt = cfg.closure_period_s();
    let periods = (min_s * freq).ceil();
    let n = (periods / freq / dt).round() as u64;
    (settle, settle + n)
}
