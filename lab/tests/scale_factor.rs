//! FOG scale factor over temperature: the fits against the simulated gyro's
//! truth, the compensation through the firmware's fixed-point code, and the
//! command line's contract (bad input: one line, exit 2).

mod common;
mod report_check;
use common::{json, lab, lab_ok};

use gyro_coeffs::fog_scale_factor::MAX_NODES;
use gyro_lab_core::bench::scale_factor::{continuous_fit_test, multipoint_test, validation_test};
use gyro_lab_core::calibration::scale_factor::compensation::compensate_rows;
use gyro_lab_core::calibration::scale_factor::families::Family;
use gyro_lab_core::calibration::scale_factor::fit::fit;
use gyro_lab_core::calibration::scale_factor::input::{prepare, SfInput};
use gyro_lab_core::calibration::scale_factor::residual::window_rms_ppm;
use gyro_lab_core::calibration::scale_factor::result::SfFit;
use gyro_lab_core::sim::scale_factor_rig::{
    simulate, Direction, RigParams, Run, SweepProfile, Test,
};
use gyro_sim::ScaleFactorTruth;

fn input(run: &Run) -> SfInput {
    prepare(&run.t_s, &run.ref_rate_dps, &run.rate_dps, &run.temp_c)
}

fn rms_ppm(run: &Run, rate: &[f64]) -> f64 {
    let err: Vec<f64> = rate
        .iter()
        .zip(&run.ref_rate_dps)
        .map(|(y, w)| y - w)
        .collect();
    window_rms_ppm(&run.t_s, &run.ref_rate_dps, &err, 60.0).0
}

#[test]
fn continuous_rotation_finds_the_knee_and_compensates_another_run() {
    let rig = RigParams::default();
    let f = fit(&input(&simulate(&continuous_fit_test(), &rig)))
        .unwrap()
        .0;
    assert_eq!(f.method.to_string(), "continuous");
    // Knees on straight lines: no curvature chosen.
    assert_eq!((f.model, f.degree), (Family::Knees, 0), "{:?}", f.families);
    assert!(f.polynomial.is_none());
    assert_eq!(f.knees.len(), 1, "{:?}", f.knees);
    let k = f.knees[0];
    let truth = rig.truth.knees[0].0;
    assert!((k.value - truth).abs() < 0.5, "{k:?}");
    assert!(k.lo <= truth && truth <= k.hi, "{k:?}");
    // The segments' slopes are the truth's (1.5 and 7.5 ppm/degC) within
    // a few standard errors.
    let s = &f.segments;
    assert!(
        (s[0].k_t_ppm_per_c - 1.5).abs() < 5.0 * s[0].k_t_se * 1e6 + 0.01,
        "{s:?}"
    );
    assert!(
        (s[1].k_t_ppm_per_c - 7.5).abs() < 5.0 * s[1].k_t_se * 1e6 + 0.05,
        "{s:?}"
    );
    let lag = f.sensor_lag_s.unwrap();
    assert!((lag.value - rig.tau_sensor_s).abs() < 2.0, "{lag:?}");
    // Another run (steps, -100 deg/s only, another seed): under 1 ppm RMS
    // of 60 s means through the firmware's fixed-point compensation.
    let val = simulate(&validation_test(), &RigParams { seed: 77, ..rig });
    let (comp, flags) = compensate_rows(&f.table, &val.t_s, &val.rate_dps, &val.temp_c);
    let before = rms_ppm(&val, &val.rate_dps);
    let after = rms_ppm(&val, &comp);
    assert!(before > 100.0, "{before}");
    assert!(after < 1.0, "{after} ppm");
    // The first row has no derivative yet; every row after is in range and the sensor good.
    assert!(flags[1..].iter().all(|&f| f == 0));
}

