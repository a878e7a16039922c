//! The eps^2 (vibration rectification) drift measured on the closed loop:
//! the firmware's core around the simulated optics under a sinusoidal
//! oscillation, averaged in blocks of whole periods until the mean is known
//! to a stated standard error. Shared by the host tests and `gyro-lab`'s
//! eps^2 bench ([`eps2_point`]); no_std, so running sums, no stored blocks.
//!
//! The drift is the bias shift under vibration (IEEE Std 952's vibration
//! sensitivity): the vibrating rig's output error less that of a twin at
//! rest whose detector draws the same noise, closure by closure (common
//! random numbers). The noise is physical (a real detector carries about
//! 20 ADC LSB of shot noise per sample, which also dithers the ADC's
//! rounding; without it the rounding of these deterministic optics
//! rectifies about one output LSB, docs/notes/issue-23-eps2.md), and the
//! twin takes its white part out of the difference: at 3pi/4, 1 000
//! deg/s^2 the difference's scatter is 50 times below the rig's own.
//!
//! What one run measures, all from the same closures:
//! - the uncorrected drift: mean of (output phase - true Sagnac phase), as a
//!   rate, with the correction's bias not subtracted, less the twin's;
//! - the corrected drift: the same with the bias subtracted;
//! - the loop gain: the measured residual regressed on the true mean
//!   residual (the simulated Sagnac phase less the feedback phase applied),
//!   `sum(r_meas * r_true) / sum(r_true^2)`.

use crate::fog_rig::RigClosure;
use crate::{FogRig, OpticsParams, Profile, Segment};
use core::f64::consts::PI;
use gyro_sp::fog::config::ConfigError;
use gyro_sp::fog::{FogConfig, FogParams};
use gyro_sp::RAD_PER_PHASE_LSB;
#[allow(unused_imports)] // sqrt from libm where core lacks it
use num_traits::Float;

/// Radians per degree.
pub const DEG: f64 = PI / 180.0;
/// deg/h per rad/s.
pub const DPH: f64 = 3600.0 / DEG;

/// Running mean and variance (Welford), no stored samples.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Welford {
    n: u64,
    mean: f64,
    m2: f64,
}

impl Welford {
    pub fn push(&mut self, x: f64) {
        self.n += 1;
        let d = x - self.mean;
        self.mean += d / self.n as f64;
        self.m2 += d * (x - self.mean);
    }

    pub fn count(&self) -> u64 {
        self.n
    }

    pub fn mean(&self) -> f64 {
        self.mean
    }

    /// Sample variance (n - 1 in the denominator; 0 below two samples).
    pub fn variance(&self) -> f64 {
        if self.n < 2 {
            0.0
        } else {
            self.m2 / (self.n - 1) as f64
        }
    }

    /// Standard error of the mean (infinite below two samples).
    pub fn standard_error(&self) -> f64 {
        if self.n < 2 {
            f64::INFINITY
        } else {
            (self.variance() / self.n as f64).sqrt()
        }
    }
}

/// A drift measurement so far: means of the output error (deg/h) with their
/// standard errors from the scatter of block means, the loop gain, and the
/// simulated time averaged.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Drift {
    pub raw_dph: f64,
    pub raw_se_dph: f64,
    pub corrected_dph: f64,
    pub corrected_se_dph: f64,
    /// Measured residual regressed on the true mean residual.
    pub loop_gain: f64,
    /// Simulated seconds averaged (after settling).
    pub seconds: f64,
    /// Blocks of whole oscillation periods averaged.
    pub blocks: u64,
}

/// Accumulates a rig's output error in blocks of whole oscillation periods
/// (the fewest whole periods of at least one second).
#[derive(Clone, Copy, Debug)]
pub struct DriftMeter {
    /// Closures per block.
    block: u64,
    raw: Welford,
    corrected: Welford,
    /// Sums of r_meas * r_true and r_true^2, rad^2.
    md: f64,
    dd: f64,
    closures: u64,
    dt: f64,
}

impl DriftMeter {
    /// For the rig's configuration under an oscillation at `freq_hz`.
    pub fn new(cfg: &FogConfig, freq_hz: f64) -> Self {
        let dt = cfg.closure_period_s();
        let periods = freq_hz.ceil().max(1.0);
        Self {
            block: ((periods / freq_hz / dt).round() as u64).max(1),
            raw: Welford::default(),
            corrected: Welford::default(),
            md: 0.0,
            dd: 0.0,
            closures: 0,
            dt,
        }
    }

