//! A term outside the library in the model file (docs/interfaces.md,
//! "Model file"): `simulate run --model` and `discover --model` evaluate
//! it the same way, and a formula the run cannot evaluate is refused at
//! its file, line and column with exit 2.

mod common;
use common::{json, lab, lab_ok};

fn p(x: &std::path::Path) -> String {
    x.display().to_string()
}

/// `simulate run` of the table profile for an hour, with `extra` options.
fn simulate(model: &std::path::Path, out: &std::path::Path, extra: &[&str]) {
    let (m, o) = (p(model), p(out));
    let mut args = vec![
        "simulate",
        "run",
        "--model",
        &m,
        "--profile",
        "table",
        "--duration-s",
        "3600",
        "--out",
        &o,
    ];
    args.extend_from_slice(extra);
    lab_ok(&args);
}

fn term_model(formula: &str, params: &str) -> String {
    format!("kind = \"gyro_model\"\nversion = 1\ngyro = \"fog\"\n[[effect]]\nname = \"term\"\nformula = \"{formula}\"\n{params}\n")
}

#[test]
fn a_quadratic_rate_term_is_simulated_and_then_explained() {
    let d = common::dir("model-term-quadratic");
    let truth = d.join("truth.toml");
    // 2e-4 deg/h per (deg/s)^2: 8 deg/h at the table's 200 deg/s.
    std::fs::write(&truth, term_model("k_dph * ref_rate_dps^2", "k_dph = 2e-4")).unwrap();
    let run = d.join("run.csv");
    let quiet = [
        "--arw-dpsh",
        "0",
        "--bias-instability-dph",
        "0",
        "--rate-random-walk-dphsh",
        "0",
    ];
    simulate(&truth, &run, &quiet);
    // Noise-free: every row is the reference plus the formula, deg/h.
    let text = std::fs::read_to_string(&run).unwrap();
    let mut rows = text.lines().filter(|l| !l.starts_with('#'));
    let head: Vec<&str> = rows.next().unwrap().split(',').collect();
    let col = |n: &str| head.iter().position(|h| *h == n).unwrap();
    let (w, y) = (col("ref_rate_dps"), col("rate_dps"));
    let mut n = 0;
    for r in rows {
        let c: Vec<f64> = r.split(',').map(|x| x.parse().unwrap()).collect();
        let want = c[w] + 2e-4 * c[w] * c[w] / 3600.0;
        assert!((c[y] - want).abs() <= 1e-9 * want.abs().max(1.0), "{r}");
        n += 1;
    }
    assert!(n > 1000);
    // With noise, the truth given as the model leaves nothing to find.
    let noisy = d.join("noisy.csv");
    simulate(&truth, &noisy, &[]);
    let v = json(&lab_ok(&[
        "discover",
        "--gyro",
        "fog",
        "--model",
        &p(&truth),
        "--data",
        &p(&noisy),
        "--out",
        &p(&d.join("o")),
        "--json",
    ]));
    assert!(v["found"].as_array().unwrap().is_empty(), "{v}");
    let (gap, floor) = (
        v["gap_before_dph"].as_f64().unwrap(),
        v["noise_floor_dph"].as_f64().unwrap(),
    );
    assert!(gap < 1.5 * floor, "gap {gap} floor {floor}");
    // The model written back keeps the term as it was given.
    let written = std::fs::read_to_string(d.join("o").join("model.toml")).unwrap();
    assert!(written.contains("k_dph * ref_rate_dps^2"), "{written}");
}

#[test]
fn formulas_the_run_cannot_evaluate_are_refused_at_their_place() {
    let d = common::dir("model-term-bad");
    let cases = [
        // (formula line, what is wrong, the column the message must name)
        (
            term_model("k / step(t_s - 1e9)", "k = 1"),
            "divides by zero",
            16,
        ),
        (
            term_model("k * t_mono_a_c", "k = 1"),
            "has no column `t_mono_a_c`",
            16,
        ),
        (term_model("k * (ref_rate_dps", "k = 1"), "", 0),
        (term_model("k * rate_dps", "k = 1"), "the gyro's output", 16),
    ];
    for (i, (text, what, col)) in cases.iter().enumerate() {
        let m = d.join(format!("m{i}.toml"));
        std::fs::write(&m, text).unwrap();
        let (code, _, err) = lab(&[
            "simulate",
            "run",
            "--model",
            &p(&m),
            "--profile",
            "table",
            "--duration-s",
            "600",
            "--out",
            &p(&d.join("x.csv")),
        ]);
        assert_eq!(code, 2, "{err}");
        assert_eq!(err.trim_end().lines().count(), 1, "{err}");
        assert!(err.contains(&format!("m{i}.toml:6:")), "{err}");
        assert!(err.contains(what), "{err}");
        if *col > 0 {
            assert!(err.contains(&format!(":6:{col}")), "{err}");
        }
        assert!(!err.contains("panicked"), "{err}");
    }
}
