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

/// `discover --model ... --data ... --json` into `out`.
fn discover(
    model: Option<&std::path::Path>,
    data: &std::path::Path,
    out: &std::path::Path,
    extra: &[&str],
) -> serde_json::Value {
    let (d, o) = (p(data), p(out));
    let m = model.map(p);
    let mut args = vec![
        "discover", "--gyro", "fog", "--data", &d, "--out", &o, "--json",
    ];
    if let Some(m) = &m {
        args.extend_from_slice(&["--model", m]);
    }
    args.extend_from_slice(extra);
    json(&lab_ok(&args))
}

/// A user who suspects a w^2 term writes it with no coefficient: discover
/// fits the coefficient (the truth inside its interval), writes it into
/// the model, and the gap falls to the noise floor.
#[test]
fn a_users_term_gets_its_coefficient_fitted() {
    let d = common::dir("model-term-user");
    let truth = d.join("truth.toml");
    std::fs::write(&truth, term_model("k_dph * ref_rate_dps^2", "k_dph = 2e-4")).unwrap();
    let run = d.join("run.csv");
    simulate(&truth, &run, &[]);
    let suspect = d.join("suspect.toml");
    std::fs::write(&suspect, term_model("k_dph * ref_rate_dps^2", "k_dph = 0")).unwrap();
    let v = discover(Some(&suspect), &run, &d.join("o"), &[]);
    let t = &v["model_terms"][0];
    assert_eq!(t["formula"], "k_dph * ref_rate_dps^2", "{v}");
    let k = t["parameters"]["k_dph"].as_f64().unwrap();
    let iv = &t["parameter_intervals"]["k_dph"];
    let (lo, hi) = (iv[0].as_f64().unwrap(), iv[1].as_f64().unwrap());
    assert!(lo < 2e-4 && 2e-4 < hi, "{k} [{lo}, {hi}]");
    assert!(hi - lo < 0.1 * 2e-4, "[{lo}, {hi}]");
    assert_eq!(t["named"], true, "{t}");
    // The library names nothing beside it.
    assert!(v["found"].as_array().unwrap().is_empty(), "{v}");
    let (after, floor) = (
        v["gap_after_dph"].as_f64().unwrap(),
        v["noise_floor_dph"].as_f64().unwrap(),
    );
    assert!(after < 1.1 * floor, "gap after {after}, floor {floor}");
    let written = std::fs::read_to_string(d.join("o").join("model.toml")).unwrap();
    let fitted: toml::Table = toml::from_str(&written).unwrap();
    let k_written = fitted["effect"][0]["k_dph"].as_float().unwrap();
    assert_eq!(k_written, k, "{written}");
}

/// No term in the model: discover proposes k w^2 (the check reads the
/// model written, not the formula), its coefficient's interval holds the
/// truth, the gap falls to the floor, and the model written on this run
/// predicts a second run of the same gyro.
#[test]
fn a_missing_rate_squared_term_is_proposed_and_predicts_a_second_run() {
    let d = common::dir("model-term-proposed");
    let truth = d.join("truth.toml");
    // 1.6e-4 deg/h per (deg/s)^2: 6.4 deg/h at 200 deg/s, some 8 times
    // the 1 s floor in RMS.
    std::fs::write(
        &truth,
        term_model("k_dph * ref_rate_dps^2", "k_dph = 1.6e-4"),
    )
    .unwrap();
    let (a, b) = (d.join("a.csv"), d.join("b.csv"));
    simulate(&truth, &a, &["--seed", "11"]);
    simulate(&truth, &b, &["--seed", "12"]);
    let v = discover(None, &a, &d.join("o"), &["--validate", &p(&b)]);
    let found = v["found"].as_array().unwrap();
    assert_eq!(found.len(), 1, "{v}");
    let t = &found[0];
    assert_eq!(t["effect"], "term");
    assert_eq!(t["library"], false);
    assert!(t["validation"]["passed"].as_bool().unwrap(), "{t}");
    assert!(
        t["validation"]["second_run"]["predicts"].as_bool().unwrap(),
        "{t}"
    );
    let (after, floor) = (
        v["gap_after_dph"].as_f64().unwrap(),
        v["noise_floor_dph"].as_f64().unwrap(),
    );
    assert!(after <= 1.25 * floor, "gap after {after}, floor {floor}");
    // What the model written adds, against the truth: the same output on
    // run B's inputs up to the noise of the fit.
    let model_a = d.join("o").join("model.toml");
    let sim = d.join("sim.csv");
    simulate(
        &model_a,
        &sim,
        &[
            "--seed",
            "12",
            "--arw-dpsh",
            "0",
            "--bias-instability-dph",
            "0",
            "--rate-random-walk-dphsh",
            "0",
        ],
    );
    let text = std::fs::read_to_string(&sim).unwrap();
    let mut rows = text.lines().filter(|l| !l.starts_with('#'));
    let head: Vec<&str> = rows.next().unwrap().split(',').collect();
    let col = |n: &str| head.iter().position(|h| *h == n).unwrap();
    let (w, y) = (col("ref_rate_dps"), col("rate_dps"));
    let (mut num, mut den) = (0.0, 0.0);
    for r in rows {
        let c: Vec<f64> = r.split(',').map(|x| x.parse().unwrap()).collect();
        let added = (c[y] - c[w]) * 3600.0;
        let hidden = 1.6e-4 * c[w] * c[w];
        num += (added - hidden).powi(2);
        den += hidden * hidden;
    }
    // A bias may come with it; the shape must be the hidden one.
    assert!(num / den < 0.01, "relative misfit {}", num / den);
    assert_eq!(v["validation"]["predicts"], true, "{v}");
    // Up to a bias, the model written leaves run B its noise: within the
    // band this run's own gap is held to.
    let vb = &v["validation"];
    let (removed, floor_b) = (
        vb["gap_bias_removed_dph"].as_f64().unwrap(),
        vb["noise_floor_dph"].as_f64().unwrap(),
    );
    assert!(
        removed <= 1.25 * floor_b,
        "{removed} against the floor {floor_b}"
    );
    // ... and within the bar of what run B's own discovery leaves:
    // the model is the gyro's, not run A's.
    let ratio = vb["prediction_ratio"].as_f64().unwrap();
    let own = vb["own_gap_after_dph"].as_f64().unwrap();
    assert!((removed / own - ratio).abs() < 1e-12, "{ratio}");
    assert!(ratio <= 1.1, "{removed} against run B's own {own}");
}

