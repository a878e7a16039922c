//! `gyro-lab simulate fog` as a user first runs it: the default result is
//! the loop's steady state, not its start-up.

mod common;
use common::{json, lab};

/// Under 50 000 deg/s^2 at 60 Hz the default run leaves out five AGC time
/// constants (4096 closures each) and its corrected mean is zero within
/// three standard errors, the raw mean the eps^2 formula's drift; a run too
/// short for the settling says so.
#[test]
fn the_default_result_is_the_steady_state() {
    // Under 50 000 deg/s^2 at 60 Hz, with `extra` options.
    let vibrated = |extra: &[&str]| {
        let mut args = vec![
            "simulate",
            "fog",
            "--vibration-dps2",
            "50000",
            "--vibration-hz",
            "60",
            "--json",
        ];
        args.extend_from_slice(extra);
        lab(&args)
    };
    let (code, out, err) = vibrated(&[]);
    assert_eq!(code, 0, "{err}");
    let v = json(&out);
    assert_eq!(v["settled"], true, "{v}");
    let settle = v["settle_s"].as_f64().unwrap();
    let tau = 4096.0 / 12_500.0;
    assert!(
        settle >= 5.0 * tau && settle < 5.0 * tau + 1.0 / 60.0,
        "{v}"
    );
    let (m, se) = (
        v["mean_error_dph"].as_f64().unwrap(),
        v["mean_error_stderr_dph"].as_f64().unwrap(),
    );
    assert!(m.abs() < 3.0 * se, "{v}");
    let (raw, raw_se, formula) = (
        v["mean_error_raw_dph"].as_f64().unwrap(),
        v["mean_error_raw_stderr_dph"].as_f64().unwrap(),
        v["predicted_drift_dph"].as_f64().unwrap(),
    );
    assert!((raw - formula).abs() < 3.0 * raw_se + 0.01 * formula, "{v}");
    let (code, out, err) = vibrated(&["--duration-s", "1"]);
    assert_eq!(code, 0, "{err}");
    assert_eq!(json(&out)["settled"], false);
    assert!(
        err.contains("too short to leave out the whole start-up"),
        "{err}"
    );
}
