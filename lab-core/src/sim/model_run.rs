//! Runs with known effects: a truth model (the effects of
//! model/effects.rs) evaluated on a test profile, plus the project's noise
//! generator (gyro_sim::noise: white, flicker and rate random walk) and its
//! thermal simulators (gyro_sim's coil, and the RLG chamber of
//! chamber.rs); optionally disturbances the library has no effect for
//! ([`Extra`]). `simulate run` writes them; the discovery bench and tests
//! draw them.

use super::chamber::{air_temperature, earth_component_dps, ChamberProfile};
use crate::model::gyro_kind::GyroKind;
use crate::model::gyro_model::Model;
use crate::model::inputs::Inputs;
use gyro_sim::{Chamber, ChamberParams, CoilThermal, NoiseParams, RateNoise};
use rand_core::{RngCore, SeedableRng};
use rand_distr::{Distribution, StandardNormal};
use rand_xoshiro::Xoshiro256PlusPlus;

/// Test profiles.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TestProfile {
    /// Rate table: 0, +-10, +-50, +-100, +-200 deg/s in a shuffled order,
    /// 60 s each, while the chamber sweeps -20 -> +60 -> -20 degC (the coil
    /// 600 s behind the air); 1 s rows, 2 h.
    Table,
    /// The same table at one constant rate (+50 deg/s) and constant
    /// temperature: a scale-factor error and a bias look alike there.
    ConstantRate,
    /// RLG at rest in a thermal chamber (gyro_sp's chamber: case and two
    /// monoblock sensors with their lags and self-heating), the cycle
    /// -40 -> +50 degC; 1 s rows, 6 h.
    Chamber,
    /// RLG rate steps near lock-in: +-0.03 .. +-3 deg/s log-spaced, 20 s
    /// each; 10 Hz rows, 30 min.
    Lockin,
    /// FOG at rest under 20 Hz sinusoidal vibration switched between
    /// amplitudes (0, 2 000, 5 000, 10 000 deg/s^2 peak), 30 s each, with
    /// `ref_acc_dps2`; 200 Hz rows, 10 min.
    Vibration,
    /// FOG under one constant vibration level: rectification looks like a
    /// bias.
    ConstantVibration,
    /// FOG at rest in a chamber: 20 -> +50 -> -10 -> 20 degC at 1 degC/min
    /// with 30 min soaks (the coil 600 s behind the air, its sensor 30 s
    /// behind the coil, read at 1/128 degC); 1 s rows, 3.7 h. The coil's
    /// temperature and its rate of change move apart (ramps and soaks).
    FogChamber,
}

impl TestProfile {
    pub fn gyro(self) -> GyroKind {
        match self {
            TestProfile::Chamber | TestProfile::Lockin => GyroKind::Rlg,
            TestProfile::FogChamber => GyroKind::Fog,
            _ => GyroKind::Fog,
        }
    }

    /// Default row period and duration, s.
    pub fn default_timing(self) -> (f64, f64) {
        match self {
            TestProfile::Table | TestProfile::ConstantRate => (1.0, 7200.0),
            TestProfile::Chamber => (1.0, 6.0 * 3600.0),
            TestProfile::Lockin => (0.1, 1800.0),
            TestProfile::Vibration | TestProfile::ConstantVibration => (0.005, 600.0),
            TestProfile::FogChamber => (1.0, FOG_CHAMBER_S),
        }
    }
}

/// Length of the FOG chamber profile, s.
pub const FOG_CHAMBER_S: f64 = 600.0 + 120.0 * 60.0 + 3.0 * 1800.0;

/// Noise of the simulated gyro: white rate (deg/sqrt(h)), bias
/// instability (deg/h) and rate random walk (deg/h/sqrt(h)).
#[derive(Clone, Copy, Debug)]
pub struct TrialNoise {
    pub arw_dpsh: f64,
    pub bias_instability_dph: f64,
    pub rate_random_walk_dphsh: f64,
}

