//! A user's own data (issue 38): the units, names, separators and
//! timestamps of the files people have, the outputs that must never
//! replace an input, and the models whose residual a user can trust. Each
//! case is made from a run the simulators wrote, changed as a user's file
//! differs, and compared with the clean run's answer.

mod common;

use common::{dir, json, lab, lab_ok};
use std::path::{Path, PathBuf};

/// A CSV file as (comment lines, header, rows of cells).
struct Csv {
    comments: Vec<String>,
    header: Vec<String>,
    rows: Vec<Vec<String>>,
}

impl Csv {
    fn read(p: &Path) -> Self {
        let text = std::fs::read_to_string(p).unwrap();
        let mut lines = text.lines();
        let mut comments = vec![];
        let header = loop {
            let l = lines.next().unwrap();
            if l.starts_with('#') {
                comments.push(l.to_owned());
            } else {
                break l.split(',').map(str::to_owned).collect::<Vec<_>>();
            }
        };
        let rows = lines
            .filter(|l| !l.is_empty())
            .map(|l| l.split(',').map(str::to_owned).collect())
            .collect();
        Self {
            comments,
            header,
            rows,
        }
    }

    fn col(&self, name: &str) -> usize {
        self.header.iter().position(|h| h == name).unwrap()
    }

    /// Every cell of `name` through `f`.
    fn map(&mut self, name: &str, mut f: impl FnMut(f64) -> f64) {
        let c = self.col(name);
        for r in &mut self.rows {
            r[c] = format!("{:.12e}", f(r[c].parse::<f64>().unwrap()));
        }
    }

    fn rename(&mut self, from: &str, to: &str) {
        let c = self.col(from);
        self.header[c] = to.to_owned();
    }

    /// Written with `sep` between cells (and a decimal comma where `sep`
    /// is not a comma), a byte-order mark first where asked.
    fn write(&self, p: &Path, sep: &str, bom: bool) -> String {
        let mut s = String::new();
        if bom {
            s.push('\u{feff}');
        }
        for c in &self.comments {
            s.push_str(c);
            s.push('\n');
        }
        s.push_str(&self.header.join(sep));
        s.push('\n');
        for r in &self.rows {
            let cells: Vec<String> = r
                .iter()
                .map(|c| {
                    if sep == "," {
                        c.clone()
                    } else {
                        c.replace('.', ",")
                    }
                })
                .collect();
            s.push_str(&cells.join(sep));
            s.push('\n');
        }
        std::fs::write(p, s).unwrap();
        p.display().to_string()
    }
}

fn f(v: &serde_json::Value, path: &[&str]) -> f64 {
    let mut x = v;
    for k in path {
        x = &x[*k];
    }
    x.as_f64().unwrap_or_else(|| panic!("{path:?} in {v}"))
}

fn codes(v: &serde_json::Value) -> Vec<String> {
    v["warnings"]
        .as_array()
        .map(|a| {
            a.iter()
                .map(|w| w["code"].as_str().unwrap_or("").to_owned())
                .collect()
        })
        .unwrap_or_default()
}

/// An RLG at rest (a soak at 20 degC, 6000 s): the Earth-rate reference.
fn soak(d: &Path) -> PathBuf {
    let p = d.join("soak.csv");
    if !p.exists() {
        lab_ok(&[
            "simulate",
            "chamber",
            "--profile",
            "soak",
            "--soak-c",
            "20",
            "--duration-s",
            "6000",
            "--out",
            p.to_str().unwrap(),
        ]);
    }
    p
}

