//! Helpers shared by the host tests: the firmware core closed around the
//! simulated gyro, with the truth alongside.

pub use gyro_sim::vibration_drift::{vibration, vibration_drift, Drift, DEG, DPH};
use gyro_sim::{FogRig, OpticsParams, Profile};
use gyro_sp::fog::{ClosureOutput, Faults, FogConfig, FogParams};

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
    pub faults_seen: Faults,
}

pub fn mean_error(rig: &mut FogRig<f64>, from: u64, to: u64) -> Means {
    let lsb = rig.cfg.rad_s_per_phase_lsb();
    let (mut c, mut r, mut n, mut faults) = (0.0, 0.0, 0.0, Faults::empty());
    let mut last = ClosureOutput::default();
    while rig.closure_index() < to {
        let k = rig.closure_index();
        let s = rig.run_closure();
        if k >= from {
            c += s.out.sagnac_phase_corrected as f64 * lsb - s.true_rate;
            r += s.out.sagnac_phase as f64 * lsb - s.true_rate;
            n += 1.0;
            faults |= s.out.faults;
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

/// Steps covering a whole number of oscillation periods (within half a step) after `settle` steps.
pub fn whole_periods(cfg: &FogConfig, freq: f64, settle: u64, min_s: f64) -> (u64, u64) {
    let dt = cfg.closure_period_s();
    let periods = (min_s * freq).ceil();
    let n = (periods / freq / dt).round() as u64;
    (settle, settle + n)
}

/// Closures of the reference instrument (`FogParams::default()`) in `seconds`.
pub fn closures_in(seconds: f64) -> u64 {
    (seconds * gyro_sp::fog::FogParams::default().closure_hz).round() as u64
}
