//! A second run generator, written apart from the project's (model_run.rs)
//! to test discovery on data it was not built on: its own profiles (a rate
//! table with ramps between plateaus, a staircase chamber, a sinusoidal
//! chamber, an RLG with its own monoblock thermal model, a continuous
//! rate sweep through lock-in, vibration at another frequency), its own
//! parameters, its own formulas (exact derivatives of the true
//! temperatures where the library uses a sensor's filtered one, the mean
//! over each sample of what varies within it, angle quantization), its
//! own noise (white; flicker by spectral synthesis; rate random walk;
//! first-order Markov; spikes) and effects outside the library (w^2, w^3,
//! a bias step, a rate ramp, d2T/dt2). Nothing here calls the library's
//! effects: the truth is stated in the library's names and parameters
//! only for scoring.

pub mod noise;
pub mod physics;
pub mod truth;

use gyro_lab_core::model::gyro_kind::GyroKind;
use noise::{noise_series, Noise, Rng};
use physics::{fog_rest, rlg_chamber, sweep, table, vibration, Physics};
use std::collections::BTreeMap;
use truth::Truth;

/// A generated run and its truth.
#[derive(Clone, Debug)]
pub struct HeldOutRun {
    pub name: String,
    pub category: String,
    pub gyro: GyroKind,
    pub t: Vec<f64>,
    pub w: Vec<f64>,
    pub rate: Vec<f64>,
    pub temp: Option<Vec<f64>>,
    pub mono: Option<(Vec<f64>, Vec<f64>)>,
    pub case: Option<Vec<f64>>,
    pub acc: Option<Vec<f64>>,
    /// What a right answer names, and the truth in the library's names
    /// and parameters (a decaying warm-up A exp(-t/tau) as the library's
    /// constant A and warm-up of amplitude -A).
    pub expect: Vec<String>,
    pub truth: BTreeMap<String, BTreeMap<String, f64>>,
    /// Disturbances outside the library, described.
    pub outside: Vec<String>,
    pub noise: String,
}

/// The kinds of profile.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum Profile {
    Table,
    FogRest,
    RlgChamber,
    Sweep,
    Vibration,
}

impl Profile {
    fn gyro(self) -> GyroKind {
        match self {
            Profile::RlgChamber | Profile::Sweep => GyroKind::Rlg,
            _ => GyroKind::Fog,
        }
    }

    fn physics(self, rng: &mut Rng) -> (Physics, f64) {
        match self {
            Profile::Table => (table(rng, 0.5, 9000.0), 0.5),
            Profile::FogRest => (fog_rest(1.0, 10_800.0), 1.0),
            Profile::RlgChamber => (rlg_chamber(2.0, 18_000.0), 2.0),
            Profile::Sweep => (sweep(0.05, 1200.0), 0.05),
            Profile::Vibration => (vibration(1.0 / 140.0, 480.0), 1.0 / 140.0),
        }
    }

    fn noise(self) -> Noise {
        let (arw, fl) = match self.gyro() {
            GyroKind::Fog | GyroKind::Mems => (0.004, 0.006),
            GyroKind::Rlg => (0.0025, 0.004),
        };
        Noise {
            arw_dpsh: arw,
            flicker_dph: fl,
            rrw_dphsh: 0.0,
            markov: (0.0, 1.0),
            quant_arcsec: if self.gyro() == GyroKind::Rlg {
                0.2
            } else {
                0.0
            },
            spikes: (0, 0.0),
        }
    }
}

