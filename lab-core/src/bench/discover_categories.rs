//! The categories of `gyro-lab bench discover`, drawn:
//!
//! - every effect of the library alone, on a profile that exercises it;
//! - nothing missing (the model is the truth);
//! - two effects hidden at once (a bias with a scale-factor error on the
//!   rate table; a case-temperature term with a warm-up in the chamber);
//! - two effects collinear by construction (a scale-factor error at one
//!   constant rate, rectification at one constant vibration level): they
//!   must be reported ambiguous;
//! - nulls with coloured noise (a rate random walk, or a flicker ten times
//!   the nominal): nothing to name;
//! - a bias with each thermal term on the RLG in the chamber;
//! - warm-ups decaying from a turn-on offset to no bias (A exp(-t/tau):
//!   in the library's terms a constant A and a warm-up of amplitude -A);
//!   the warm-up is to be named, not a bias;
//! - disturbances outside the library (w^2, w^3, a bias step, a rate ramp,
//!   a d2T/dt2 term): nothing to name, and the residual said unexplained;
//! - every effect of the library near 1.5 times the noise floor (its 1 s
//!   means' RMS 1.5 times the white noise of a 1 s mean).

use super::discover_trials::{
    bench_effects, draw, effect_of, signed, uni, Outside, Trial, TrialKind,
};
use crate::model::discovery::windows::Windows;
use crate::model::effects::Effect;
use crate::model::gyro_model::ModelEffect;
use crate::sim::model_run::{inputs_of, Extra, TestProfile, TrialNoise};
use rand_core::SeedableRng;
use rand_xoshiro::Xoshiro256PlusPlus;

/// How many trials of each kind, and the seed of the draws.
#[derive(Clone, Copy, Debug)]
pub struct TrialCounts {
    pub per_effect: u64,
    pub nothing: u64,
    pub pairs: u64,
    pub collinear: u64,
    pub coloured: u64,
    /// Per thermal term.
    pub bias_thermal: u64,
    pub decaying: u64,
    /// Per disturbance.
    pub outside: u64,
    /// Per effect.
    pub weak: u64,
    pub seed: u64,
}

/// The thermal terms of the RLG in the chamber.
pub const THERMAL: [Effect; 5] = [
    Effect::ThermalDifference,
    Effect::ThermalGradient,
    Effect::ThermalDifferenceSquared,
    Effect::CaseTemperature,
    Effect::WarmUp,
];

/// A disturbance outside the library, drawn, with its profile, at 4 to 9
/// times the 1 s noise floor (its 1 s means' RMS, their mean removed,
/// over the white noise's of a 1 s mean).
fn outside(o: Outside, i: u64, seed: u64, rng: &mut Xoshiro256PlusPlus) -> (TestProfile, Extra) {
    let at_rest = [TestProfile::Chamber, TestProfile::FogChamber][(i % 2) as usize];
    let one = |rng: &mut Xoshiro256PlusPlus| signed(rng, 1.0, 1.0);
    let (p, x) = match o {
        Outside::RateSquared => (TestProfile::Table, Extra::RateSquared(one(rng))),
        Outside::RateCubed => (TestProfile::Table, Extra::RateCubed(one(rng))),
        Outside::RateAbsRate => (TestProfile::Table, Extra::RateAbsRate(one(rng))),
        Outside::BiasTempSquared => (
            TestProfile::FogChamber,
            Extra::BiasTempSquared {
                c: one(rng),
                t0_c: uni(rng, 10.0, 40.0),
            },
        ),
        Outside::ScaleFactorTempSquared => (
            TestProfile::Table,
            Extra::ScaleFactorTempSquared {
                c: one(rng),
                t0_c: uni(rng, 10.0, 40.0),
            },
        ),
        Outside::TempCurvature => (TestProfile::FogChamber, Extra::TempCurvature(one(rng))),
        Outside::ScaleFactorTempRate => (TestProfile::Table, Extra::ScaleFactorTempRate(one(rng))),
        Outside::CaseMinusMono => (TestProfile::Chamber, Extra::CaseMinusMono(one(rng))),
        Outside::CaseRate => (TestProfile::Chamber, Extra::CaseRate(one(rng))),
        Outside::AbsAcceleration => (TestProfile::Vibration, Extra::AbsAcceleration(one(rng))),
        Outside::BiasStep => {
            let p = [
                TestProfile::Table,
                TestProfile::Chamber,
                TestProfile::FogChamber,
            ][(i % 3) as usize];
            let dur = p.default_timing().1;
            (
                p,
                Extra::BiasStep {
                    at_s: uni(rng, 0.3, 0.7) * dur,
                    dph: one(rng),
                },
            )
        }
        Outside::Periodic => (
            at_rest,
            Extra::Periodic {
                dph: one(rng),
                period_s: uni(rng, 1200.0, 3600.0),
                phase: uni(rng, 0.0, std::f64::consts::TAU),
            },
        ),
        Outside::RateRamp => (at_rest, Extra::RateRamp(one(rng))),
    };
    let floor = TrialNoise::nominal(p.gyro()).arw_dpsh * 60.0;
    let target = uni(rng, 4.0, 9.0) * floor;
    let inp = inputs_of(p, seed, None);
    let m = Windows::new(&inp.t, 1.0).mean(&x.contribution(&inp));
    let mean = m.iter().sum::<f64>() / m.len().max(1) as f64;
    let rms =
        (m.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / m.len().max(1) as f64).sqrt() * 3600.0;
    (p, x.scaled(if rms > 0.0 { target / rms } else { 1.0 }))
}