/// A disturbance no effect of the library describes.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub enum Extra {
    /// c w^2, deg/h per (deg/s)^2.
    RateSquared(f64),
    /// c w^3, deg/h per (deg/s)^3.
    RateCubed(f64),
    /// The bias steps by `dph` at `at_s`.
    BiasStep { at_s: f64, dph: f64 },
    /// A bias growing linearly in time, deg/h per hour.
    RateRamp(f64),
    /// k d2T/dt2 of the main (FOG) or case (RLG) temperature, deg/h per
    /// degC/s^2.
    TempCurvature(f64),
    /// c w|w|, deg/h per (deg/s)^2.
    RateAbsRate(f64),
    /// c (T - t0)^2 of the coil, deg/h per degC^2.
    BiasTempSquared { c: f64, t0_c: f64 },
    /// c w (T - t0)^2, deg/h per deg/s per degC^2.
    ScaleFactorTempSquared { c: f64, t0_c: f64 },
    /// c w dT/dt, deg/h per deg/s per degC/s.
    ScaleFactorTempRate(f64),
    /// c (T_case - (T_mono_a + T_mono_b)/2), deg/h per degC.
    CaseMinusMono(f64),
    /// c dT_case/dt, deg/h per degC/s.
    CaseRate(f64),
    /// c |angular acceleration|, deg/h per deg/s^2.
    AbsAcceleration(f64),
    /// amp sin(2 pi t / period + phase), deg/h.
    Periodic { dph: f64, period_s: f64, phase: f64 },
}

/// Half width of each of the two slopes the generator's d2T/dt2 takes, s.
const CURVATURE_HALF_WIDTH_S: f64 = 120.0;

impl Extra {
    /// The disturbance with its size multiplied by `f`.
    pub fn scaled(self, f: f64) -> Self {
        match self {
            Extra::RateSquared(c) => Extra::RateSquared(c * f),
            Extra::RateCubed(c) => Extra::RateCubed(c * f),
            Extra::BiasStep { at_s, dph } => Extra::BiasStep { at_s, dph: dph * f },
            Extra::RateRamp(c) => Extra::RateRamp(c * f),
            Extra::TempCurvature(c) => Extra::TempCurvature(c * f),
            Extra::RateAbsRate(c) => Extra::RateAbsRate(c * f),
            Extra::BiasTempSquared { c, t0_c } => Extra::BiasTempSquared { c: c * f, t0_c },
            Extra::ScaleFactorTempSquared { c, t0_c } => {
                Extra::ScaleFactorTempSquared { c: c * f, t0_c }
            }
            Extra::ScaleFactorTempRate(c) => Extra::ScaleFactorTempRate(c * f),
            Extra::CaseMinusMono(c) => Extra::CaseMinusMono(c * f),
            Extra::CaseRate(c) => Extra::CaseRate(c * f),
            Extra::AbsAcceleration(c) => Extra::AbsAcceleration(c * f),
            Extra::Periodic {
                dph,
                period_s,
                phase,
            } => Extra::Periodic {
                dph: dph * f,
                period_s,
                phase,
            },
        }
    }

