//! FOG scale factor over temperature: the fits against the simulated gyro's
//! truth, the compensation through the firmware's fixed-point code, and the
//! command line's contract (bad input: one line, exit 2).

mod common;
use common::lab;

use gyro_lab::bench::scale_factor::{continuous_fit_test, multipoint_test, validation_test};
use gyro_lab::calibration::scale_factor::compensation::compensate_rows;
use gyro_lab::calibration::scale_factor::fit::fit;
use gyro_lab::calibration::scale_factor::input::{prepare, SfInput};
use gyro_lab::calibration::scale_factor::residual::window_rms_ppm;
use gyro_lab::sim::scale_factor_rig::{simulate, RigParams, Run};

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
    let (code, _, err) = lab(&["simulate", "scale-factor", "--out", &p("fit.csv")]);
    assert_eq!(code, 0, "{err}");
    let (code, out, err) = lab(&[
        "fit",
        "scale-factor",
        "--data",
        &p("fit.csv"),
        "--out",
        &p("sf.toml"),
        "--json",
    ]);
    assert_eq!(code, 0, "{err}");
    let v: serde_json::Value = serde_json::from_str(out.lines().last().unwrap()).unwrap();
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
    let (code, out, err) = lab(&[
        "compensate",
        "--coeffs",
        &p("sf.toml"),
        "--data",
        &p("fit.csv"),
        "--out",
        &p("comp.csv"),
        "--json",
    ]);
    assert_eq!(code, 0, "{err}");
    let v: serde_json::Value = serde_json::from_str(out.lines().last().unwrap()).unwrap();
    assert!(v["comp_ppm"].as_f64().unwrap() < 1.0, "{v}");
    let text = std::fs::read_to_string(p("comp.csv")).unwrap();
    assert!(text.lines().next().unwrap().ends_with(",rate_comp_dps"));
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