#[test]
fn a_rate_in_another_unit_is_refused_with_its_factor_and_read_when_given() {
    let d = dir("units");
    let clean = soak(&d);
    let base = json(&lab_ok(&[
        "allan",
        "--data",
        clean.to_str().unwrap(),
        "--json",
    ]));
    let n0 = f(&base, &["terms", "angle_random_walk_dpsh", "value"]);
    for (unit, k) in [("rad/s", std::f64::consts::PI / 180.0), ("deg/h", 3600.0)] {
        let mut c = Csv::read(&clean);
        c.map("rate_dps", |v| v * k);
        let p = c.write(
            &d.join(format!("rate-{}.csv", unit.replace('/', "-"))),
            ",",
            false,
        );
        let (code, _, err) = lab(&["allan", "--data", &p, "--json"]);
        assert_eq!(code, 2, "{unit}: {err}");
        assert_eq!(err.trim_end().lines().count(), 1, "{err}");
        // At the rate column's header cell (line 2: one comment line first).
        assert!(
            err.contains("--rate-unit") && err.contains(&format!("{p}:2:3")),
            "{err}"
        );
        // Given, with the reference's own unit: the clean run's answer.
        let v = json(&lab_ok(&[
            "allan",
            "--data",
            &p,
            "--rate-unit",
            unit,
            "--ref-rate-unit",
            "deg/s",
            "--json",
        ]));
        let n = f(&v, &["terms", "angle_random_walk_dpsh", "value"]);
        assert!((n / n0 - 1.0).abs() < 1e-6, "{unit}: {n} against {n0}");
    }
}

#[test]
fn kelvin_is_refused_at_its_cell_and_read_with_the_unit() {
    let d = dir("kelvin");
    let cyc = d.join("cycle.csv");
    lab_ok(&[
        "simulate",
        "chamber",
        "--profile",
        "cycle",
        "--out",
        cyc.to_str().unwrap(),
    ]);
    let mut c = Csv::read(&cyc);
    for n in ["t_mono_a_c", "t_mono_b_c", "t_case_c", "t_air_c"] {
        c.map(n, |v| v + 273.15);
    }
    let k = c.write(&d.join("cycle-k.csv"), ",", false);
    let out = d.join("k.toml");
    let (code, _, err) = lab(&[
        "fit",
        "thermal",
        "--data",
        &k,
        "--out",
        out.to_str().unwrap(),
    ]);
    assert_eq!(code, 2, "{err}");
    assert!(
        err.contains("--temp-unit K") && err.contains("kelvin"),
        "{err}"
    );
    assert!(!out.exists(), "nothing written");
    let a = json(&lab_ok(&[
        "fit",
        "thermal",
        "--data",
        &k,
        "--temp-unit",
        "K",
        "--out",
        out.to_str().unwrap(),
        "--json",
    ]));
    let b = json(&lab_ok(&[
        "fit",
        "thermal",
        "--data",
        cyc.to_str().unwrap(),
        "--out",
        d.join("c.toml").to_str().unwrap(),
        "--json",
    ]));
    // The same fit, to rounding (the cells are read back through kelvin).
    for (k, x) in a["coefficients"].as_object().unwrap() {
        let (x, y) = (x.as_f64().unwrap(), b["coefficients"][k].as_f64().unwrap());
        assert!(
            (x - y).abs() <= 1e-9 * y.abs().max(1e-6),
            "{k}: {x} against {y}"
        );
    }
    // The coefficient file carries the range it was fitted over.
    let text = std::fs::read_to_string(&out).unwrap();
    assert!(
        text.contains("[range]") && text.contains("temp_c"),
        "{text}"
    );
}

#[test]
fn the_files_people_have_read_as_the_clean_one() {
    let d = dir("formats");
    let clean = soak(&d);
    let run = |p: &str, extra: &[&str]| {
        let mut a = vec![
            "discover", "--gyro", "rlg", "--data", p, "--json", "--force",
        ];
        let out = d.join(format!("disc-{}", p.len() + extra.len()));
        let o = out.display().to_string();
        a.extend(["--out", &o]);
        a.extend(extra);
        json(&lab_ok(&a))
    };
    let base = run(clean.to_str().unwrap(), &[]);
    let c = Csv::read(&clean);
    let semi = c.write(&d.join("semi.csv"), ";", true);
    let tab = c.write(&d.join("tab.csv"), "\t", false);
    for p in [&semi, &tab] {
        let v = run(p, &[]);
        assert_eq!(v["found"], base["found"], "{p}");
        assert_eq!(v["gap_after_dph"], base["gap_after_dph"], "{p}");
    }
    // Their own names: every missing column said at once, with a mapping.
    let mut r = Csv::read(&clean);
    r.rename("t_s", "time");
    r.rename("rate_dps", "gyro_z");
    let named = r.write(&d.join("named.csv"), ",", false);
    let (code, _, err) = lab(&["allan", "--data", &named]);
    assert_eq!(code, 2);
    assert!(
        err.contains("missing columns `t_s`, `rate_dps`")
            && err.contains("--columns t_s=time,rate_dps=gyro_z"),
        "{err}"
    );
    let v = run(&named, &["--columns", "t_s=time,rate_dps=gyro_z"]);
    assert_eq!(v["found"], base["found"]);
    // A static record without a reference: taken as one at rest, and said.
    let mut s = Csv::read(&clean);
    s.rename("ref_rate_dps", "unused");
    let no_ref = s.write(&d.join("no-ref.csv"), ",", false);
    let v = run(&no_ref, &[]);
    assert!(codes(&v).contains(&"no_reference".to_owned()), "{v}");
}