    /// Its contribution, deg/s, on `inp`.
    pub fn contribution(&self, inp: &Inputs) -> Vec<f64> {
        use crate::model::inputs::{centered_slope, RATE_HALF_WIDTH_S};
        let d = 1.0 / 3600.0;
        match *self {
            Extra::RateSquared(c) => inp.w.iter().map(|w| c * d * w * w).collect(),
            Extra::RateCubed(c) => inp.w.iter().map(|w| c * d * w * w * w).collect(),
            Extra::BiasStep { at_s, dph } => inp
                .t
                .iter()
                .map(|&t| if t >= at_s { dph * d } else { 0.0 })
                .collect(),
            Extra::RateRamp(r) => inp.t.iter().map(|t| r * d * t / 3600.0).collect(),
            Extra::RateAbsRate(c) => inp.w.iter().map(|w| c * d * w * w.abs()).collect(),
            Extra::BiasTempSquared { c, t0_c } => match &inp.temp {
                Some(x) => x.iter().map(|v| c * d * (v - t0_c).powi(2)).collect(),
                None => vec![0.0; inp.len()],
            },
            Extra::ScaleFactorTempSquared { c, t0_c } => match &inp.temp {
                Some(x) => x
                    .iter()
                    .zip(&inp.w)
                    .map(|(v, w)| c * d * w * (v - t0_c).powi(2))
                    .collect(),
                None => vec![0.0; inp.len()],
            },
            Extra::ScaleFactorTempRate(c) => match &inp.temp {
                Some(x) => centered_slope(&inp.t, x, RATE_HALF_WIDTH_S)
                    .iter()
                    .zip(&inp.w)
                    .map(|(r, w)| c * d * w * r)
                    .collect(),
                None => vec![0.0; inp.len()],
            },
            Extra::CaseMinusMono(c) => match (&inp.case, &inp.mono) {
                (Some(k), Some((a, b))) => k
                    .iter()
                    .zip(a.iter().zip(b))
                    .map(|(k, (a, b))| c * d * (k - 0.5 * (a + b)))
                    .collect(),
                _ => vec![0.0; inp.len()],
            },
            Extra::CaseRate(c) => match &inp.case {
                Some(k) => centered_slope(&inp.t, k, RATE_HALF_WIDTH_S)
                    .iter()
                    .map(|r| c * d * r)
                    .collect(),
                None => vec![0.0; inp.len()],
            },
            Extra::AbsAcceleration(c) => inp.acc.iter().map(|a| c * d * a.abs()).collect(),
            Extra::Periodic {
                dph,
                period_s,
                phase,
            } => inp
                .t
                .iter()
                .map(|t| dph * d * (std::f64::consts::TAU * t / period_s + phase).sin())
                .collect(),
            Extra::TempCurvature(k) => {
                let temp = inp.temp.as_ref().or(inp.case.as_ref());
                match temp {
                    // The curvature of the temperature itself, smooth over
                    // minutes (the sensor's quantization is not the gyro's).
                    Some(x) => {
                        let r = centered_slope(&inp.t, x, CURVATURE_HALF_WIDTH_S);
                        centered_slope(&inp.t, &r, CURVATURE_HALF_WIDTH_S)
                            .iter()
                            .map(|c| k * d * c)
                            .collect()
                    }
                    None => vec![0.0; inp.len()],
                }
            }
        }
    }
}

impl TrialNoise {
    /// A navigation-grade FOG or RLG, an industrial MEMS gyro.
    pub fn nominal(g: GyroKind) -> Self {
        match g {
            GyroKind::Fog => Self {
                arw_dpsh: 0.005,
                bias_instability_dph: 0.005,
                rate_random_walk_dphsh: 0.0,
            },
            GyroKind::Rlg => Self {
                arw_dpsh: 0.003,
                bias_instability_dph: 0.003,
                rate_random_walk_dphsh: 0.0,
            },
            // An industrial MEMS gyro (discover --gyro mems).
            GyroKind::Mems => Self {
                arw_dpsh: 0.3,
                bias_instability_dph: 10.0,
                rate_random_walk_dphsh: 0.0,
            },
        }
    }
}

/// A generated run: its inputs, the measured rate, and the columns to write.
pub struct TrialRun {
    pub inputs: Inputs,
    pub rate: Vec<f64>,
    /// The mono/case columns when the profile has them (for the file).
    pub mono: Option<(Vec<f64>, Vec<f64>)>,
    pub case: Option<Vec<f64>>,
    pub acc_column: bool,
}

fn triangle(t: f64, period: f64, lo: f64, hi: f64) -> f64 {
    let p = (t / period).fract();
    let x = if p < 0.5 { 2.0 * p } else { 2.0 - 2.0 * p };
    lo + (hi - lo) * x
}

/// The inputs of a profile, one value per row of `t` (the rows' end
/// times, `dt` apart, `dur` in all).
#[derive(Default)]
struct ProfileInputs {
    w: Vec<f64>,
    temp: Option<Vec<f64>>,
    mono: Option<(Vec<f64>, Vec<f64>)>,
    case: Option<Vec<f64>>,
    acc: Option<Vec<f64>>,
}

