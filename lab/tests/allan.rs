//! `gyro-lab allan`: recovery of known noise terms from the project's
//! generators, the JSON and files it promises, a report that fetches
//! nothing and shows its data, and bad input (one line, exit 2).
//! The 100-seed figures are `cargo lab bench allan`'s; this runs a few.

#![allow(clippy::needless_range_loop)] // per-term parallel arrays

mod common;
use common::{lab, lab_ok};

use gyro_lab_core::bench::allan::{judge, truth_present, SAMPLES, SCENARIOS, SHORT, TAU0_S};
use gyro_lab_core::noise::analysis::{analyse, Allan};
use gyro_lab_core::noise::terms;
use gyro_lab_core::sim::independent_noise;
use gyro_lab_core::sim::noise_run::{record, record_with, Truth};

#[test]
fn known_terms_recovered_and_absent_ones_not_reported() {
    // Every scenario (the power laws, the sinusoid, the Markov term), 6
    // seeds: each present term's intervals hold the truth in at least 5
    // (the bench: at least 90 of 100), no absent term reported more than
    // once (the bench: under 1 %).
    for sc in SCENARIOS {
        let present = truth_present(&sc.truth);
        let mut held = [0; terms::ALL];
        let mut false_reports = 0;
        for seed in 1..=6 {
            let an = analyse(&record_with(&sc.truth, SAMPLES, TAU0_S, seed), TAU0_S).unwrap();
            for (j, &(reported, ok, _)) in judge(&an, &sc.truth).iter().enumerate() {
                if present[j] && reported && ok {
                    held[j] += 1;
                } else if !present[j] && reported {
                    false_reports += 1;
                }
            }
        }
        for j in 0..terms::ALL {
            if present[j] {
                assert!(
                    held[j] >= 5,
                    "{}: {} held in {}/6",
                    sc.name,
                    SHORT[j],
                    held[j]
                );
            }
        }
        assert!(
            false_reports <= 1,
            "{}: {false_reports} false reports",
            sc.name
        );
    }
}

/// The fit's N: the angle random walk term (deg/sqrt(h)).
fn fitted_n(an: &Allan) -> Option<f64> {
    an.terms.present[1].then(|| terms::to_units(1, an.terms.c[1]))
}

/// The fraction of measured intervals the model passes through.
fn inside_fraction(an: &Allan) -> f64 {
    1.0 - an.terms.goodness.outside.len() as f64 / an.taus.len() as f64
}