/// A user's --out never replaces what they gave, nor a file unasked.
#[test]
fn no_output_over_an_input() {
    let d = dir("out");
    let clean = soak(&d);
    let data = clean.to_str().unwrap();
    let before = std::fs::read(&clean).unwrap();
    let tries: Vec<Vec<&str>> = vec![
        vec!["fit", "thermal", "--data", data, "--out", data],
        vec![
            "compensate",
            "--coeffs",
            "../config/rlg_thermal.toml",
            "--data",
            data,
            "--out",
            data,
        ],
        vec!["allan", "--data", data, "--out", data],
        vec!["discover", "--gyro", "rlg", "--data", data, "--out", data],
    ];
    for t in &tries {
        let (code, _, err) = lab(t);
        assert_eq!(code, 2, "{t:?}: {err}");
        assert_eq!(err.trim_end().lines().count(), 1, "{err}");
    }
    assert_eq!(std::fs::read(&clean).unwrap(), before, "the input is whole");
    // An existing output needs --force; a file of another kind, never.
    let out = d.join("coeffs.toml");
    std::fs::write(&out, "t_s,rate_dps\n0,0\n").unwrap();
    let o = out.to_str().unwrap();
    let (code, _, err) = lab(&["fit", "thermal", "--data", data, "--out", o, "--force"]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains("not replaced"), "{err}");
    // A folder command given a file's name makes no folder of it.
    let named = d.join("mymodel.toml");
    let (code, _, err) = lab(&[
        "discover",
        "--gyro",
        "rlg",
        "--data",
        data,
        "--out",
        named.to_str().unwrap(),
    ]);
    assert_eq!(code, 2, "{err}");
    assert!(!named.exists());
}

/// PC-stamped rows (+-1 % of the step): the same names and terms.
#[test]
fn jittered_timestamps_change_no_named_effect_and_no_allan_term() {
    let d = dir("jitter");
    let truth = d.join("truth.toml");
    std::fs::write(
        &truth,
        "kind = \"gyro_model\"\nversion = 1\ngyro = \"fog\"\n[[effect]]\nname = \"bias_temperature\"\ndph_per_c = 0.01\n[[effect]]\nname = \"shupe\"\ndph_per_c_per_s = 30.0\n",
    )
    .unwrap();
    let run = d.join("run.csv");
    lab_ok(&[
        "simulate",
        "run",
        "--model",
        truth.to_str().unwrap(),
        "--profile",
        "fog-chamber",
        "--out",
        run.to_str().unwrap(),
    ]);
    let mut c = Csv::read(&run);
    let mut s = 12345u64;
    c.map("t_s", |t| {
        s = s
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        t + 0.02 * ((s >> 11) as f64 / (1u64 << 53) as f64 - 0.5)
    });
    let jit = c.write(&d.join("jittered.csv"), ",", false);
    let disc = |p: &str, o: &str| {
        json(&lab_ok(&[
            "discover",
            "--gyro",
            "fog",
            "--data",
            p,
            "--out",
            d.join(o).to_str().unwrap(),
            "--json",
            "--force",
        ]))
    };
    let a = disc(run.to_str().unwrap(), "a");
    let b = disc(&jit, "b");
    let names = |v: &serde_json::Value| -> Vec<String> {
        v["found"]
            .as_array()
            .unwrap()
            .iter()
            .map(|e| e["effect"].as_str().unwrap().to_owned())
            .collect()
    };
    assert_eq!(names(&a), names(&b));
    assert_eq!(b["sampling"]["kind"], "jittered", "{}", b["sampling"]);
    assert!(b["unexplained"].is_null(), "{}", b["unexplained"]);
    for (ea, eb) in a["found"]
        .as_array()
        .unwrap()
        .iter()
        .zip(b["found"].as_array().unwrap())
    {
        for (k, iv) in ea["parameter_intervals"].as_object().unwrap() {
            let v = eb["parameters"][k].as_f64().unwrap();
            let (lo, hi) = (iv[0].as_f64().unwrap(), iv[1].as_f64().unwrap());
            assert!(lo <= v && v <= hi, "{k}: {v} outside [{lo}, {hi}]");
        }
    }
    let al = |p: &str| json(&lab_ok(&["allan", "--data", p, "--json"]));
    let (x, y) = (al(run.to_str().unwrap()), al(&jit));
    let (n, lo, hi) = (
        f(&y, &["terms", "angle_random_walk_dpsh", "value"]),
        f(&x, &["terms", "angle_random_walk_dpsh", "lo"]),
        f(&x, &["terms", "angle_random_walk_dpsh", "hi"]),
    );
    assert!(lo <= n && n <= hi, "ARW {n} outside [{lo}, {hi}]");
}