    /// Runs one block of closures on `rig` (and on its twin at `rest`, whose
    /// output error is subtracted closure by closure) and adds it.
    pub fn run_block(&mut self, rig: &mut FogRig<f64>, mut rest: Option<&mut FogRig<f64>>) {
        let lsb = rig.cfg.rad_s_per_phase_lsb();
        let ks = rig.cfg.k_sagnac_s;
        // A closure's output error (rad/s), uncorrected and corrected.
        let error = |c: &RigClosure<f64>| {
            (
                c.out.sagnac_phase as f64 * lsb - c.true_rate,
                c.out.sagnac_phase_corrected as f64 * lsb - c.true_rate,
            )
        };
        let (mut raw, mut corrected) = (0.0, 0.0);
        for _ in 0..self.block {
            let s = rig.run_closure();
            let (mut r, mut c) = error(&s);
            if let Some(twin) = rest.as_deref_mut() {
                let (tr, tc) = error(&twin.run_closure());
                (r, c) = (r - tr, c - tc);
            }
            raw += r;
            corrected += c;
            let applied = (s.out.sagnac_phase - s.out.residual as i64) as f64 * RAD_PER_PHASE_LSB;
            let truth = ks * s.true_rate - applied;
            self.md += s.out.residual as f64 * RAD_PER_PHASE_LSB * truth;
            self.dd += truth * truth;
        }
        let n = self.block as f64;
        self.raw.push(raw / n * DPH);
        self.corrected.push(corrected / n * DPH);
        self.closures += self.block;
    }

    pub fn drift(&self) -> Drift {
        Drift {
            raw_dph: self.raw.mean(),
            raw_se_dph: self.raw.standard_error(),
            corrected_dph: self.corrected.mean(),
            corrected_se_dph: self.corrected.standard_error(),
            loop_gain: if self.dd > 0.0 {
                self.md / self.dd
            } else {
                f64::NAN
            },
            seconds: self.closures as f64 * self.dt,
            blocks: self.raw.count(),
        }
    }
}

/// Runs `rig` (and its twin at `rest`) to closure `settle`, then in blocks
/// of whole periods of an oscillation at `freq_hz` until `done` says the
/// drift so far is enough (it is asked after every block).
pub fn vibration_drift(
    rig: &mut FogRig<f64>,
    mut rest: Option<&mut FogRig<f64>>,
    freq_hz: f64,
    settle: u64,
    mut done: impl FnMut(&Drift) -> bool,
) -> Drift {
    while rig.closure_index() < settle {
        rig.run_closure();
        if let Some(twin) = rest.as_deref_mut() {
            twin.run_closure();
        }
    }
    let mut meter = DriftMeter::new(&rig.cfg, freq_hz);
    loop {
        meter.run_block(rig, rest.as_deref_mut());
        let d = meter.drift();
        if done(&d) {
            return d;
        }
    }
}

/// Oscillation at `freq_hz` with peak angular acceleration `eps_dps2`.
pub fn vibration(eps_dps2: f64, freq_hz: f64) -> Profile<f64> {
    Profile::new(&[Segment::Oscillation {
        offset: 0.0,
        eps_peak: eps_dps2 * DEG,
        freq_hz,
        duration: f64::INFINITY,
    }])
}

/// The eps^2 envelope of issue 23: peak angular accelerations, deg/s^2.
pub const EPS2_ACCELERATIONS_DPS2: [f64; 4] = [1_000.0, 5_000.0, 20_000.0, 50_000.0];
/// Oscillation frequencies, Hz.
pub const EPS2_FREQUENCIES_HZ: [f64; 3] = [20.0, 60.0, 200.0];
/// The two reference instruments: (phi0 in rad, closure rate in Hz).
pub const EPS2_INSTRUMENTS: [(f64, f64); 2] = [(0.75 * PI, 12_500.0), (0.875 * PI, 6_250.0)];
/// DAC latencies, closures: none (QEMU, host rigs) and the hw board's DMA ping-pong.
pub const EPS2_DAC_LATENCIES: [u32; 2] = [0, 1];

/// Closures to settle before measuring: ten time constants of the AGC's DC
/// filter (4 096 closures), which sets the loop gain.
pub const EPS2_SETTLE_CLOSURES: u64 = 10 * 4_096;