/// `h` scaled so that its contribution's 1 s means have an RMS of `target`
/// deg/h on `profile`'s inputs for `seed` (its linear parameters scaled;
/// None for an effect without one).
fn scaled(h: &ModelEffect, profile: TestProfile, seed: u64, target: f64) -> Option<ModelEffect> {
    if h.effect.linear_params().is_empty() {
        return None;
    }
    let inp = inputs_of(profile, seed, None);
    let win = Windows::new(&inp.t, 1.0);
    let m = win.mean(&h.effect.contribution(&inp, &h.params));
    let rms = (m.iter().map(|v| v * v).sum::<f64>() / m.len().max(1) as f64).sqrt() * 3600.0;
    if rms <= 0.0 {
        return None;
    }
    let mut out = h.clone();
    for p in h.effect.linear_params() {
        if let Some(v) = out.params.get_mut(*p) {
            *v *= target / rms;
        }
    }
    Some(out)
}

/// The trials, drawn.
pub fn trials(a: &TrialCounts) -> Vec<Trial> {
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(a.seed);
    let mut out: Vec<Trial> = vec![];
    let mut seed = a.seed * 1_000_003;
    let mut next = || {
        seed += 1;
        seed
    };
    let effects = bench_effects();
    for &e in &effects {
        for _ in 0..a.per_effect {
            let (p, h, known) = draw(e, &mut rng);
            out.push(Trial::hiding(
                TrialKind::Single(e),
                p,
                known,
                vec![h],
                next(),
            ));
        }
    }
    for i in 0..a.nothing {
        let e = effects[(i as usize) % effects.len()];
        let (p, h, mut known) = draw(e, &mut rng);
        known.push(h);
        out.push(Trial::hiding(
            TrialKind::NothingMissing,
            p,
            known,
            vec![],
            next(),
        ));
    }
    for i in 0..a.pairs {
        let (pair, profile) = if i % 2 == 0 {
            ([Effect::Bias, Effect::ScaleFactorError], TestProfile::Table)
        } else {
            (
                [Effect::CaseTemperature, Effect::WarmUp],
                TestProfile::Chamber,
            )
        };
        let hidden: Vec<ModelEffect> = pair.iter().map(|&e| draw(e, &mut rng).1).collect();
        out.push(Trial::hiding(
            TrialKind::TwoHidden,
            profile,
            vec![],
            hidden,
            next(),
        ));
    }
    for i in 0..a.collinear {
        let (e, profile) = if i % 2 == 0 {
            (Effect::ScaleFactorError, TestProfile::ConstantRate)
        } else {
            (
                Effect::VibrationRectification,
                TestProfile::ConstantVibration,
            )
        };
        let h = draw(e, &mut rng).1;
        out.push(Trial::hiding(
            TrialKind::Collinear,
            profile,
            vec![],
            vec![h],
            next(),
        ));
    }
    for i in 0..a.coloured {
        let e = [
            Effect::ScaleFactorTemperature,
            Effect::ThermalDifference,
            Effect::BiasTemperature,
        ][(i % 3) as usize];
        let (p, h, mut known) = draw(e, &mut rng);
        known.push(h);
        let mut t = Trial::hiding(TrialKind::ColouredNull, p, known, vec![], next());
        let nom = TrialNoise::nominal(p.gyro());
        t.noise = if i % 2 == 0 {
            TrialNoise {
                rate_random_walk_dphsh: uni(&mut rng, 0.01, 0.05),
                ..nom
            }
        } else {
            TrialNoise {
                bias_instability_dph: nom.bias_instability_dph * uni(&mut rng, 5.0, 10.0),
                ..nom
            }
        };
        out.push(t);
    }
    for e in THERMAL {
        for _ in 0..a.bias_thermal {
            let b = effect_of(Effect::Bias, &[("bias_dph", signed(&mut rng, 0.1, 1.0))]);
            let h = draw(e, &mut rng).1;
            out.push(Trial::hiding(
                TrialKind::BiasThermal(e),
                TestProfile::Chamber,
                vec![],
                vec![b, h],
                next(),
            ));
        }
    }
    for i in 0..a.decaying {
        let p = [TestProfile::Chamber, TestProfile::FogChamber][(i % 2) as usize];
        let amp = signed(&mut rng, 0.2, 1.0);
        let tau = uni(&mut rng, 300.0, 2400.0);
        let hidden = vec![
            effect_of(Effect::Bias, &[("bias_dph", amp)]),
            effect_of(Effect::WarmUp, &[("amplitude_dph", -amp), ("tau_s", tau)]),
        ];
        let mut t = Trial::hiding(TrialKind::DecayingWarmUp, p, vec![], hidden, next());
        t.expect = vec![Effect::WarmUp];
        out.push(t);
    }
    for o in Outside::ALL {
        for i in 0..a.outside {
            let s = next();
            let (p, x) = outside(o, i, s, &mut rng);
            let mut t = Trial::hiding(TrialKind::Outside(o), p, vec![], vec![], s);
            t.extras = vec![x];
            out.push(t);
        }
    }
    for &e in &effects {
        for _ in 0..a.weak {
            let (p, h, known) = draw(e, &mut rng);
            let s = next();
            let floor = TrialNoise::nominal(p.gyro()).arw_dpsh * 60.0;
            let Some(h) = scaled(&h, p, s, 1.5 * floor) else {
                continue;
            };
            out.push(Trial::hiding(TrialKind::Weak(e), p, known, vec![h], s));
        }
    }
    out
}