/// The README's Allan example: a soak that warms up reports no rate
/// random walk, and says why it left the warm-up out.
#[test]
fn a_warm_up_is_said_and_left_out_of_the_noise() {
    let d = dir("warm");
    let p = d.join("rest.csv");
    lab_ok(&[
        "simulate",
        "chamber",
        "--profile",
        "soak",
        "--soak-c",
        "20",
        "--duration-s",
        "20000",
        "--out",
        p.to_str().unwrap(),
    ]);
    let v = json(&lab_ok(&["allan", "--data", p.to_str().unwrap(), "--json"]));
    let c = codes(&v);
    assert!(
        c.contains(&"non_stationary".into()) && c.contains(&"warm_up".into()),
        "{c:?}"
    );
    assert!(v["terms"]["rate_random_walk"].is_null(), "{}", v["terms"]);
    // Asked for the whole record, it is analysed whole and warned about.
    let w = json(&lab_ok(&[
        "allan",
        "--data",
        p.to_str().unwrap(),
        "--from-s",
        "0",
        "--json",
    ]));
    assert!(codes(&w).contains(&"non_stationary".into()));
    assert_eq!(w["analysed_from_s"].as_f64(), Some(1.0));
}

/// The measured hub (shared/data/measured): the model's residual averages to zero
/// within its interval, what is left is named, and the wrong gyro kind
/// does not do better.
#[test]
fn a_measured_record_leaves_a_residual_that_averages_to_zero() {
    // The workplace's measured records (shared/data/measured, beside the
    // repository; GYRO_MEASURED_DIR elsewhere). Their source has no licence,
    // so they are not committed: without them the test says it is skipped.
    let dir_m = std::env::var_os("GYRO_MEASURED_DIR").map_or_else(
        || Path::new(env!("CARGO_MANIFEST_DIR")).join("../../shared/data/measured"),
        PathBuf::from,
    );
    let hub = dir_m.join("spike_hub_RB_gyroZ.csv");
    if !hub.exists() {
        eprintln!("skipped: no measured hub record at {}", hub.display());
        return;
    }
    let d = dir("hub");
    let disc = |g: &str| {
        json(&lab_ok(&[
            "discover",
            "--gyro",
            g,
            "--data",
            hub.to_str().unwrap(),
            "--out",
            d.join(g).to_str().unwrap(),
            "--json",
            "--force",
        ]))
    };
    let m = disc("mems");
    let (lo, hi) = (
        f(&m, &["residual_mean", "lo_dph"]),
        f(&m, &["residual_mean", "hi_dph"]),
    );
    assert!(lo <= 0.0 && 0.0 <= hi, "{}", m["residual_mean"]);
    let named = m["found"]
        .as_array()
        .unwrap()
        .iter()
        .any(|e| e["effect"] == "term");
    assert!(
        named || !m["unexplained"].is_null(),
        "what is left is named: {m}"
    );
    // An RLG's library reads no temperature slope on `temp_c`; started
    // without a warm-up (restart.rs) its proposals find the slope as a
    // term, and it does as well as the MEMS library up to how the fits
    // weigh the record (least squares against the noise's generalised
    // ones): no better than that.
    let r = disc("rlg");
    assert!(
        f(&m, &["gap_after_dph"]) <= 1.05 * f(&r, &["gap_after_dph"]),
        "mems {} rlg {}",
        m["gap_after_dph"],
        r["gap_after_dph"]
    );
}