/// The instrument the eps^2 envelope is measured on: the reference FOG at
/// depth `phi0_rad` and `closure_hz`, `dac_latency` closures of DAC
/// latency, a 16-bit ADC (with the 12-bit default the rounding floor, about
/// 0.01 deg/h, exceeds the 1 000 deg/s^2 drift's 1 %) and a 240-code depth
/// dither (+-0.012 rad at 3pi/4; 60 codes at 16 bits left a rounding
/// artefact at 20 Hz), correction on.
pub fn eps2_instrument(phi0_rad: f64, closure_hz: f64, dac_latency: u32) -> FogParams {
    FogParams {
        phi0_rad,
        closure_hz,
        dac_latency,
        adc_bits: 16,
        dither_adc_codes: 240.0,
        vibration_correction: true,
        ..FogParams::default()
    }
}

/// The eps^2 bench's default seed of the detector noise (the vibrating rig
/// and its twin at rest draw the same).
pub const EPS2_NOISE_SEED: u64 = 1;

/// A rig for `params` (the nominal optics at the ADC resolution
/// `params.adc_bits`, the detector matched to phi0, its shot and intensity
/// noise on, drawn from `seed`) under `profile`.
pub fn eps2_rig(
    params: FogParams,
    seed: u64,
    profile: Profile<f64>,
) -> Result<FogRig<f64>, ConfigError> {
    let mut optics = OpticsParams::<f64>::nominal(
        params.tau_s,
        params.samples_per_half,
        params.dac_codes_per_turn,
    );
    optics.adc_bits = params.adc_bits;
    optics.noise = true;
    optics.seed = seed;
    let cfg = FogConfig::new(optics.matched(params))?;
    Ok(FogRig::new(cfg, optics, profile))
}

/// One point of the eps^2 table.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Eps2Point {
    /// `FogConfig::predicted_vibration_drift` at <eps^2> = eps_pk^2/2, deg/h.
    pub formula_dph: f64,
    /// The measurement (uncorrected and corrected drift, loop gain, time).
    pub drift: Drift,
}

impl Eps2Point {
    /// Share of the formula's drift the correction leaves (signed: negative
    /// when it over-corrects).
    pub fn share_left(&self) -> f64 {
        self.drift.corrected_dph / self.formula_dph
    }

    /// Standard error of [`Self::share_left`].
    pub fn share_left_se(&self) -> f64 {
        self.drift.corrected_se_dph / self.formula_dph.abs()
    }

    /// Uncorrected drift relative to the formula, less one.
    pub fn raw_off_formula(&self) -> f64 {
        self.drift.raw_dph / self.formula_dph - 1.0
    }
}

/// Measures one point: the instrument `params` under `eps_dps2` peak at
/// `freq_hz` against its twin at rest, settled for [`EPS2_SETTLE_CLOSURES`], averaged in blocks of
/// whole periods (about one second) until the share left's standard error
/// is at most `se_target` (e.g. 0.0025: a quarter of 1 %) over at least 8
/// blocks, or `max_seconds` of simulated time. `progress` sees the point
/// after every block (a bench's progress bar: the time still needed is
/// about `seconds * ((share_left_se / se_target)^2 - 1)`).
pub fn eps2_point(
    params: FogParams,
    seed: u64,
    eps_dps2: f64,
    freq_hz: f64,
    se_target: f64,
    max_seconds: f64,
    mut progress: impl FnMut(&Eps2Point),
) -> Result<Eps2Point, ConfigError> {
    let mut rig = eps2_rig(params, seed, vibration(eps_dps2, freq_hz))?;
    let mut rest = eps2_rig(params, seed, Profile::constant(0.0))?;
    let formula_dph = rig
        .cfg
        .predicted_vibration_drift((eps_dps2 * DEG).powi(2) / 2.0)
        * DPH;
    let drift = vibration_drift(
        &mut rig,
        Some(&mut rest),
        freq_hz,
        EPS2_SETTLE_CLOSURES,
        |d| {
            let p = Eps2Point {
                formula_dph,
                drift: *d,
            };
            progress(&p);
            (d.blocks >= 8 && p.share_left_se() <= se_target) || d.seconds >= max_seconds
        },
    );
    Ok(Eps2Point { formula_dph, drift })
}