#[test]
fn textbook_curve_from_the_independent_generator() {
    // White noise, flicker and a rate random walk by other algorithms
    // (FFT flicker, sub-sampled walk, splitmix64 normals): the model
    // passes through at least 90 % of the intervals, N within 10 % of the
    // -1/2 line's reading and within its interval of the truth, B no higher
    // than the floor's reading and within 35 % of it, and the truth.
    //
    // A textbook curve has a floor that the rate random walk visibly
    // climbs out of. The truth was first N = 0.05 deg/sqrt(h), B = 0.2
    // deg/h, K = 0.05 deg/h/sqrt(h) (8.3e-4 deg/h/sqrt(s)): K^2 tau / 3
    // reaches the flicker's (0.664 B)^2 = 0.0176 (deg/h)^2 only at tau =
    // 76 000 s, beyond the longest averaging time of this 200 000 s record
    // (63 000 s, about 2 degrees of freedom), so the curve stays flat to
    // its end, the fit rightly found no K and the floor is rightly only an
    // upper bound (`resolved` false, seed 1): the test's truth, not the
    // reading, was wrong. A larger K alone does not mend it: the floor's
    // reading is (2 N K / sqrt(3) + (0.664 B)^2)^(1/2) at tau* = sqrt(3) N/K,
    // and with N = 0.05 a K that rises clearly (0.5) lifts it to 1.6 x
    // 0.664 B, where B and floor/0.664 no longer agree to 35 %, while K =
    // 0.2 still left one seed in four unresolved (a rate random walk seen
    // at 3 degrees of freedom can fall). So N = 0.02 and K = 0.5: the
    // floor is 1.3 x 0.664 B at 250 s, and the walk triples the
    // deviation by 10 000 s, where 18 degrees of freedom resolve it.
    let truth = Truth::laws([0.0, 0.02, 0.2, 0.5, 0.0]);
    let mut covered = [0; 3];
    for seed in 1..=4 {
        let y = independent_noise::record(&truth, SAMPLES, TAU0_S, seed);
        let an = analyse(&y, TAU0_S).unwrap();
        let r = &an.readings;
        assert!(an.terms.goodness.consistent, "seed {seed}");
        assert!(
            inside_fraction(&an) >= 0.9,
            "seed {seed}: {}",
            inside_fraction(&an)
        );
        let n = fitted_n(&an).unwrap();
        let n_read = r.arw_dpsh.unwrap();
        assert!(
            (n / n_read - 1.0).abs() < 0.1,
            "seed {seed}: N {n} vs {n_read}"
        );
        assert!(r.resolved, "seed {seed}");
        let b = terms::to_units(2, an.terms.c[2]);
        assert!(
            b <= r.bias_instability_dph && b >= 0.65 * r.bias_instability_dph,
            "seed {seed}: B {b} vs {}",
            r.bias_instability_dph
        );
        for (k, j) in [1usize, 2, 3].into_iter().enumerate() {
            let (lo, hi) = (
                terms::to_units(j, an.terms.lo[j]),
                terms::to_units(j, an.terms.hi[j]),
            );
            if an.terms.present[j] && lo <= truth.laws[j] && truth.laws[j] <= hi {
                covered[k] += 1;
            }
        }
        for j in [0, 4] {
            assert!(
                !an.terms.present[j],
                "seed {seed}: {} reported",
                terms::NAMES[j]
            );
        }
        assert!(
            an.terms.sinusoid.is_none() && an.terms.correlated.is_none(),
            "seed {seed}"
        );
    }
    assert!(covered.iter().all(|&c| c >= 3), "{covered:?}");
}

#[test]
fn rlg_like_curve_is_quantization_and_a_sinusoid_not_white_noise() {
    // A true angle quantizer (20 arcsec: quanta of 69 arcsec) read through
    // a stripped dither as a ring-laser gyro's is, on little white noise,
    // with a sinusoid whose bump sits at 0.37/f = 3.7 s, from the
    // independent generator: the -1 slope is named quantization, the bump
    // a sinusoid of the right frequency and amplitude, and any angle random
    // walk reported stays below the bound the long-tau points give.
    //
    // Q = 12 where the truth is 20 was the generator's, not the fit's: the
    // quantizer had no dither, and this sinusoid swings the angle 0.018
    // deg peak to peak, less than one 0.019 deg quantum, so the counter's
    // error followed the signal instead of being white angle noise of
    // quantum^2/12 (IEEE 952's 3 Q^2 / tau^2 holds for that white error
    // only; independent_noise.rs). With the dither the record's deviation
    // meets 3 Q^2 / tau^2 at Q = 20 where the sinusoid has its nulls (tau =
    // k/f). The fit then also had to find f to about 1/tau_max
    // (fit::refine_frequency): these estimates are so precise that a
    // sinusoid at 0.104 Hz missed every point.
    let truth = Truth {
        laws: [20.0, 0.002, 0.0, 0.0, 0.0],
        sinusoid: Some((20.0, 0.1)),
        markov: None,
    };
    for seed in 1..=3 {
        let y = independent_noise::record(&truth, SAMPLES, TAU0_S, seed);
        let an = analyse(&y, TAU0_S).unwrap();
        let t = &an.terms;
        assert!(t.present[0], "seed {seed}: quantization absent");
        let q = terms::to_units(0, t.c[0]);
        assert!((q / 20.0 - 1.0).abs() < 0.05, "seed {seed}: Q {q}");
        let s = t.sinusoid.as_ref().expect("sinusoid");
        assert!(
            (s.frequency_hz.value / 0.1 - 1.0).abs() < 0.02,
            "seed {seed}: f {:?}",
            s.frequency_hz
        );
        let a = s.amplitude_dps.value * 3600.0;
        assert!((a / 20.0 - 1.0).abs() < 0.1, "seed {seed}: amplitude {a}");
        // N^2/tau <= AVAR at every tau: N below min over tau of ADEV sqrt(tau).
        let bound = (0..an.taus.len())
            .map(|i| an.avar_hi[i].sqrt() * an.taus[i].sqrt() * 60.0)
            .fold(f64::INFINITY, f64::min);
        if let Some(n) = fitted_n(&an) {
            assert!(
                n <= bound,
                "seed {seed}: N {n} above the long-tau bound {bound}"
            );
        }
    }
}

