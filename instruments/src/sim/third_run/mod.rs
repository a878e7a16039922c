//! A third run generator, written apart from the project's (model_run.rs)
//! and the second one (heldout_run/) from physics.md and interfaces.md
//! alone, to score discovery on data neither was built on (issue 31): its
//! own profiles (profiles.rs: a rate table with log-spaced rates while the
//! chamber ramps, a FOG soaking at random levels, an RLG heating itself
//! with case lags of 400..800 s and monoblock lags of 1000..3200 s, an RLG
//! stepped through rates below 0.5 deg/s in its lock-in regime, vibration
//! at 45..110 Hz, MEMS gyros heating themselves or in a 5..65 degC
//! chamber), its own thermal model (thermal.rs: lags in series, exact
//! derivatives), its own sensors (lagged, noisy, quantised at 0.01, 1/16
//! or 0.1 degC), its own noise (noise.rs: Kasdin flicker, random walk,
//! Markov; an RLG's angle counts, a MEMS gyro's words averaged), its own
//! random numbers (rng.rs), and terms outside the library (a sinusoidal
//! bias of a quarter to half the record's period, d2T/dt2, a step,
//! ageing, w^2, w|w|, a bias quadratic in temperature, the case less a
//! monoblock). The truth is stated in the library's names only to score.
//!
//! MEMS runs come with a second day of the same gyro (same coefficients,
//! another turn-on bias, another temperature history) for `--validate`.

pub mod noise;
pub mod profiles;
pub mod rng;
pub mod thermal;
pub mod truth;

use super::heldout_run::HeldOutRun;
use gyro_lab_core::model::gyro_kind::GyroKind;
use noise::{rate_noise, NoiseSpec};
use profiles::Profile;
use rng::Rng;
use thermal::Sensor;
use truth::{Physics, Truth};

/// A run of the third generator, its grade, and for MEMS runs a second
/// day of the same gyro.
pub struct ThirdRun {
    pub run: HeldOutRun,
    pub grade: &'static str,
    pub day2: Option<HeldOutRun>,
}

/// How a gyro's output is quantised.
#[derive(Clone, Copy, Debug)]
enum Quant {
    None,
    /// RLG angle counts of this many arcsec.
    Angle(f64),
    /// A MEMS word of this many deg/s, sampled at 100 Hz and averaged.
    Word(f64),
}

fn gyro_of(p: Profile) -> GyroKind {
    match p {
        Profile::RlgChamber | Profile::LockInSteps => GyroKind::Rlg,
        Profile::MemsHeating | Profile::MemsChamber => GyroKind::Mems,
        _ => GyroKind::Fog,
    }
}

/// The gyro's own noise and quantisation, drawn for its kind: a
/// navigation FOG or RLG, an industrial or consumer MEMS gyro.
fn noise_for(g: GyroKind, rng: &mut Rng) -> (NoiseSpec, Quant, &'static str) {
    match g {
        GyroKind::Fog => (
            NoiseSpec {
                arw_dpsh: rng.between(0.002, 0.006),
                flicker_dph: rng.between(0.002, 0.008),
                ..Default::default()
            },
            Quant::None,
            "navigation",
        ),
        GyroKind::Rlg => (
            NoiseSpec {
                arw_dpsh: rng.between(0.0015, 0.004),
                flicker_dph: rng.between(0.001, 0.005),
                ..Default::default()
            },
            Quant::Angle(rng.between(0.5, 2.0)),
            "navigation",
        ),
        GyroKind::Mems => {
            let arw = rng.log_between(0.15, 1.2);
            (
                NoiseSpec {
                    arw_dpsh: arw,
                    flicker_dph: rng.between(3.0, 15.0),
                    ..Default::default()
                },
                Quant::Word([1.0 / 131.0, 1.0 / 65.5, 1.0 / 16.4][rng.pick(3)]),
                if arw < 0.5 { "industrial" } else { "consumer" },
            )
        }
    }
}