/// The rate table in a shuffled order while the chamber sweeps; the coil
/// sensor read at 1/128 degC with 0.005 degC noise.
fn table(t: &[f64], dt: f64, dur: f64, rng: &mut Xoshiro256PlusPlus) -> ProfileInputs {
    let mut rates = vec![0.0, 10.0, -10.0, 50.0, -50.0, 100.0, -100.0, 200.0, -200.0];
    // Shuffle (Fisher-Yates) so each seed orders the rates its own way.
    for i in (1..rates.len()).rev() {
        let j = (rng.next_u64() % (i as u64 + 1)) as usize;
        rates.swap(i, j);
    }
    let mut coil = CoilThermal::new(-20.0);
    let mut tc = Vec::with_capacity(t.len());
    for &tk in t {
        let air = triangle(tk, dur, -20.0, 60.0);
        let (c, _) = coil.step(dt, air);
        let z: f64 = StandardNormal.sample(rng);
        tc.push(((c + 0.005 * z) * 128.0).round() / 128.0);
    }
    ProfileInputs {
        w: t.iter()
            .map(|&tk| rates[((tk - dt / 2.0) / 60.0) as usize % rates.len()])
            .collect(),
        temp: Some(tc),
        ..Default::default()
    }
}

/// Air of the FOG chamber profile at time t: 10 min at 20 degC, then
/// ramps at 1 degC/min to 50, -10 and 20 degC with 30 min soaks.
fn fog_chamber_air(t: f64) -> f64 {
    let pts = [20.0, 50.0, -10.0, 20.0];
    let mut t0 = 600.0;
    if t < t0 {
        return pts[0];
    }
    for w in pts.windows(2) {
        let ramp = (w[1] - w[0]).abs() * 60.0;
        if t < t0 + ramp {
            return w[0] + (w[1] - w[0]) * (t - t0) / ramp;
        }
        t0 += ramp;
        if t < t0 + 1800.0 {
            return w[1];
        }
        t0 += 1800.0;
    }
    pts[pts.len() - 1]
}

/// The FOG at rest in the chamber: the coil sensor read at 1/128 degC
/// with 0.005 degC noise.
fn fog_chamber(t: &[f64], dt: f64, rng: &mut Xoshiro256PlusPlus) -> ProfileInputs {
    let mut coil = CoilThermal::new(20.0);
    let tc = t
        .iter()
        .map(|&tk| {
            let (_, sensor) = coil.step(dt, fog_chamber_air(tk - dt / 2.0));
            let z: f64 = StandardNormal.sample(rng);
            ((sensor + 0.005 * z) * 128.0).round() / 128.0
        })
        .collect();
    ProfileInputs {
        w: vec![earth_component_dps(0.0, 90.0, 48.0); t.len()],
        temp: Some(tc),
        ..Default::default()
    }
}

/// The RLG at rest in the chamber's cycle.
fn chamber(t: &[f64], dt: f64, seed: u64) -> ProfileInputs {
    let p = ChamberParams {
        seed,
        ..ChamberParams::default()
    };
    let mut ch = Chamber::new(p, 20.0);
    let (mut a, mut b, mut k) = (vec![], vec![], vec![]);
    for &tk in t {
        let air = air_temperature(ChamberProfile::Cycle, 20.0, tk - dt / 2.0);
        let s = ch.step(dt, air, 0.0);
        a.push(s.t_mono_a_c);
        b.push(s.t_mono_b_c);
        k.push(s.t_case_c);
    }
    ProfileInputs {
        // At rest, the Earth's component along an upright axis at 48 deg.
        w: vec![earth_component_dps(0.0, 90.0, 48.0); t.len()],
        mono: Some((a, b)),
        case: Some(k),
        ..Default::default()
    }
}

/// Rate steps near lock-in, log-spaced magnitudes, each both ways.
fn lockin(t: &[f64], dt: f64) -> ProfileInputs {
    let mags: Vec<f64> = (0..12)
        .map(|i| 0.03 * 10f64.powf(2.0 * i as f64 / 11.0))
        .collect();
    ProfileInputs {
        w: t.iter()
            .map(|&tk| {
                let step = ((tk - dt / 2.0) / 20.0) as usize;
                let m = mags[(step / 2) % mags.len()];
                if step.is_multiple_of(2) {
                    m
                } else {
                    -m
                }
            })
            .collect(),
        ..Default::default()
    }
}