#[test]
fn no_knee_is_fitted_with_no_knee() {
    let rig = RigParams {
        truth: RigParams::default().truth.without_knees(),
        seed: 5,
        ..RigParams::default()
    };
    let f = fit(&input(&simulate(&continuous_fit_test(), &rig)))
        .unwrap()
        .0;
    assert!(f.knees.is_empty(), "{:?} (BIC {:?})", f.knees, f.bic);
    assert_eq!(f.segments.len(), 1);
    // A straight line: the polynomial family at degree 1.
    assert_eq!(
        (f.model, f.degree),
        (Family::Polynomial, 1),
        "{:?}",
        f.families
    );
}

/// The issue's run: continuous rotation at 100 deg/s reversed every 5 min,
/// chamber -40..+60 degC, 0.01 deg/sqrt(h).
fn issue_run(truth: ScaleFactorTruth, seed: u64) -> (SfFit, Run, RigParams) {
    let rig = RigParams {
        truth,
        arw_dpsh: 0.01,
        seed,
        ..RigParams::default()
    };
    let test = Test::Continuous {
        profile: SweepProfile::Cycle,
        rate_dps: 100.0,
        direction: Direction::Both,
        reverse_every_s: 300.0,
    };
    let run = simulate(&test, &rig);
    (fit(&input(&run)).unwrap().0, run, rig)
}

/// Validation through the firmware's table: steps profile, -100 deg/s
/// only, another seed; RMS of 60 s means, ppm.
fn validation_ppm(f: &SfFit, rig: &RigParams) -> f64 {
    let val = simulate(
        &validation_test(),
        &RigParams {
            seed: rig.seed + 100,
            ..*rig
        },
    );
    let (comp, _) = compensate_rows(&f.table, &val.t_s, &val.rate_dps, &val.temp_c);
    rms_ppm(&val, &comp)
}

/// The table the firmware holds for a smooth curve: within the fit's
/// range, linear interpolation between nodes no farther apart than the
/// chord rule allows for the curve's largest curvature (h^2 |s''| / 8 <=
/// 0.1 ppm), and the fixed-point lookup within 0.1 ppm of the model.
fn assert_table_holds(f: &SfFit, truth: &ScaleFactorTruth) {
    let t = &f.table;
    assert!(t.check().is_ok() && t.n <= MAX_NODES, "{t:?}");
    assert!(f.tabulation.max_error_ppm < 0.1, "{:?}", f.tabulation);
    let (lo, hi) = (f.range_c[0], f.range_c[1]);
    let curv = truth
        .curvature_ppm_per_c2(lo)
        .abs()
        .max(truth.curvature_ppm_per_c2(hi).abs());
    for w in t.temps_c[..t.n].windows(2) {
        let h = w[1] - w[0];
        assert!(h * h * curv / 8.0 <= 0.1, "spacing {h} degC for s'' {curv}");
    }
}

/// Acceptance: a quadratic (0.02 ppm/degC^2 about 10 degC) and a cubic
/// scale factor with no knee are fitted as polynomials of their degree,
/// with no knee, their leading term's 95 % interval holding the truth, and
/// compensate a validation run to at most 1 ppm through the firmware.
#[test]
fn smooth_curves_are_fitted_with_no_knee() {
    for (truth, degree, seed) in [
        (ScaleFactorTruth::quadratic(), 2usize, 11u64),
        (ScaleFactorTruth::cubic(), 3, 12),
    ] {
        let (f, _, rig) = issue_run(truth, seed);
        assert!(f.knees.is_empty(), "{:?}: {:?}", f.knees, f.criteria);
        assert_eq!(
            (f.model, f.degree),
            (Family::Polynomial, degree),
            "{:?}",
            f.families
        );
        // Decisively: every other family's best is far worse.
        assert!(f.criterion_margin > 10.0, "{:?}", f.families);
        let p = f.polynomial.as_ref().unwrap();
        let c = p.coef_ppm[degree];
        // The truth's leading coefficient about 20 degC (the quadratic's is
        // the same about any centre; the cubic's too).
        let want = if degree == 2 {
            truth.quad_ppm_per_c2
        } else {
            truth.cubic_ppm_per_c3
        };
        assert!((c.value - want).abs() <= 1.96 * c.se, "{c:?} vs {want}");
        assert_table_holds(&f, &truth);
        let v = validation_ppm(&f, &rig);
        assert!(v <= 1.0, "degree {degree}: validation {v} ppm");
        assert!(f.residual_ppm.value <= 1.0, "{:?}", f.residual_ppm);
    }
}