#[test]
fn markov_hump_from_the_independent_generator() {
    // White noise, an AR(1) Markov term (sigma 0.5 deg/h, T 300 s) and no
    // other term: the Markov term is found, its sigma and time within
    // their intervals in most seeds, and no flicker or random walk is
    // invented for its hump.
    let truth = Truth {
        laws: [0.0, 0.02, 0.0, 0.0, 0.0],
        sinusoid: None,
        markov: Some((0.5, 300.0)),
    };
    let mut held = 0;
    for seed in 1..=4 {
        let an = analyse(
            &independent_noise::record(&truth, SAMPLES, TAU0_S, seed),
            TAU0_S,
        )
        .unwrap();
        let (reported, ok, _) = judge(&an, &truth)[terms::MARKOV];
        assert!(reported, "seed {seed}");
        held += usize::from(ok);
        for j in [0, 2, 3, 4] {
            assert!(
                !an.terms.present[j],
                "seed {seed}: {} reported",
                terms::NAMES[j]
            );
        }
    }
    assert!(held >= 3, "{held}/4");
}

#[test]
fn a_curve_the_model_cannot_hold_is_said_so_and_where() {
    // Two sinusoids a decade and a half apart (the model holds one) on
    // white noise: the fit is inconsistent, the averaging times it misses
    // include the bump it could not take, and no reported term has an
    // interval under 1 % wide.
    let tau0 = 1.0;
    let mut y = record_with(
        &Truth {
            laws: [0.0, 0.05, 0.0, 0.0, 0.0],
            sinusoid: Some((3.0, 0.1)),
            markov: None,
        },
        SAMPLES,
        tau0,
        5,
    );
    let extra = record_with(
        &Truth {
            laws: [0.0; 5],
            sinusoid: Some((3.0, 0.003)),
            markov: None,
        },
        SAMPLES,
        tau0,
        6,
    );
    y.iter_mut().zip(&extra).for_each(|(a, b)| *a += b);
    let an = analyse(&y, tau0).unwrap();
    let g = &an.terms.goodness;
    assert!(!g.consistent, "chi2/dof {}", g.chi2_per_dof);
    // The bumps: 3.7 s and 123 s; one of them is missed.
    let missed: Vec<f64> = g.outside.iter().map(|&i| an.taus[i]).collect();
    assert!(
        missed.iter().any(|&t| (2.0..6.0).contains(&t))
            || missed.iter().any(|&t| (60.0..250.0).contains(&t)),
        "{missed:?}"
    );
    let t = &an.terms;
    for j in 0..terms::COUNT {
        if t.present[j] {
            let (v, lo, hi) = (
                terms::to_units(j, t.c[j]),
                terms::to_units(j, t.lo[j]),
                terms::to_units(j, t.hi[j]),
            );
            assert!(
                (hi - lo) / v >= 0.01,
                "{}: {v} [{lo}, {hi}]",
                terms::NAMES[j]
            );
        }
    }
    if let Some(s) = &t.sinusoid {
        let a = &s.amplitude_dps;
        assert!((a.hi - a.lo) / a.value >= 0.01, "{a:?}");
    }
}