/// A model from discover applied by compensate: the residual it leaves.
#[test]
fn compensate_applies_what_discover_found() {
    let d = dir("comp-model");
    let cyc = d.join("cycle.csv");
    lab_ok(&[
        "simulate",
        "chamber",
        "--profile",
        "cycle",
        "--out",
        cyc.to_str().unwrap(),
    ]);
    let disc = d.join("disc");
    lab_ok(&[
        "discover",
        "--gyro",
        "rlg",
        "--data",
        cyc.to_str().unwrap(),
        "--out",
        disc.to_str().unwrap(),
    ]);
    let out = d.join("comp.csv");
    let v = json(&lab_ok(&[
        "compensate",
        "--coeffs",
        disc.join("model.toml").to_str().unwrap(),
        "--data",
        cyc.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
        "--json",
    ]));
    assert!(
        f(&v, &["rms_after_dph"]) < 0.5 * f(&v, &["rms_before_dph"]),
        "{v}"
    );
    assert!(
        f(&v, &["mean_after_dph"]).abs() < 3.0 * f(&v, &["mean_after_se_dph"]) + 1e-9,
        "{v}"
    );
    // An unknown kind names the kinds it takes.
    let bad = d.join("bad.toml");
    std::fs::write(&bad, "kind = \"other\"\nversion = 1\n").unwrap();
    let (code, _, err) = lab(&[
        "compensate",
        "--coeffs",
        bad.to_str().unwrap(),
        "--data",
        cyc.to_str().unwrap(),
        "--out",
        d.join("x.csv").to_str().unwrap(),
    ]);
    assert_eq!(code, 2);
    assert!(
        err.contains("gyro_model") && err.contains("rlg_thermal"),
        "{err}"
    );
}

/// A bowed residual under a slow noise the noise model could take it as:
/// a curvature in the coil temperature, (temp_c - 20)^2, beneath a rate
/// random walk. The bow is found and the residual left averages to zero.
#[test]
fn a_bow_the_temperature_explains_is_not_taken_for_noise() {
    let d = dir("bow");
    let truth = d.join("bow.toml");
    std::fs::write(
        &truth,
        "kind = \"gyro_model\"\nversion = 1\ngyro = \"fog\"\n[[effect]]\nname = \"term\"\nformula = \"k_dph * (temp_c - 20)^2\"\nk_dph = 1e-3\n",
    )
    .unwrap();
    let run = d.join("bow.csv");
    lab_ok(&[
        "simulate",
        "run",
        "--model",
        truth.to_str().unwrap(),
        "--profile",
        "fog-chamber",
        "--duration-s",
        "7200",
        "--rate-random-walk-dphsh",
        "0.05",
        "--seed",
        "3",
        "--out",
        run.to_str().unwrap(),
    ]);
    let v = json(&lab_ok(&[
        "discover",
        "--gyro",
        "fog",
        "--data",
        run.to_str().unwrap(),
        "--out",
        d.join("disc").to_str().unwrap(),
        "--json",
    ]));
    let term = v["found"]
        .as_array()
        .unwrap()
        .iter()
        .find(|e| e["effect"] == "term")
        .unwrap_or_else(|| panic!("the bow is named: {v}"));
    let iv = &term["parameter_intervals"]["k_dph"];
    assert!(
        iv[0].as_f64().unwrap() <= 1e-3 && 1e-3 <= iv[1].as_f64().unwrap(),
        "{term}"
    );
    let (lo, hi) = (
        f(&v, &["residual_mean", "lo_dph"]),
        f(&v, &["residual_mean", "hi_dph"]),
    );
    assert!(lo <= 0.0 && 0.0 <= hi);
}