/// Acceptance: a knee on a curved background is found, with the
/// curvature: the knee within 0.5 degC and its interval covering it, the
/// quadratic term's interval covering the truth, 1 ppm on validation.
#[test]
fn knee_on_a_curved_background_is_found_with_the_curvature() {
    let truth = ScaleFactorTruth::knee_on_curve();
    let (f, _, rig) = issue_run(truth, 21);
    assert_eq!(
        (f.model, f.degree),
        (Family::PolynomialWithKnees, 2),
        "{:?}",
        f.families
    );
    assert_eq!(f.knees.len(), 1, "{:?}", f.knees);
    let (k, kt) = (f.knees[0], truth.knees[0].0);
    assert!(
        (k.value - kt).abs() < 0.5 && k.lo <= kt && kt <= k.hi,
        "{k:?}"
    );
    let c = f.polynomial.as_ref().unwrap().coef_ppm[2];
    assert!(
        (c.value - truth.quad_ppm_per_c2).abs() <= 1.96 * c.se,
        "{c:?}"
    );
    // The slope change at the knee: the segments either side of its node.
    let i = f
        .table
        .temps_c
        .iter()
        .position(|&t| (t - k.value).abs() < 0.01)
        .unwrap();
    let (below, above) = (&f.segments[i - 1], &f.segments[i]);
    let jump = above.k_t_ppm_per_c - below.k_t_ppm_per_c;
    // Plus the quadratic's own change of slope over the two segments.
    let curve = 2.0 * truth.quad_ppm_per_c2 * 0.5 * (above.to_c - below.from_c);
    assert!(
        (jump - truth.knees[0].1 - curve).abs() < 0.1,
        "slope change {jump} vs {}",
        truth.knees[0].1
    );
    assert_table_holds(&f, &truth);
    let v = validation_ppm(&f, &rig);
    assert!(v <= 1.0, "validation {v} ppm");
}

#[test]
fn multipoint_brackets_the_knee_and_measures_asymmetry() {
    let rig = RigParams {
        seed: 3,
        ..RigParams::default()
    };
    let (f, plateaus) = fit(&input(&simulate(&multipoint_test(), &rig))).unwrap();
    assert_eq!(f.method.to_string(), "multi-point");
    let plateaus = plateaus.unwrap();
    assert_eq!(plateaus.len(), 5);
    // Each plateau's scale factor is the truth's at its temperature.
    for p in &plateaus {
        let truth = rig.truth.sf_ppm(p.temp_c, 0.0);
        assert!(
            (p.sf_ppm.value - truth).abs() < 5.0 * p.sf_ppm.se + 0.05,
            "{p:?} vs {truth}"
        );
    }
    // The knee lies between the 35 and 60 degC plateaus: only bracketed.
    assert_eq!(f.knees.len(), 1);
    assert!(
        f.knees[0].lo <= 48.0 && 48.0 <= f.knees[0].hi,
        "{:?}",
        f.knees
    );
    assert!(f.knees[0].hi - f.knees[0].lo > 10.0);
    let a = f.asymmetry_ppm.unwrap();
    assert!(
        (a.value - rig.truth.asymmetry_ppm).abs() < 4.0 * a.se,
        "{a:?}"
    );
    assert!(f.nonlinearity_ppm.is_some());
}

fn dir() -> std::path::PathBuf {
    common::dir("sf")
}