#[test]
fn bias_instability_uses_the_0_664_factor() {
    // A flicker floor of ADEV 0.0664 deg/h is B = 0.1 deg/h, not 0.0664.
    let an = analyse(
        &record(&[0.0, 0.0, 0.1, 0.0, 0.0], SAMPLES, TAU0_S, 3),
        TAU0_S,
    )
    .unwrap();
    let b = terms::to_units(2, an.terms.c[2]);
    assert!((b - 0.1).abs() < 0.005, "{b}");
    let floor = an.avar[an.avar.len() / 2].sqrt() * 3600.0;
    assert!((floor / b - 0.664).abs() < 0.03, "floor {floor} for B {b}");
}

#[test]
fn bias_on_an_unresolved_floor_is_an_upper_bound_at_most_the_floor_reading() {
    // Flicker alone: the curve never turns up after its floor, so the floor
    // bounds B from above only; B is held to floor/0.664 and said to be a
    // bound, its interval still reaching the truth in most seeds.
    let (mut bounded, mut held) = (0, 0);
    // (On a flat curve the scatter makes about half the seeds "resolved".)
    for seed in 1..=10 {
        let an = analyse(
            &record(&[0.0, 0.0, 0.1, 0.0, 0.0], SAMPLES, TAU0_S, seed),
            TAU0_S,
        )
        .unwrap();
        let t = &an.terms;
        if an.readings.resolved || !t.present[2] {
            continue;
        }
        bounded += 1;
        assert!(t.bias_upper_bound, "seed {seed}");
        let (b, lo, hi) = (
            terms::to_units(2, t.c[2]),
            terms::to_units(2, t.lo[2]),
            terms::to_units(2, t.hi[2]),
        );
        assert!(
            b <= an.readings.bias_instability_dph * (1.0 + 1e-9),
            "seed {seed}: B {b} above floor/0.664 {}",
            an.readings.bias_instability_dph
        );
        assert!(lo <= b && b <= hi, "seed {seed}: {lo} {b} {hi}");
        held += usize::from(lo <= 0.1 && 0.1 <= hi);
    }
    assert!(bounded >= 3, "only {bounded} of 10 seeds unresolved with B");
    assert!(
        held + 1 >= bounded,
        "{held} of {bounded} intervals hold B = 0.1"
    );
}

fn dir(name: &str) -> std::path::PathBuf {
    common::dir(&format!("allan-{name}"))
}

fn write_run(path: &std::path::Path, y: &[f64], tau0: f64) {
    let mut s = String::from("# white + flicker\nt_s,ref_rate_dps,rate_dps\n");
    for (k, v) in y.iter().enumerate() {
        s.push_str(&format!("{},0,{:.12e}\n", (k + 1) as f64 * tau0, v));
    }
    std::fs::write(path, s).unwrap();
}

