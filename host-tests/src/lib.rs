//! Helpers shared by the host tests: the firmware core closed around the
//! simulated gyro, with the truth alongside.

use gyro_sim::{FogRig, OpticsParams, Profile, Segment};
use gyro_sp::fog::{ClosureOutput, Faults, FogConfig, FogParams};

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

/// Vibration drift measured to a stated precision: mean output error (deg/h)
/// raw and corrected, and the raw mean's standard error from the scatter of
/// block means (each block whole oscillation periods).
pub struct Drift {
    pub raw_dph: f64,
    pub corrected_dph: f64,
    pub raw_se_dph: f64,
    pub seconds: f64,
}

/// Runs `rig` (settled from step `settle`) under an oscillation at `freq` Hz
/// in blocks of whole periods of about one second until the raw mean's
/// standard error is below `se_target_dph` (at least 8 blocks and `min_s`
/// seconds, at most `max_s`). The error has no time scale of its own (ADC
/// rounding and dither are white), so its mean converges as 1/sqrt(T): at
/// 1 000 deg/s^2 the published tests averaged 3-5 minutes per point too.
pub fn vibration_drift(
    rig: &mut FogRig<f64>,
    freq: f64,
    settle: u64,
    se_target_dph: f64,
    (min_s, max_s): (f64, f64),
) -> Drift {
    let dt = rig.cfg.closure_period_s();
    let lsb = rig.cfg.rad_s_per_phase_lsb();
    let periods = freq.ceil();
    let block = (periods / freq / dt).round() as u64;
    while rig.closure_index() < settle {
        rig.run_closure();
    }
    let (mut raw, mut corr) = (Vec::new(), 0.0);
    loop {
        let (mut b, mut c) = (0.0, 0.0);
        for _ in 0..block {
            let s = rig.run_closure();
            b += s.out.sagnac_phase as f64 * lsb - s.true_rate;
            c += s.out.sagnac_phase_corrected as f64 * lsb - s.true_rate;
        }
        raw.push(b / block as f64 * DPH);
        corr += c / block as f64 * DPH;
        let n = raw.len() as f64;
        let mean = raw.iter().sum::<f64>() / n;
        let var = raw.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n - 1.0).max(1.0);
        let se = (var / n).sqrt();
        let seconds = n * block as f64 * dt;
        if (n >= 8.0 && seconds >= min_s && se < se_target_dph) || seconds >= max_s {
            return Drift {
                raw_dph: mean,
                corrected_dph: corr / n,
                raw_se_dph: se,
                seconds,
            };
        }
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

/// Closures of the reference instrument (`FogParams::default()`) in `seconds`.
pub fn closures_in(seconds: f64) -> u64 {
    (seconds * gyro_sp::fog::FogParams::default().closure_hz).round() as u64
}