#[test]
fn command_line_round_trip() {
    let d = dir();
    let p = |n: &str| d.join(n).display().to_string();
    lab_ok(&["simulate", "scale-factor", "--out", &p("fit.csv")]);
    let out = lab_ok(&[
        "fit",
        "scale-factor",
        "--data",
        &p("fit.csv"),
        "--out",
        &p("sf.toml"),
        "--json",
    ]);
    let v = json(&out);
    for key in ["knees_c", "knees_ci_c", "residual_ppm", "segments"] {
        assert!(v.get(key).is_some(), "{key} missing: {v}");
    }
    let seg = &v["segments"][0];
    for key in ["from_c", "to_c", "k0", "k_t"] {
        assert!(seg.get(key).is_some(), "{key} missing: {seg}");
    }
    let ci = &v["knees_ci_c"][0];
    assert!(ci[0].as_f64().unwrap() <= v["knees_c"][0].as_f64().unwrap());
    // The file is what the firmware loads: it reads back as a valid record.
    let (_, c) = gyro_coeffs::file::read(std::path::Path::new(&p("sf.toml"))).unwrap();
    let gyro_coeffs::file::Coeffs::FogScaleFactor(t) = c else {
        panic!("kind")
    };
    assert_eq!(
        gyro_coeffs::ScaleFactorTable::from_record(&t.to_record()),
        Ok(t)
    );
    let out = lab_ok(&[
        "compensate",
        "--coeffs",
        &p("sf.toml"),
        "--data",
        &p("fit.csv"),
        "--out",
        &p("comp.csv"),
        "--json",
    ]);
    let v: serde_json::Value = serde_json::from_str(out.lines().last().unwrap()).unwrap();
    assert!(v["comp_ppm"].as_f64().unwrap() < 1.0, "{v}");
    // The run as read, its comment lines kept after one naming the
    // coefficients, with the new column.
    let text = std::fs::read_to_string(p("comp.csv")).unwrap();
    let input = std::fs::read_to_string(p("fit.csv")).unwrap();
    assert!(text
        .lines()
        .next()
        .unwrap()
        .starts_with("# gyro-lab compensate: "));
    for c in input.lines().filter(|l| l.starts_with('#')) {
        assert!(text.contains(c), "comment kept: {c}");
    }
    let header = text.lines().find(|l| !l.starts_with('#')).unwrap();
    assert!(header.ends_with(",rate_comp_dps"), "{header}");
}