#[test]
fn json_files_and_a_self_contained_report() {
    let d = dir("report");
    let run = d.join("run.csv");
    write_run(
        &run,
        &record(&[0.0, 0.02, 0.1, 0.0, 0.0], 50_000, 1.0, 2),
        1.0,
    );
    let out = d.join("out");
    let stdout = lab_ok(&[
        "allan",
        "--data",
        run.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--json",
    ]);
    let v: serde_json::Value = serde_json::from_str(stdout.lines().last().unwrap()).unwrap();
    let n = v["taus_s"].as_array().unwrap().len();
    assert!(n >= 30);
    for k in ["adev_dph", "adev_lo_dph", "adev_hi_dph"] {
        assert_eq!(v[k].as_array().unwrap().len(), n, "{k}");
    }
    for (i, t) in v["adev_dph"].as_array().unwrap().iter().enumerate() {
        let (lo, hi) = (
            v["adev_lo_dph"][i].as_f64().unwrap(),
            v["adev_hi_dph"][i].as_f64().unwrap(),
        );
        assert!(lo < t.as_f64().unwrap() && t.as_f64().unwrap() < hi);
    }
    let terms = v["terms"].as_object().unwrap();
    for name in terms::NAMES {
        assert!(terms.contains_key(name), "{name}");
    }
    assert!(terms["quantization"].is_null() && terms["rate_ramp"].is_null());
    let b = &terms["bias_instability_dph"];
    assert!(
        b["lo"].as_f64().unwrap() <= 0.1 && 0.1 <= b["hi"].as_f64().unwrap(),
        "{b}"
    );
    let csv = std::fs::read_to_string(out.join("allan.csv")).unwrap();
    assert_eq!(csv.lines().count(), n + 1);
    let html = std::fs::read_to_string(out.join("report.html")).unwrap();
    // Nothing fetched: no scripts, no links, no URLs but the SVG namespace
    // name (an identifier, never fetched).
    let stripped = html.replace("xmlns=\"http://www.w3.org/2000/svg\"", "");
    for bad in [
        "<script", "<link", "src=", "href=", "url(", "@import", "http:", "https:",
    ] {
        assert!(!stripped.contains(bad), "report holds `{bad}`");
    }
    // The curve and the panel of normalised residuals, with both axes'
    // labels, the data points and the fitted line.
    assert_eq!(html.matches("<svg").count(), 2);
    assert!(html.contains("averaging time tau, s") && html.contains("Allan deviation, deg/h"));
    assert!(html.matches("<circle").count() >= n, "data points");
    assert!(html.contains("<polyline"), "fitted model");
    assert!(html.contains("bias instability") && html.contains("absent"));
    assert!(
        html.contains("In short: angle random walk"),
        "the figures first"
    );
}

#[test]
fn bad_input_is_one_line_and_exit_2() {
    let d = dir("bad");
    let write = |name: &str, text: String| {
        let p = d.join(name);
        std::fs::write(&p, text).unwrap();
        p.display().to_string()
    };
    let rows = |n: usize, f: &dyn Fn(usize) -> String| -> String { (0..n).map(f).collect() };
    let cases = [
        (
            "short.csv",
            "t_s,rate_dps\n0,1\n1,2\n".to_owned(),
            "",
            "too short",
        ),
        (
            // A stretch of a day missing from 1 s rows: not a few lost
            // frames but another record (uneven rows are analysed, on
            // their own times: record/sampling.rs).
            "gap.csv",
            format!(
                "t_s,rate_dps\n{}",
                rows(100, &|k| format!(
                    "{},{}\n",
                    if k >= 50 {
                        k as f64 + 86_400.0
                    } else {
                        k as f64
                    },
                    (k as f64).sin()
                ))
            ),
            ":52:1 (column `t_s`)",
            "not uniform",
        ),
        (
            "constant.csv",
            format!("t_s,rate_dps\n{}", rows(100, &|k| format!("{k},0.25\n"))),
            "",
            "constant",
        ),
        (
            "nan.csv",
            format!(
                "t_s,rate_dps\n0,1\n1,nan\n{}",
                rows(100, &|k| format!("{},1\n", k + 2))
            ),
            ":3:2 (column `rate_dps`)",
            "finite",
        ),
        (
            "column.csv",
            format!("t_s,rate\n{}", rows(100, &|k| format!("{k},1\n"))),
            ":1",
            "missing column `rate_dps`",
        ),
    ];
    for (name, text, pos, what) in cases {
        let p = write(name, text);
        let (code, _, err) = lab(&["allan", "--data", &p]);
        assert_eq!(code, 2, "{name}: {err}");
        assert_eq!(err.trim_end().lines().count(), 1, "{name}: {err}");
        assert!(err.contains(&format!("{p}{pos}")), "{name}: {err}");
        assert!(err.contains(what), "{name}: {err}");
    }
}