/// Builds one run.
fn make(
    name: &str,
    category: &str,
    p: Profile,
    truth: Truth,
    expect: &[&str],
    noise: Option<Noise>,
    seed: u64,
) -> HeldOutRun {
    let mut rng = Rng::new(seed);
    let (ph, dt) = p.physics(&mut rng);
    let nz = noise.unwrap_or(p.noise());
    let n = ph.t.len();
    let y = truth.output(&ph);
    let noise_v = noise_series(&nz, n, dt, seed);
    let rate: Vec<f64> = (0..n).map(|k| ph.w[k] + y[k] + noise_v[k]).collect();
    // Sensors: 0.01 degC steps with 0.004 degC noise.
    let sense = |x: &[f64], rng: &mut Rng| -> Vec<f64> {
        x.iter()
            .map(|v| ((v + 0.004 * rng.normal()) * 100.0).round() / 100.0)
            .collect()
    };
    let rlg = p.gyro() == GyroKind::Rlg;
    let (temp, case, mono) = if ph.temp.is_empty() {
        (None, None, None)
    } else if let Some((a, b, _)) = &ph.mono {
        (
            None,
            Some(sense(&ph.temp, &mut rng)),
            Some((sense(a, &mut rng), sense(b, &mut rng))),
        )
    } else {
        (Some(sense(&ph.temp, &mut rng)), None, None)
    };
    HeldOutRun {
        name: name.into(),
        category: category.into(),
        gyro: p.gyro(),
        t: ph.t.clone(),
        w: ph.w.clone(),
        rate,
        temp,
        mono,
        case,
        acc: ph.acc.clone(),
        expect: expect.iter().map(|s| s.to_string()).collect(),
        truth: truth.library(rlg),
        outside: truth.outside(),
        noise: nz.describe(),
    }
}