/// The white level of a 1 s mean (or of a row, when rows are longer),
/// deg/h: what the weak effects and the terms outside are scaled against.
fn floor_dph(spec: &NoiseSpec, dt: f64) -> f64 {
    spec.arw_dpsh * 60.0 / dt.max(1.0).sqrt()
}

/// RMS of the 1 s means of `x` (deg/s) over rows `t`, about their mean
/// or not, deg/h.
fn rms_1s(t: &[f64], x: &[f64], about_mean: bool) -> f64 {
    let mut sums: std::collections::BTreeMap<i64, (f64, f64)> = Default::default();
    for (s, v) in t.iter().zip(x) {
        let e = sums.entry(s.floor() as i64).or_default();
        e.0 += v;
        e.1 += 1.0;
    }
    let m: Vec<f64> = sums.values().map(|(a, c)| a / c).collect();
    let mean = if about_mean {
        m.iter().sum::<f64>() / m.len().max(1) as f64
    } else {
        0.0
    };
    (m.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / m.len().max(1) as f64).sqrt() * 3600.0
}

/// Extra noise a null run adds on top of the gyro's own.
type ExtraNoise = Box<dyn Fn(&mut NoiseSpec, &mut Rng)>;

/// What a run is made of.
struct Spec {
    name: String,
    category: &'static str,
    profile: Profile,
    truth: Truth,
    expect: Vec<&'static str>,
    /// Extra noise (nulls) on top of the gyro's own.
    extra: Option<ExtraNoise>,
    /// Scale the truth so that the 1 s means of what it adds have an RMS
    /// (about their mean for the terms outside the library, whose level
    /// the constant takes) of this many white floors.
    scale_to: Option<f64>,
}

/// Times the truth states relative to the record: a sinusoid's period (a
/// quarter to half the record), a step's time (30 .. 70 % into it).
fn place_in_record(t: &mut Truth, ph: &Physics, rng: &mut Rng) {
    let span = ph.t.last().copied().unwrap_or(1.0) - ph.t.first().copied().unwrap_or(0.0);
    if let Some((a, _, phase)) = t.sine {
        t.sine = Some((a, span * rng.between(0.25, 0.5), phase));
    }
    if let Some((_, size)) = t.step {
        t.step = Some((ph.t[0] + span * rng.between(0.3, 0.7), size));
    }
}

