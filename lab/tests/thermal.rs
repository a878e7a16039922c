//! RLG thermal calibration end to end (docs/rlg.md): simulate two chamber
//! runs with different profiles and orientations, fit on one, compensate the
//! other with the firmware's fixed-point code through `gyro-lab`.

mod common;

fn lab_json(args: &[&str]) -> serde_json::Value {
    let args: Vec<&str> = args.iter().copied().chain(["--json"]).collect();
    common::json(&common::lab_ok(&args))
}

fn dir() -> std::path::PathBuf {
    let d = std::env::temp_dir().join(format!("gyro-lab-thermal-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// Acceptance: fitted on a -40..+50 degC cycle with the axis up, validated on
/// a step profile with the axis horizontal towards east (another Earth-rate
/// component, another noise seed): the residual drift (std of 100 s means)
/// is within 1.5x the validation run's noise floor, far below the raw drift
/// and the classic one-sensor cubic.
#[test]
fn fit_on_one_run_validate_on_another() {
    let d = dir();
    let p = |n: &str| d.join(n).display().to_string();
    lab_json(&[
        "simulate",
        "chamber",
        "--profile",
        "cycle",
        "--out",
        &p("fit.csv"),
    ]);
    lab_json(&[
        "simulate",
        "chamber",
        "--profile",
        "steps",
        "--azimuth-deg",
        "90",
        "--elevation-deg",
        "0",
        "--seed",
        "7",
        "--out",
        &p("val.csv"),
    ]);
    let fit = lab_json(&[
        "fit",
        "thermal",
        "--data",
        &p("fit.csv"),
        "--out",
        &p("c.toml"),
    ]);
    let truth = gyro_sim::ChamberParams::default().truth;
    // The well-determined terms come back close to the simulator's truth.
    let c = &fit["coefficients"];
    let near = |k: &str, v: f64, tol: f64| {
        let got = c[k].as_f64().unwrap();
        assert!((got - v).abs() <= tol * v.abs(), "{k}: {got} vs {v}");
    };
    near("k1_dph_per_c", truth.k1_dph_per_c, 0.1);
    near("k3_dph_per_c2", truth.k3_dph_per_c2, 0.1);
    near("k4_dph_per_c", truth.k4_dph_per_c, 0.1);
    near("tau_warm_s", truth.tau_warm_s, 0.25);
    let v = lab_json(&[
        "compensate",
        "--coeffs",
        &p("c.toml"),
        "--data",
        &p("val.csv"),
        "--out",
        &p("val_comp.csv"),
        "--cubic-from",
        &p("fit.csv"),
    ]);
    let f = |k: &str| v[k].as_f64().unwrap();
    let (raw, comp, floor, cubic) = (
        f("raw_std_100s_dph"),
        f("comp_std_100s_dph"),
        f("noise_floor_100s_dph"),
        f("cubic_std_100s_dph"),
    );
    eprintln!("raw {raw:.4} cubic {cubic:.4} comp {comp:.4} floor {floor:.4} deg/h");
    assert!(comp <= 1.5 * floor, "{v}");
    assert!(raw > 5.0 * floor && cubic > 3.0 * comp, "{v}");
    assert!(!v["coeffs_refused"].as_bool().unwrap());
    // The written run holds the new column next to the old ones.
    let text = std::fs::read_to_string(p("val_comp.csv")).unwrap();
    assert!(text
        .lines()
        .find(|l| !l.starts_with('#'))
        .unwrap()
        .ends_with("bias_true_dph,rate_comp_dps"));
}

/// A broken coefficient file: one line naming file, line and column; exit 2.
#[test]
fn bad_coefficient_file() {
    let d = dir();
    let bad = d.join("bad.toml");
    std::fs::write(
        &bad,
        "kind = \"rlg_thermal\"\nversion = 1\n[rlg_thermal]\nbias0_dph = 0.1\nk1_dph_per_c = oops\n",
    )
    .unwrap();
    let run = d.join("run.csv");
    let rows: String = (0..300).map(|k| format!("{k},0,0,20,20,20\n")).collect();
    std::fs::write(
        &run,
        format!("t_s,ref_rate_dps,rate_dps,t_mono_a_c,t_mono_b_c,t_case_c\n{rows}"),
    )
    .unwrap();
    let p = |x: &std::path::Path| x.display().to_string();
    let (code, _, err) = common::lab(&[
        "compensate",
        "--coeffs",
        &p(&bad),
        "--data",
        &p(&run),
        "--out",
        &p(&d.join("o.csv")),
    ]);
    assert_eq!(code, 2, "{err}");
    assert!(err.contains(&format!("{}:5:16", bad.display())), "{err}");
    assert_eq!(err.trim_end().lines().count(), 1, "{err}");
}

/// A record too short to fit (the QEMU run's 2.4 s) is refused in one line
/// that says what is wrong and what to do: no coefficient dump.
#[test]
fn too_short_to_fit_says_what_to_do() {
    let d = dir();
    let run = d.join("short.csv");
    let rows: String = (0..1200)
        .map(|k| {
            format!(
                "{},0,{},20,20.01,20\n",
                k as f64 * 0.002,
                1e-4 * (k % 7) as f64
            )
        })
        .collect();
    std::fs::write(
        &run,
        format!("t_s,ref_rate_dps,rate_dps,t_mono_a_c,t_mono_b_c,t_case_c\n{rows}"),
    )
    .unwrap();
    let (code, _, err) = common::lab(&[
        "fit",
        "thermal",
        "--data",
        &run.display().to_string(),
        "--out",
        &d.join("short.toml").display().to_string(),
    ]);
    assert_eq!(code, 2, "{err}");
    assert_eq!(err.trim_end().lines().count(), 1, "{err}");
    assert!(err.contains("too short to fit: 2.4 s"), "{err}");
    assert!(err.contains("simulate chamber --profile cycle"), "{err}");
    assert!(!err.contains('{'), "{err}");
}

mod report_check;

/// `fit thermal` and `compensate` write their reports beside their output,
/// named after it (both kept in one folder):
/// self-contained, every plot with axes, units and data, the verdict's
/// numbers the JSON's. A soak at one temperature leaves the temperature
/// terms unresolved: the report says so.
#[test]
fn reports_and_their_warnings() {
    let d = common::dir("thermal-report");
    let p = |n: &str| d.join(n).display().to_string();
    lab_json(&[
        "simulate",
        "chamber",
        "--profile",
        "cycle",
        "--out",
        &p("fit.csv"),
    ]);
    std::fs::create_dir_all(d.join("f")).unwrap();
    let v = lab_json(&[
        "fit",
        "thermal",
        "--data",
        &p("fit.csv"),
        "--out",
        &p("f/c.toml"),
    ]);
    let html = std::fs::read_to_string(d.join("f").join("c.html")).unwrap();
    report_check::check(&html, &v, 4, 12);
    assert!(html.contains("Allan deviation of the residual against the noise floor"));
    // Compensating the fit run itself.
    let v = lab_json(&[
        "compensate",
        "--coeffs",
        &p("f/c.toml"),
        "--data",
        &p("fit.csv"),
        "--out",
        &p("comp.csv"),
    ]);
    let html = std::fs::read_to_string(d.join("comp.html")).unwrap();
    report_check::check(&html, &v, 2, 6);
    // A soak: dT, T_K and their rates hardly move.
    lab_json(&[
        "simulate",
        "chamber",
        "--profile",
        "soak",
        "--soak-c",
        "20",
        "--duration-s",
        "20000",
        "--out",
        &p("soak.csv"),
    ]);
    std::fs::create_dir_all(d.join("s")).unwrap();
    let v = lab_json(&[
        "fit",
        "thermal",
        "--data",
        &p("soak.csv"),
        "--out",
        &p("s/c.toml"),
    ]);
    let html = std::fs::read_to_string(d.join("s").join("c.html")).unwrap();
    let kinds = report_check::assert_warnings_match(&html, &v);
    assert!(
        kinds.iter().filter(|k| *k == "term_not_resolved").count() >= 3,
        "{kinds:?}"
    );
    report_check::check(&html, &v, 4, 12);
    // The soak's coefficients on the cycle: the run leaves the one
    // temperature the fit saw, and the compensation report says where.
    std::fs::create_dir_all(d.join("sc")).unwrap();
    let soak_on_cycle = |out: &str| {
        lab_json(&[
            "compensate",
            "--coeffs",
            &p("s/c.toml"),
            "--data",
            &p("fit.csv"),
            "--out",
            &p(out),
        ])
    };
    let v = soak_on_cycle("sc/comp.csv");
    let html = std::fs::read_to_string(d.join("sc").join("comp.html")).unwrap();
    // The fit's report in the same folder as another command's survives.
    soak_on_cycle("s/comp.csv");
    assert!(d.join("s").join("c.html").exists() && d.join("s").join("comp.html").exists());
    report_check::check(&html, &v, 2, 8);
    let kinds = report_check::assert_warnings_match(&html, &v);
    assert!(
        kinds.iter().any(|k| k == "outside_calibrated_range"),
        "{kinds:?}"
    );
    let spans = v["out_of_range_spans"].as_array().unwrap();
    let [lo, hi] = [0, 1].map(|i| v["calibrated_range"]["mono_a_c"][i].as_f64().unwrap());
    assert!(!spans.is_empty(), "{v}");
    for s in spans {
        let (a, b) = (s["min_c"].as_f64().unwrap(), s["max_c"].as_f64().unwrap());
        assert!(a < lo || b > hi, "{s} inside {lo} .. {hi}");
    }
    assert!(
        html.contains("outside the fit&#39;s temperatures")
            || html.contains("outside the fit's temperatures")
    );
}