#[test]
fn bad_input_is_one_line_and_exit_2() {
    let d = dir();
    let write = |name: &str, text: &str| {
        let p = d.join(name);
        std::fs::write(&p, text).unwrap();
        p.display().to_string()
    };
    let rows = |f: &dyn Fn(usize) -> String| -> String { (0..200).map(f).collect() };
    let cases = [
        (
            "no_temp.csv",
            format!(
                "t_s,ref_rate_dps,rate_dps\n{}",
                rows(&|k| format!("{k},50,50.01\n"))
            ),
            ":1",
            "missing column `temp_c`",
        ),
        (
            "no_rotation.csv",
            format!(
                "# at rest\nt_s,ref_rate_dps,rate_dps,temp_c\n{}",
                rows(&|k| format!("{k},0,0.0001,{}\n", -40.0 + k as f64 * 0.5))
            ),
            ":2:2 (column `ref_rate_dps`)",
            "no rotation",
        ),
        (
            "span.csv",
            format!(
                "t_s,ref_rate_dps,rate_dps,temp_c\n{}",
                rows(&|k| format!("{k},50,50.01,{}\n", 20.0 + k as f64 * 0.01))
            ),
            ":1:4 (column `temp_c`)",
            "temperature span",
        ),
        (
            "nan.csv",
            format!(
                "t_s,ref_rate_dps,rate_dps,temp_c\n0,50,NaN,20\n{}",
                rows(&|k| format!("{},50,50.01,{}\n", k + 1, k as f64 * 0.5))
            ),
            ":2:3",
            "finite",
        ),
    ];
    for (name, text, pos, what) in cases {
        let p = write(name, &text);
        let out = d.join("x.toml").display().to_string();
        let (code, _, err) = lab(&["fit", "scale-factor", "--data", &p, "--out", &out]);
        assert_eq!(code, 2, "{name}: {err}");
        assert_eq!(err.trim_end().lines().count(), 1, "{name}: {err}");
        assert!(err.contains(&format!("{p}{pos}")), "{name}: {err}");
        assert!(err.contains(what), "{name}: {err}");
    }
    // A coefficient file with a table the firmware would refuse.
    let bad = write(
        "bad.toml",
        "kind = \"fog_scale_factor\"\nversion = 1\n[fog_scale_factor]\ntemps_c = [10.0, 0.0]\nsf_ppm = [1.0, 2.0]\nbias_dph = [0.0, 0.0]\nsensor_lag_s = 0.0\n",
    );
    let data = write(
        "ok.csv",
        &format!(
            "t_s,ref_rate_dps,rate_dps,temp_c\n{}",
            rows(&|k| format!("{k},50,50.01,{}\n", k as f64 * 0.1))
        ),
    );
    let out = d.join("y.csv").display().to_string();
    let (code, _, err) = lab(&[
        "compensate",
        "--coeffs",
        &bad,
        "--data",
        &data,
        "--out",
        &out,
    ]);
    assert_eq!(code, 2, "{err}");
    assert_eq!(err.trim_end().lines().count(), 1, "{err}");
    assert!(err.contains(&bad) && err.contains("range"), "{err}");
}

/// The scale-factor reports: `fit scale-factor` (continuous and
/// multi-point) and `compensate` write a self-contained report beside
/// their output, named after it, whose plots have axes, units and data and whose
/// verdict's numbers and warnings are the JSON's.
#[test]
fn fit_and_compensate_reports() {
    let d = common::dir("sf-report");
    let p = |n: &str| d.join(n).display().to_string();
    for (name, extra) in [
        (
            "fit.csv",
            vec!["--quadratic-ppm-per-c2", "0.02", "--no-knee"],
        ),
        ("mp.csv", vec!["--test", "multipoint"]),
    ] {
        let mut args = vec!["simulate", "scale-factor"];
        args.extend(extra);
        let out = p(name);
        args.extend(["--out", &out]);
        let (code, _, err) = lab(&args);
        assert_eq!(code, 0, "{err}");
    }
    for (run, dir, figures) in [("fit.csv", "c", 6), ("mp.csv", "m", 3)] {
        std::fs::create_dir_all(d.join(dir)).unwrap();
        let out = d.join(dir).join("sf.toml").display().to_string();
        let stdout = lab_ok(&[
            "fit",
            "scale-factor",
            "--data",
            &p(run),
            "--out",
            &out,
            "--json",
        ]);
        let v = common::json(&stdout);
        let report = d.join(dir).join("sf.html");
        assert_eq!(
            v["report"].as_str(),
            Some(report.display().to_string().as_str())
        );
        let html = std::fs::read_to_string(&report).unwrap();
        report_check::check(&html, &v, figures, 10);
        assert!(html.contains("the criterion of each family and knee count"));
        if run == "mp.csv" {
            assert!(html.contains("plateaus (95 % error bars)"));
            assert_eq!(v["model"], "knees");
        } else {
            assert_eq!(v["model"], "polynomial");
            assert_eq!(v["degree"], 2);
            assert!(v["knees_c"].as_array().unwrap().is_empty());
        }
    }
    // Compensation of another run with the continuous table.
    lab_ok(&[
        "simulate",
        "scale-factor",
        "--quadratic-ppm-per-c2",
        "0.02",
        "--no-knee",
        "--profile",
        "steps",
        "--rate-dps",
        "100",
        "--direction",
        "negative",
        "--seed",
        "4",
        "--out",
        &p("val.csv"),
    ]);
    let stdout = lab_ok(&[
        "compensate",
        "--coeffs",
        &p("c/sf.toml"),
        "--data",
        &p("val.csv"),
        "--out",
        &p("val_comp.csv"),
        "--json",
    ]);
    let v = common::json(&stdout);
    assert!(v["comp_ppm"].as_f64().unwrap() < 1.0, "{v}");
    let html = std::fs::read_to_string(d.join("val_comp.html")).unwrap();
    report_check::check(&html, &v, 4, 10);
    // The steps run stays inside the calibrated range. (Its residual may be
    // warned about: the simulated gyro's 1 ppm asymmetry, which the fit's
    // both-ways run averages out, shows on this one-sign run at about
    // three times its white-noise floor.)
    let kinds = report_check::assert_warnings_match(&html, &v);
    assert!(
        kinds.iter().all(|k| k == "residual_above_noise"),
        "{kinds:?}"
    );
}