fn spec(
    name: &str,
    category: &'static str,
    profile: Profile,
    truth: Truth,
    expect: &[&'static str],
) -> Spec {
    Spec {
        name: name.into(),
        category,
        profile,
        truth,
        expect: expect.to_vec(),
        extra: None,
        scale_to: None,
    }
}

/// The run of a spec from `seed`.
fn make(s: &Spec, seed: u64) -> ThirdRun {
    let mut rng = Rng::new(seed);
    let g = gyro_of(s.profile);
    let (ph, dt) = s.profile.build(&mut rng);
    let (mut nz, quant, grade) = noise_for(g, &mut rng);
    if let Some(f) = &s.extra {
        f(&mut nz, &mut rng);
    }
    let mut truth = s.truth.clone();
    place_in_record(&mut truth, &ph, &mut rng);
    if let Some(k) = s.scale_to {
        let e = truth.error(&ph);
        let r = rms_1s(&ph.t, &e, s.category == "outside the library");
        truth = truth.scaled(k * floor_dph(&nz, dt) / r.max(1e-300));
    }
    let run = render(s, &ph, dt, &truth, &nz, quant, g, &mut rng);
    let day2 = (g == GyroKind::Mems).then(|| {
        // The same gyro another day: its coefficients, another turn-on
        // bias and another temperature history; its own noise draw.
        let mut r2 = Rng::new(seed ^ 0xDA72);
        let (ph2, dt2) = s.profile.build(&mut r2);
        let mut t2 = truth.clone();
        t2.bias_dph += r2.signed(20.0, 200.0);
        let mut s2 = Spec {
            name: format!("{}-day2", s.name),
            ..spec("", s.category, s.profile, Truth::default(), &[])
        };
        s2.expect = s.expect.clone();
        render(&s2, &ph2, dt2, &t2, &nz, quant, g, &mut r2)
    });
    ThirdRun { run, grade, day2 }
}

/// Noise, quantisation and sensors on the physics: the run file's content.
#[allow(clippy::too_many_arguments)]
fn render(
    s: &Spec,
    ph: &Physics,
    dt: f64,
    truth: &Truth,
    nz: &NoiseSpec,
    quant: Quant,
    g: GyroKind,
    rng: &mut Rng,
) -> HeldOutRun {
    let n = ph.t.len();
    let err = truth.error(ph);
    let noise = match quant {
        // The word's white noise is added per internal sample below.
        Quant::Word(_) => rate_noise(
            &NoiseSpec {
                arw_dpsh: 0.0,
                ..*nz
            },
            n,
            dt,
            rng,
        ),
        _ => rate_noise(nz, n, dt, rng),
    };
    let clean: Vec<f64> = (0..n).map(|k| ph.w[k] + err[k] + noise[k]).collect();
    let rate = match quant {
        Quant::None => clean,
        Quant::Angle(q_arcsec) => {
            let q = q_arcsec / 3600.0;
            let mut angle = 0.0;
            let mut last = 0.0;
            clean
                .iter()
                .map(|r| {
                    angle += r * dt;
                    let counted = (angle / q).floor() * q;
                    let out = (counted - last) / dt;
                    last = counted;
                    out
                })
                .collect()
        }
        Quant::Word(lsb) => {
            let m = ((dt * 100.0).round() as usize).max(1);
            let sd = nz.arw_dpsh / 60.0 * (m as f64 / dt).sqrt();
            clean
                .iter()
                .map(|r| {
                    (0..m)
                        .map(|_| ((r + sd * rng.normal()) / lsb).round() * lsb)
                        .sum::<f64>()
                        / m as f64
                })
                .collect()
        }
    };
    let mut temp = None;
    let mut case = None;
    let mut mono = None;
    if let (Some(c), Some((a, b))) = (&ph.case, &ph.mono) {
        let sensor = Sensor::draw(rng);
        case = Some(sensor.read(&ph.t, c, rng));
        mono = Some((sensor.read(&ph.t, a, rng), sensor.read(&ph.t, b, rng)));
    } else if let Some(m) = &ph.main {
        let mut sensor = Sensor::draw(rng);
        if g == GyroKind::Mems {
            // On the die: no lag to speak of; a 1/256 or 1/16 degC word.
            sensor.lag_s = 0.5;
            sensor.step_c = [1.0 / 256.0, 0.0625][rng.pick(2)];
        }
        temp = Some(sensor.read(&ph.t, m, rng));
    }
    let mems = g == GyroKind::Mems;
    HeldOutRun {
        name: s.name.clone(),
        category: s.category.into(),
        gyro: g,
        t: ph.t.clone(),
        w: ph.w.clone(),
        rate,
        temp,
        mono,
        case,
        acc: ph.acc.clone(),
        expect: s.expect.iter().map(|x| x.to_string()).collect(),
        truth: truth.library(mems),
        outside: truth.outside(),
        noise: format!("{}; quantisation {quant:?}", nz.describe()),
    }
}

/// The third generator's held-out set: 54 runs (docs/notes/issue-31-discover.md).
pub fn third_set(seed: u64) -> Vec<ThirdRun> {
    let mut r = Rng::new(seed.wrapping_mul(0x2545_F491_4F6C_DD1D) ^ 0x33);
    let d = Truth::default;
    use Profile::*;
    let mut specs: Vec<Spec> = vec![];
    let single = "single effect";
    let mut s1 = |name: &str, p: Profile, t: Truth, e: &[&'static str]| {
        specs.push(spec(&format!("single-{name}"), single, p, t, e));
    };
    s1(
        "bias",
        Table,
        Truth {
            bias_dph: r.signed(0.3, 2.0),
            ..d()
        },
        &["bias"],
    );
    s1(
        "scale_factor_error",
        Table,
        Truth {
            sf_ppm: r.signed(8.0, 120.0),
            ..d()
        },
        &["scale_factor_error"],
    );
    s1(
        "scale_factor_asymmetry",
        Table,
        Truth {
            asym_ppm: r.signed(4.0, 40.0),
            ..d()
        },
        &["scale_factor_asymmetry"],
    );
    s1(
        "scale_factor_temperature",
        Table,
        Truth {
            sf_ppm_per_c: r.signed(0.3, 3.0),
            ..d()
        },
        &["scale_factor_temperature"],
    );
    s1(
        "scale_factor_knee",
        Table,
        Truth {
            sf_ppm_per_c: r.signed(0.5, 2.0),
            knee: Some((r.between(5.0, 40.0), r.signed(2.0, 8.0))),
            ..d()
        },
        &["scale_factor_temperature", "scale_factor_knee"],
    );
    s1(
        "vibration_rectification",
        Vibration,
        Truth {
            vib: r.between(1e-8, 6e-8),
            ..d()
        },
        &["vibration_rectification"],
    );
    s1(
        "lock_in",
        LockInSteps,
        Truth {
            lock_in_dps: r.between(0.03, 0.3),
            ..d()
        },
        &["lock_in"],
    );
    s1(
        "thermal_difference",
        RlgChamber,
        Truth {
            k_dt: r.signed(0.04, 0.2),
            ..d()
        },
        &["thermal_difference"],
    );
    s1(
        "thermal_gradient",
        RlgChamber,
        Truth {
            k_grad: r.signed(150.0, 600.0),
            ..d()
        },
        &["thermal_gradient"],
    );
    s1(
        "thermal_difference_squared",
        RlgChamber,
        Truth {
            k_dt2: r.signed(0.005, 0.03),
            ..d()
        },
        &["thermal_difference_squared"],
    );
    s1(
        "case_temperature",
        RlgChamber,
        Truth {
            k_case: r.signed(0.003, 0.012),
            ..d()
        },
        &["case_temperature"],
    );
    s1(
        "warm_up",
        RlgChamber,
        Truth {
            warm: Some((r.signed(0.2, 0.6), r.between(400.0, 2500.0), false)),
            ..d()
        },
        &["warm_up"],
    );
    s1(
        "bias_temperature",
        FogSoak,
        Truth {
            bias_per_c: r.signed(0.01, 0.04),
            ..d()
        },
        &["bias_temperature"],
    );
    s1(
        "shupe",
        FogSoak,
        Truth {
            rate_coef: r.signed(40.0, 200.0),
            ..d()
        },
        &["shupe"],
    );
    // MEMS gyros whose bias follows their temperature.
    let mems = "mems thermal";
    for (name, p, rate) in [
        ("mems-heating", MemsHeating, false),
        ("mems-chamber", MemsChamber, false),
        ("mems-chamber-rate", MemsChamber, true),
    ] {
        let t = Truth {
            bias_dph: r.signed(200.0, 3000.0),
            bias_per_c: r.signed(20.0, 300.0),
            rate_coef: if rate { r.signed(3000.0, 20000.0) } else { 0.0 },
            ..d()
        };
        let e: &[&'static str] = if rate {
            &["bias", "bias_temperature", "bias_temperature_rate"]
        } else {
            &["bias", "bias_temperature"]
        };
        specs.push(spec(name, mems, p, t, e));
    }
    // Nulls: the model is the truth, the noise is coloured.
    let null = "null, coloured noise";
    type Extra = Box<dyn Fn(&mut NoiseSpec, &mut Rng)>;
    let nulls: Vec<(&str, Profile, Extra)> = vec![
        (
            "flicker-fog",
            FogSoak,
            Box::new(|n, r| n.flicker_dph = r.between(0.02, 0.06)),
        ),
        (
            "rw-fog-table",
            Table,
            Box::new(|n, r| n.rrw_dphsh = r.between(0.02, 0.06)),
        ),
        (
            "markov-fog",
            FogSoak,
            Box::new(|n, r| {
                n.markov_dph = r.between(0.01, 0.04);
                n.markov_s = r.log_between(300.0, 3000.0);
            }),
        ),
        (
            "flicker-rlg",
            RlgChamber,
            Box::new(|n, r| n.flicker_dph = r.between(0.01, 0.04)),
        ),
        (
            "rw-rlg",
            RlgChamber,
            Box::new(|n, r| n.rrw_dphsh = r.between(0.01, 0.04)),
        ),
        (
            "mix-rlg",
            RlgChamber,
            Box::new(|n, r| {
                n.flicker_dph = r.between(0.005, 0.02);
                n.rrw_dphsh = r.between(0.005, 0.02);
                n.markov_dph = r.between(0.005, 0.02);
                n.markov_s = r.log_between(200.0, 2000.0);
            }),
        ),
        (
            "flicker-mems",
            MemsHeating,
            Box::new(|n, r| n.flicker_dph = r.between(20.0, 60.0)),
        ),
        (
            "rw-mems",
            MemsChamber,
            Box::new(|n, r| n.rrw_dphsh = r.between(5.0, 20.0)),
        ),
    ];
    for (name, p, x) in nulls {
        let mut s = spec(&format!("null-{name}"), null, p, d(), &[]);
        s.extra = Some(x);
        specs.push(s);
    }
    // A bias with each thermal term, RLG heating itself in the chamber.
    let bt = "bias + thermal term (RLG chamber)";
    let terms: Vec<(&'static str, Truth)> = vec![
        (
            "thermal_difference",
            Truth {
                k_dt: r.signed(0.04, 0.2),
                ..d()
            },
        ),
        (
            "thermal_gradient",
            Truth {
                k_grad: r.signed(150.0, 600.0),
                ..d()
            },
        ),
        (
            "thermal_difference_squared",
            Truth {
                k_dt2: r.signed(0.005, 0.03),
                ..d()
            },
        ),
        (
            "case_temperature",
            Truth {
                k_case: r.signed(0.003, 0.012),
                ..d()
            },
        ),
        (
            "warm_up",
            Truth {
                warm: Some((r.signed(0.2, 0.5), r.between(500.0, 2500.0), false)),
                ..d()
            },
        ),
    ];
    for (name, t) in terms {
        let t = Truth {
            bias_dph: r.signed(0.3, 1.5),
            ..t
        };
        specs.push(spec(
            &format!("bias+{name}"),
            bt,
            RlgChamber,
            t,
            &["bias", name],
        ));
    }
    // Warm-ups that decay to no bias.
    for (i, p) in [RlgChamber, RlgChamber, FogSoak, FogSoak]
        .into_iter()
        .enumerate()
    {
        let t = Truth {
            warm: Some((r.signed(0.3, 1.2), r.between(300.0, 2500.0), true)),
            ..d()
        };
        specs.push(spec(
            &format!("decaying-{i}"),
            "decaying warm_up",
            p,
            t,
            &["warm_up"],
        ));
    }
    // Outside the library, each at 3 to 8 white floors.
    let out = "outside the library";
    let outside: Vec<(&str, Profile, Truth)> = vec![
        (
            "sine-fog",
            FogSoak,
            Truth {
                sine: Some((1.0, 0.0, r.between(0.0, std::f64::consts::TAU))),
                ..d()
            },
        ),
        (
            "sine-rlg",
            RlgChamber,
            Truth {
                sine: Some((1.0, 0.0, r.between(0.0, std::f64::consts::TAU))),
                ..d()
            },
        ),
        (
            "curvature-fog",
            FogSoak,
            Truth {
                curv: r.signed(1.0, 2.0),
                ..d()
            },
        ),
        (
            "curvature-rlg",
            RlgChamber,
            Truth {
                curv: r.signed(1.0, 2.0),
                ..d()
            },
        ),
        (
            "step-fog",
            FogSoak,
            Truth {
                step: Some((0.0, r.signed(1.0, 2.0))),
                ..d()
            },
        ),
        (
            "ageing-rlg",
            RlgChamber,
            Truth {
                ageing_dph_per_h: r.signed(1.0, 2.0),
                ..d()
            },
        ),
        (
            "w2-table",
            Table,
            Truth {
                w2: r.signed(1.0, 2.0),
                ..d()
            },
        ),
        (
            "w-abs-w-table",
            Table,
            Truth {
                wabsw: r.signed(1.0, 2.0),
                ..d()
            },
        ),
        (
            "temp-squared-fog",
            FogSoak,
            Truth {
                temp2: r.signed(1.0, 2.0),
                ..d()
            },
        ),
        (
            "case-minus-mono-rlg",
            RlgChamber,
            Truth {
                case_minus_mono: r.signed(1.0, 2.0),
                ..d()
            },
        ),
    ];
    for (name, p, t) in outside {
        let mut s = spec(&format!("outside-{name}"), out, p, t, &[]);
        s.scale_to = Some(r.between(3.0, 8.0));
        specs.push(s);
    }
    // Weak effects, 1.5 to 2 white floors.
    let weak: Vec<(&'static str, Profile, Truth)> = vec![
        (
            "bias",
            Table,
            Truth {
                bias_dph: 1.0,
                ..d()
            },
        ),
        ("scale_factor_error", Table, Truth { sf_ppm: 1.0, ..d() }),
        (
            "bias_temperature",
            FogSoak,
            Truth {
                bias_per_c: 1.0,
                ..d()
            },
        ),
        (
            "shupe",
            FogSoak,
            Truth {
                rate_coef: 1.0,
                ..d()
            },
        ),
        ("case_temperature", RlgChamber, Truth { k_case: 1.0, ..d() }),
        (
            "vibration_rectification",
            Vibration,
            Truth { vib: 1.0, ..d() },
        ),
    ];
    for (name, p, t) in weak {
        let sign = if r.unit() < 0.5 { -1.0 } else { 1.0 };
        let mut s = spec(
            &format!("weak-{name}"),
            "weak (1.5 x floor)",
            p,
            t.scaled(sign),
            &[name],
        );
        s.scale_to = Some(r.between(1.5, 2.0));
        specs.push(s);
    }
    // Two at once.
    let two = "two hidden";
    specs.push(spec(
        "pair-bias+sf",
        two,
        Table,
        Truth {
            bias_dph: r.signed(0.3, 1.0),
            sf_ppm: r.signed(20.0, 80.0),
            ..d()
        },
        &["bias", "scale_factor_error"],
    ));
    specs.push(spec(
        "pair-sf-temp+asym",
        two,
        Table,
        Truth {
            sf_ppm_per_c: r.signed(0.5, 2.0),
            asym_ppm: r.signed(8.0, 30.0),
            ..d()
        },
        &["scale_factor_temperature", "scale_factor_asymmetry"],
    ));
    specs.push(spec(
        "pair-case+warm",
        two,
        RlgChamber,
        Truth {
            k_case: r.signed(0.004, 0.012),
            warm: Some((r.signed(0.2, 0.5), r.between(600.0, 2000.0), false)),
            ..d()
        },
        &["case_temperature", "warm_up"],
    ));
    specs.push(spec(
        "pair-bias_temperature+shupe",
        two,
        FogSoak,
        Truth {
            bias_per_c: r.signed(0.01, 0.04),
            rate_coef: r.signed(60.0, 200.0),
            ..d()
        },
        &["bias_temperature", "shupe"],
    ));
    specs
        .iter()
        .enumerate()
        .map(|(i, s)| {
            make(
                s,
                seed.wrapping_mul(1_000_003)
                    .wrapping_add(i as u64 * 7919 + 17),
            )
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_set_has_its_runs_and_finite_rates() {
        let runs = third_set(2);
        assert_eq!(runs.len(), 54);
        for r in &runs {
            assert_eq!(r.run.t.len(), r.run.rate.len());
            assert!(r.run.rate.iter().all(|v| v.is_finite()), "{}", r.run.name);
            assert_eq!(r.day2.is_some(), r.run.gyro == GyroKind::Mems);
        }
    }
}