/// Coloured noise alone (flicker and a rate random walk, the usual
/// imitators): nothing proposed.
#[test]
fn coloured_noise_gets_no_term() {
    let d = common::dir("model-term-null");
    let ideal = d.join("ideal.toml");
    std::fs::write(
        &ideal,
        "kind = \"gyro_model\"\nversion = 1\ngyro = \"fog\"\n",
    )
    .unwrap();
    for seed in ["21", "22"] {
        let run = d.join(format!("run{seed}.csv"));
        simulate(
            &ideal,
            &run,
            &[
                "--seed",
                seed,
                "--bias-instability-dph",
                "0.05",
                "--rate-random-walk-dphsh",
                "0.05",
            ],
        );
        let v = discover(None, &run, &d.join(format!("o{seed}")), &[]);
        let terms: Vec<&serde_json::Value> = v["found"]
            .as_array()
            .unwrap()
            .iter()
            .filter(|f| f["effect"] == "term")
            .collect();
        assert!(terms.is_empty(), "seed {seed}: {v}");
    }
}

/// A jump that relaxes (a relock, a heater's transient) on a FOG chamber
/// run: the noise model first takes it as a random walk beyond any
/// navigation gyro's, under which it predicts nothing, and a smooth
/// settling that misses the jump itself fails the checks. Looked at
/// under the grade's noise, with its onset refined off the coarse grid,
/// the event is proposed with its truth inside its intervals, and the gap
/// falls to the floor.
#[test]
fn a_jump_that_relaxes_is_found_where_a_random_walk_took_it() {
    event_found(
        "model-term-jump-relax",
        "k_dph * step(t_s - t0_s) * exp(-(t_s - t0_s) * step(t_s - t0_s) / tau_s)",
        &[("k_dph", 2.0), ("t0_s", 5000.0), ("tau_s", 900.0)],
    );
}

/// An event hidden in the project's FOG chamber profile (`simulate run
/// --model`) is proposed with exactly its formula, each truth inside its
/// parameter's interval, and the gap after within 1.1 times the floor.
fn event_found(name: &str, formula: &str, truth: &[(&str, f64)]) {
    let d = common::dir(name);
    let model = d.join("truth.toml");
    let params: Vec<String> = truth.iter().map(|(k, v)| format!("{k} = {v:?}")).collect();
    std::fs::write(&model, term_model(formula, &params.join("\n"))).unwrap();
    let run = d.join("run.csv");
    let (m, o) = (p(&model), p(&run));
    lab_ok(&[
        "simulate",
        "run",
        "--model",
        &m,
        "--profile",
        "fog-chamber",
        "--out",
        &o,
    ]);
    let v = discover(None, &run, &d.join("o"), &[]);
    // A proposed term is among what was found (model_terms are a user's).
    let found = v["found"].as_array().unwrap();
    let t = found
        .iter()
        .find(|t| t["formula"] == formula)
        .unwrap_or_else(|| panic!("{formula} not proposed: {}", v["proposal"]));
    for &(name, want) in truth {
        let iv = &t["parameter_intervals"][name];
        let (lo, hi) = (iv[0].as_f64().unwrap(), iv[1].as_f64().unwrap());
        assert!(
            lo <= want && want <= hi,
            "{name}: {want} outside [{lo}, {hi}]: {t}"
        );
    }
    let (after, floor) = (
        v["gap_after_dph"].as_f64().unwrap(),
        v["noise_floor_dph"].as_f64().unwrap(),
    );
    assert!(
        after < 1.1 * floor,
        "gap {after} against a floor of {floor}"
    );
}

/// A pulse (a heater on for ten minutes) whose edges fall between the
/// coarse grid's: a wider pulse on the grid fits as well wherever it
/// covers the truth, so the onset, refined with the width held, had
/// nowhere better to go. Refined with its end held, then the width, each
/// edge is the truth's, inside its interval, and the gap falls to the
/// floor.
#[test]
fn a_pulse_between_the_grid_points_is_found_edge_by_edge() {
    event_found(
        "model-term-pulse",
        "k_dph * (step(t_s - t0_s) - step(t_s - t0_s - w_s))",
        &[("k_dph", -1.5), ("t0_s", 4777.0), ("w_s", 622.0)],
    );
}
