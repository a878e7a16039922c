//! `gyro-lab allan`: recovery of known noise terms from the project's
//! generators, the JSON and files it promises, a report that fetches
//! nothing and shows its data, and bad input (one line, exit 2).
//! The 100-seed figures are `cargo lab bench allan`'s; this runs a few.

#![allow(clippy::needless_range_loop)] // per-term parallel arrays

mod common;
use common::lab;

use gyro_lab::bench::allan::{SAMPLES, SCENARIOS, TAU0_S};
use gyro_lab::noise::analysis::analyse;
use gyro_lab::noise::terms;
use gyro_lab::sim::noise_run::record;

#[test]
fn known_terms_recovered_and_absent_ones_not_reported() {
    // Every scenario, 6 seeds: each present term's interval holds the truth
    // in at least 5 (the bench: at least 91 of 100), no absent term
    // reported more than once (the bench: 2 of 2800).
    for sc in SCENARIOS {
        let mut held = [0; terms::COUNT];
        let mut false_reports = 0;
        for seed in 1..=6 {
            let an = analyse(&record(&sc.truth, SAMPLES, TAU0_S, seed), TAU0_S).unwrap();
            let t = &an.terms;
            for j in 0..terms::COUNT {
                if sc.truth[j] > 0.0 {
                    let (lo, hi) = (terms::to_units(j, t.lo[j]), terms::to_units(j, t.hi[j]));
                    if t.present[j] && lo <= sc.truth[j] && sc.truth[j] <= hi {
                        held[j] += 1;
                    }
                } else if t.present[j] {
                    false_reports += 1;
                }
            }
        }
        for j in 0..terms::COUNT {
            if sc.truth[j] > 0.0 {
                assert!(
                    held[j] >= 5,
                    "{}: {} held in {}/6",
                    sc.name,
                    terms::NAMES[j],
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
    let (code, stdout, err) = lab(&[
        "allan",
        "--data",
        run.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--json",
    ]);
    assert_eq!(code, 0, "{err}");
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
    // One plot, with both axes' labels, its data points and the fitted line.
    assert_eq!(html.matches("<svg").count(), 1);
    assert!(html.contains("averaging time tau, s") && html.contains("Allan deviation, deg/h"));
    assert!(html.matches("<circle").count() >= n, "data points");
    assert!(html.contains("<polyline"), "fitted model");
    assert!(html.contains("bias_instability_dph") && html.contains("absent"));
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
            "uneven.csv",
            format!(
                "t_s,rate_dps\n{}",
                rows(100, &|k| format!(
                    "{},{}\n",
                    if k == 50 { 50.5 } else { k as f64 },
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
    let (code, stdout, err) = lab(&[
        "allan",
        "--data",
        dir.join("white_rw.csv").to_str().unwrap(),
        "--json",
    ]);
    assert_eq!(code, 0, "{err}");
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