/// The held-out set: 53 runs across the categories (see the README of
/// docs/discovery.md).
pub fn held_out(seed: u64) -> Vec<HeldOutRun> {
    let mut r = Rng::new(seed ^ 0xBEEF);
    let mut out = vec![];
    let mut s = seed * 7919;
    let mut next = || {
        s += 1;
        s
    };
    use Profile::*;
    let d = Truth::default;
    // 1. Each effect of the library alone.
    let singles: Vec<(&str, Profile, Truth)> = vec![
        (
            "bias",
            Table,
            Truth {
                bias: r.pm(0.2, 1.5),
                ..d()
            },
        ),
        (
            "scale_factor_error",
            Table,
            Truth {
                sf_ppm: r.pm(10.0, 150.0),
                ..d()
            },
        ),
        (
            "scale_factor_asymmetry",
            Table,
            Truth {
                asym_ppm: r.pm(5.0, 40.0),
                ..d()
            },
        ),
        (
            "scale_factor_temperature",
            Table,
            Truth {
                sf_t: r.pm(0.3, 4.0),
                ..d()
            },
        ),
        (
            "scale_factor_knee",
            Table,
            Truth {
                sf_t: r.pm(0.5, 2.0),
                knee: Some((r.range(5.0, 40.0), r.pm(2.0, 8.0))),
                ..d()
            },
        ),
        (
            "vibration_rectification",
            Vibration,
            Truth {
                vib: r.range(1e-8, 6e-8),
                ..d()
            },
        ),
        (
            "lock_in",
            Sweep,
            Truth {
                lock_in: r.range(0.08, 0.6),
                ..d()
            },
        ),
        (
            "thermal_difference",
            RlgChamber,
            Truth {
                k_dt: r.pm(0.05, 0.25),
                ..d()
            },
        ),
        (
            "thermal_gradient",
            RlgChamber,
            Truth {
                k_grad: r.pm(200.0, 600.0),
                ..d()
            },
        ),
        (
            "thermal_difference_squared",
            RlgChamber,
            Truth {
                k_dt2: r.pm(0.01, 0.04),
                ..d()
            },
        ),
        (
            "case_temperature",
            RlgChamber,
            Truth {
                k_case: r.pm(0.004, 0.015),
                ..d()
            },
        ),
        (
            "warm_up",
            RlgChamber,
            Truth {
                warm: Some((r.pm(0.2, 0.6), r.range(400.0, 2500.0), false)),
                ..d()
            },
        ),
        (
            "bias_temperature",
            FogRest,
            Truth {
                b_t: r.pm(0.01, 0.04),
                ..d()
            },
        ),
        (
            "shupe",
            FogRest,
            Truth {
                shupe: r.pm(40.0, 150.0),
                ..d()
            },
        ),
    ];
    for (name, p, t) in singles {
        let known: Vec<&str> = if name == "scale_factor_knee" {
            vec!["scale_factor_temperature", "scale_factor_knee"]
        } else {
            vec![name]
        };
        out.push(make(
            &format!("single-{name}"),
            "single effect",
            p,
            t,
            &known,
            None,
            next(),
        ));
    }
    // 2. Nulls with coloured noise.
    let nulls: Vec<(&str, Profile, Noise)> = vec![
        (
            "rw-table",
            Table,
            Noise {
                rrw_dphsh: 0.05,
                ..Table.noise()
            },
        ),
        (
            "rw-rlg",
            RlgChamber,
            Noise {
                rrw_dphsh: 0.03,
                ..RlgChamber.noise()
            },
        ),
        (
            "rw-fog-rest",
            FogRest,
            Noise {
                rrw_dphsh: 0.04,
                ..FogRest.noise()
            },
        ),
        (
            "flicker-table",
            Table,
            Noise {
                flicker_dph: 0.05,
                ..Table.noise()
            },
        ),
        (
            "flicker-rlg",
            RlgChamber,
            Noise {
                flicker_dph: 0.03,
                ..RlgChamber.noise()
            },
        ),
        (
            "flicker-fog-rest",
            FogRest,
            Noise {
                flicker_dph: 0.04,
                ..FogRest.noise()
            },
        ),
        (
            "markov-rlg",
            RlgChamber,
            Noise {
                markov: (0.02, 600.0),
                ..RlgChamber.noise()
            },
        ),
        (
            "spike-fog-rest",
            FogRest,
            Noise {
                spikes: (2, 40.0),
                ..FogRest.noise()
            },
        ),
    ];
    for (name, p, nz) in nulls {
        out.push(make(
            &format!("null-{name}"),
            "null, coloured noise",
            p,
            d(),
            &[],
            Some(nz),
            next(),
        ));
    }
    // 3. A bias with each thermal term, RLG in the chamber.
    let thermal: Vec<(&str, Truth)> = vec![
        (
            "thermal_difference",
            Truth {
                k_dt: r.pm(0.05, 0.2),
                ..d()
            },
        ),
        (
            "thermal_gradient",
            Truth {
                k_grad: r.pm(200.0, 600.0),
                ..d()
            },
        ),
        (
            "thermal_difference_squared",
            Truth {
                k_dt2: r.pm(0.01, 0.04),
                ..d()
            },
        ),
        (
            "case_temperature",
            Truth {
                k_case: r.pm(0.004, 0.015),
                ..d()
            },
        ),
        (
            "warm_up",
            Truth {
                warm: Some((r.pm(0.2, 0.5), r.range(500.0, 2000.0), false)),
                ..d()
            },
        ),
    ];
    for (name, t) in thermal {
        let t = Truth {
            bias: r.pm(0.3, 1.2),
            ..t
        };
        out.push(make(
            &format!("bias+{name}"),
            "bias + thermal term (RLG chamber)",
            RlgChamber,
            t,
            &["bias", name],
            None,
            next(),
        ));
    }
    // 4. Warm-ups decaying to no bias.
    for (i, p) in [RlgChamber, RlgChamber, RlgChamber, FogRest, FogRest]
        .into_iter()
        .enumerate()
    {
        let t = Truth {
            warm: Some((r.pm(0.3, 1.2), r.range(300.0, 2000.0), true)),
            ..d()
        };
        out.push(make(
            &format!("decaying-{i}"),
            "decaying warm_up",
            p,
            t,
            &["warm_up"],
            None,
            next(),
        ));
    }
    // 5. Outside the library.
    let outside: Vec<(&str, Profile, Truth)> = vec![
        (
            "w2-a",
            Table,
            Truth {
                w2: r.pm(0.6, 2.0) / 160_000.0,
                ..d()
            },
        ),
        (
            "w2-b",
            Table,
            Truth {
                w2: r.pm(0.6, 2.0) / 160_000.0,
                ..d()
            },
        ),
        (
            "w3-a",
            Table,
            Truth {
                w3: r.pm(0.6, 2.0) / 6.4e7,
                ..d()
            },
        ),
        (
            "w3-b",
            Table,
            Truth {
                w3: r.pm(0.6, 2.0) / 6.4e7,
                ..d()
            },
        ),
        (
            "step-rest",
            FogRest,
            Truth {
                step: Some((r.range(3000.0, 8000.0), r.pm(0.15, 0.6))),
                ..d()
            },
        ),
        (
            "step-rlg",
            RlgChamber,
            Truth {
                step: Some((r.range(5000.0, 13000.0), r.pm(0.1, 0.4))),
                ..d()
            },
        ),
        (
            "ramp-rlg",
            RlgChamber,
            Truth {
                ramp: r.pm(0.05, 0.15),
                ..d()
            },
        ),
        (
            "ramp-fog",
            FogRest,
            Truth {
                ramp: r.pm(0.08, 0.25),
                ..d()
            },
        ),
        (
            "curvature-fog",
            FogRest,
            Truth {
                curv: r.pm(3e4, 8e4),
                ..d()
            },
        ),
        (
            "curvature-rlg",
            RlgChamber,
            Truth {
                curv: r.pm(3e4, 8e4),
                ..d()
            },
        ),
    ];
    for (name, p, t) in outside {
        out.push(make(
            &format!("outside-{name}"),
            "outside the library",
            p,
            t,
            &[],
            None,
            next(),
        ));
    }
    // 6. Weak effects, near 1.5 times the noise floor.
    let weak: Vec<(&str, Profile, Truth)> = vec![
        ("bias", Table, Truth { bias: 0.35, ..d() }),
        ("scale_factor_error", Table, Truth { sf_ppm: 2.0, ..d() }),
        (
            "scale_factor_temperature",
            Table,
            Truth { sf_t: 0.08, ..d() },
        ),
        ("bias_temperature", FogRest, Truth { b_t: 0.022, ..d() }),
        ("shupe", FogRest, Truth { shupe: 60.0, ..d() }),
        (
            "thermal_difference",
            RlgChamber,
            Truth { k_dt: 0.05, ..d() },
        ),
        (
            "case_temperature",
            RlgChamber,
            Truth {
                k_case: 0.008,
                ..d()
            },
        ),
        (
            "vibration_rectification",
            Vibration,
            Truth { vib: 7e-9, ..d() },
        ),
    ];
    for (name, p, t) in weak {
        let sign = if r.u() < 0.5 { -1.0 } else { 1.0 };
        let seed = next();
        // Scaled so that the 1 s means of what it adds have an RMS of 1.5
        // times the white noise of a 1 s mean.
        let (ph, _) = p.physics(&mut Rng::new(seed));
        let y = t.output(&ph);
        let mut sums: BTreeMap<i64, (f64, f64)> = BTreeMap::new();
        for (tk, v) in ph.t.iter().zip(&y) {
            let e = sums.entry(tk.floor() as i64).or_default();
            e.0 += v;
            e.1 += 1.0;
        }
        let rms = (sums.values().map(|(a, c)| (a / c).powi(2)).sum::<f64>() / sums.len() as f64)
            .sqrt()
            * 3600.0;
        let target = 1.5 * p.noise().arw_dpsh * 60.0;
        let t = t.scaled(sign * target / rms.max(1e-12));
        out.push(make(
            &format!("weak-{name}"),
            "weak (1.5 x floor)",
            p,
            t,
            &[name],
            None,
            seed,
        ));
    }
    // 7. Two at once.
    let pairs: Vec<(&str, Profile, Truth, Vec<&str>)> = vec![
        (
            "bias+sf",
            Table,
            Truth {
                bias: r.pm(0.3, 1.0),
                sf_ppm: r.pm(20.0, 80.0),
                ..d()
            },
            vec!["bias", "scale_factor_error"],
        ),
        (
            "sf-temp+asym",
            Table,
            Truth {
                sf_t: r.pm(0.5, 2.0),
                asym_ppm: r.pm(8.0, 30.0),
                ..d()
            },
            vec!["scale_factor_temperature", "scale_factor_asymmetry"],
        ),
        (
            "case+warm",
            RlgChamber,
            Truth {
                k_case: r.pm(0.005, 0.015),
                warm: Some((r.pm(0.2, 0.5), r.range(600.0, 2000.0), false)),
                ..d()
            },
            vec!["case_temperature", "warm_up"],
        ),
    ];
    for (name, p, t, e) in pairs {
        out.push(make(
            &format!("pair-{name}"),
            "two hidden",
            p,
            t,
            &e,
            None,
            next(),
        ));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fifty_three_runs_in_the_categories() {
        let runs = held_out(1);
        assert_eq!(runs.len(), 53);
        for r in &runs {
            assert_eq!(r.t.len(), r.rate.len());
            assert!(r.rate.iter().all(|v| v.is_finite()), "{}", r.name);
        }
    }
}