/// Warnings appear where a run is built to trigger them: a knee 4 degC
/// from the top of the sweep; a table calibrated over 0..30 degC applied
/// to a run that leaves that range.
#[test]
fn reports_warn_on_runs_built_to_trigger_it() {
    let d = common::dir("sf-warn");
    let p = |n: &str| d.join(n).display().to_string();
    lab_ok(&[
        "simulate",
        "scale-factor",
        "--knees-c",
        "56",
        "--out",
        &p("edge.csv"),
    ]);
    let stdout = lab_ok(&[
        "fit",
        "scale-factor",
        "--data",
        &p("edge.csv"),
        "--out",
        &p("edge.toml"),
        "--json",
    ]);
    let v = common::json(&stdout);
    let k = v["knees_c"][0].as_f64().unwrap();
    assert!((k - 56.0).abs() < 0.5, "{v}");
    let html = std::fs::read_to_string(d.join("edge.html")).unwrap();
    let kinds = report_check::assert_warnings_match(&html, &v);
    assert!(kinds.iter().any(|k| k == "knee_near_edge"), "{kinds:?}");
    report_check::check(&html, &v, 6, 10);
    // A table over 0..30 degC only; the steps run goes -20..55 degC.
    std::fs::write(
        d.join("narrow.toml"),
        "kind = \"fog_scale_factor\"\nversion = 1\n[fog_scale_factor]\ntemps_c = [0.0, 30.0]\n\
         sf_ppm = [120.0, 165.0]\nbias_dph = [0.3, 0.3]\nsensor_lag_s = 30.0\n",
    )
    .unwrap();
    lab_ok(&[
        "simulate",
        "scale-factor",
        "--no-knee",
        "--profile",
        "steps",
        "--out",
        &p("val.csv"),
    ]);
    let stdout = lab_ok(&[
        "compensate",
        "--coeffs",
        &p("narrow.toml"),
        "--data",
        &p("val.csv"),
        "--out",
        &p("val_comp.csv"),
        "--json",
    ]);
    let v = common::json(&stdout);
    let spans = v["out_of_range_spans"].as_array().unwrap();
    assert!(!spans.is_empty(), "{v}");
    // The spans are where the coil sensor (less the lead) was outside.
    for s in spans {
        let (lo, hi) = (s["min_c"].as_f64().unwrap(), s["max_c"].as_f64().unwrap());
        assert!(lo < 1.0 || hi > 29.0, "{s}");
    }
    let html = std::fs::read_to_string(d.join("val_comp.html")).unwrap();
    let kinds = report_check::assert_warnings_match(&html, &v);
    assert!(
        kinds.iter().any(|k| k == "outside_calibrated_range"),
        "{kinds:?}"
    );
    report_check::check(&html, &v, 4, 10);
}