#[test]
fn agrees_with_allantools() {
    // A record and allantools' overlapping deviations of it, produced
    // offline (lab/tests/data; allantools from PyPI): ours within 1e-9.
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data");
    let stdout = lab_ok(&[
        "allan",
        "--data",
        dir.join("white_rw.csv").to_str().unwrap(),
        "--json",
    ]);
    let ours: serde_json::Value = serde_json::from_str(stdout.lines().last().unwrap()).unwrap();
    let theirs: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("allantools_oadev.json")).unwrap())
            .unwrap();
    let taus = theirs["taus_s"].as_array().unwrap();
    assert!(taus.len() >= 25);
    for (i, t) in taus.iter().enumerate() {
        let k = ours["taus_s"]
            .as_array()
            .unwrap()
            .iter()
            .position(|x| x.as_f64() == t.as_f64())
            .unwrap_or_else(|| panic!("tau {t} not among ours"));
        let a = ours["adev_dph"][k].as_f64().unwrap() / 3600.0;
        let b = theirs["oadev"][i].as_f64().unwrap();
        assert!((a - b).abs() / b < 1e-9, "tau {t}: {a} vs allantools {b}");
    }
}

/// The series analysed is the output less the reference; a reference that
/// turns is `not_static`, and a plain static record has no warning. (The
/// `too_short` rule is unit-tested in noise/record_checks.rs.)
#[test]
fn rate_less_reference_and_the_record_warnings() {
    let d = common::dir("allan-warn");
    // White noise of 1e-3 deg/s at 100 Hz from a small LCG (Box-Muller).
    let mut x = 12345u64;
    let mut u = move || {
        x = x
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((x >> 11) as f64 + 0.5) / (1u64 << 53) as f64
    };
    let noise: Vec<f64> = (0..2000)
        .map(|_| 1e-3 * (-2.0 * u().ln()).sqrt() * (std::f64::consts::TAU * u()).cos())
        .collect();
    let write = |name: &str, rows: &mut dyn Iterator<Item = String>| {
        let p = d.join(name);
        let body: String = rows.collect();
        std::fs::write(&p, format!("t_s,ref_rate_dps,rate_dps\n{body}")).unwrap();
        p.display().to_string()
    };
    let warnings = |p: &str| -> (Vec<String>, serde_json::Value) {
        let v = common::json(&lab_ok(&["allan", "--data", p, "--json"]));
        let codes = v["warnings"]
            .as_array()
            .unwrap()
            .iter()
            .map(|w| w["code"].as_str().unwrap().to_owned())
            .collect();
        (codes, v)
    };
    // A rate table stepping 0 -> 50 deg/s with a 10 ppm scale-factor
    // error: the analysis sees the gyro's error, and the warning.
    let table = write(
        "table.csv",
        &mut noise.iter().enumerate().map(|(k, n)| {
            let w = if k < 1000 { 0.0 } else { 50.0 };
            format!("{},{w},{}\n", k as f64 * 0.01, w * (1.0 + 1e-5) + n)
        }),
    );
    let (codes, v) = warnings(&table);
    assert_eq!(codes, vec!["not_static"], "{v}");
    assert_eq!(v["analysed"], "rate_dps - ref_rate_dps");
    assert!(v["mean_dps"].as_f64().unwrap().abs() < 1e-3, "{v}");
    // At rest: the same noise, no warning.
    let rest = write(
        "rest.csv",
        &mut noise
            .iter()
            .enumerate()
            .map(|(k, n)| format!("{},0.004178,{}\n", k as f64 * 0.01, 0.004178 + n)),
    );
    assert_eq!(warnings(&rest).0, Vec::<String>::new());
}