/// 20 Hz vibration at rest, its level switched (or one constant level).
fn vibration(t: &[f64], dt: f64, constant: bool) -> ProfileInputs {
    let f = 20.0;
    let wv = std::f64::consts::TAU * f;
    let levels = [0.0, 2_000.0, 5_000.0, 10_000.0];
    let eps = |tk: f64| {
        if constant {
            5_000.0
        } else {
            levels[((tk / 30.0) as usize) % levels.len()]
        }
    };
    // Rate and acceleration at the row's middle (the rates are the
    // oscillation's values there; the rectification responds to
    // eps^2, whose row mean this samples without bias).
    let mid: Vec<f64> = t.iter().map(|tk| tk - dt / 2.0).collect();
    ProfileInputs {
        w: mid
            .iter()
            .map(|&tm| eps(tm) / wv * (wv * tm).sin())
            .collect(),
        acc: Some(mid.iter().map(|&tm| eps(tm) * (wv * tm).cos()).collect()),
        ..Default::default()
    }
}

/// Generates a run of `profile` for the truth `model`.
pub fn generate(
    model: &Model,
    profile: TestProfile,
    noise: TrialNoise,
    seed: u64,
    timing: Option<(f64, f64)>,
) -> TrialRun {
    generate_with(model, &[], profile, noise, seed, timing)
}

/// The inputs of `profile` for `seed` at (row period, duration): the same
/// as [`generate`]'s.
pub fn inputs_of(profile: TestProfile, seed: u64, timing: Option<(f64, f64)>) -> Inputs {
    profile_inputs(profile, seed, timing.unwrap_or(profile.default_timing())).0
}

fn profile_inputs(
    profile: TestProfile,
    seed: u64,
    (dt, dur): (f64, f64),
) -> (Inputs, ProfileInputs) {
    let n = (dur / dt).round() as usize;
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(seed ^ 0xD15C_0FE2);
    let t: Vec<f64> = (0..n).map(|k| (k + 1) as f64 * dt).collect();
    let mut p = match profile {
        TestProfile::Table => table(&t, dt, dur, &mut rng),
        TestProfile::ConstantRate => ProfileInputs {
            w: vec![50.0; n],
            temp: Some(vec![25.0; n]),
            ..Default::default()
        },
        TestProfile::Chamber => chamber(&t, dt, seed),
        TestProfile::Lockin => lockin(&t, dt),
        TestProfile::Vibration => vibration(&t, dt, false),
        TestProfile::ConstantVibration => vibration(&t, dt, true),
        TestProfile::FogChamber => fog_chamber(&t, dt, &mut rng),
    };
    let inputs = Inputs::new(
        t,
        std::mem::take(&mut p.w),
        p.temp.take(),
        p.mono.clone(),
        p.case.clone(),
        p.acc.clone(),
    );
    (inputs, p)
}

/// [`generate`] with disturbances outside the library added.
pub fn generate_with(
    model: &Model,
    extras: &[Extra],
    profile: TestProfile,
    noise: TrialNoise,
    seed: u64,
    timing: Option<(f64, f64)>,
) -> TrialRun {
    let (dt, dur) = timing.unwrap_or(profile.default_timing());
    let (inputs, p) = profile_inputs(profile, seed, (dt, dur));
    let acc_column = p.acc.is_some();
    let mut g = RateNoise::new(
        NoiseParams {
            n_dps_rts: NoiseParams::arw_from_dpsh(noise.arw_dpsh),
            b_dps: NoiseParams::b_from_dph(noise.bias_instability_dph),
            k_dps_rts: NoiseParams::k_from_dphsh(noise.rate_random_walk_dphsh),
            // Bias instability up to a third of the record (as far as the
            // run's Allan deviation reaches): slower processes would only
            // add a turn-on bias, which no record can tell from a bias
            // effect.
            flicker_max_tau_s: dur / 3.0,
            ..NoiseParams::default()
        },
        dt,
        seed,
    );
    let mut rate: Vec<f64> = model
        .evaluate(&inputs)
        .iter()
        .map(|y| y + g.sample())
        .collect();
    for x in extras {
        for (r, c) in rate.iter_mut().zip(x.contribution(&inputs)) {
            *r += c;
        }
    }
    TrialRun {
        inputs,
        rate,
        mono: p.mono,
        case: p.case,
        acc_column,
    }
}
