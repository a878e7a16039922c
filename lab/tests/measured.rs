//! Discovery on a measured gyro it was not built on: a MEMS IMU in a
//! climate chamber (tests/data/measured/tofupilot_imu_thermal/SOURCE.md),
//! read from the file as its owner wrote it (tab separated, dotted column
//! names, rad/s, microsecond timestamps). The check is against an
//! independent fit, made here from the file: the bias of a MEMS gyro
//! over -18 to 74 degC is a cubic in temperature, and the least-squares
//! cubic's gap is the least a polynomial model of the sensor's reading
//! leaves.

mod common;

use common::{dir, json, lab_ok};
use std::path::Path;

/// (t s, rate deg/h, temperature degC) of the record's y axis.
fn rows(p: &Path) -> Vec<(f64, f64, f64)> {
    let text = std::fs::read_to_string(p).unwrap();
    let mut lines = text.lines();
    let head: Vec<&str> = lines.next().unwrap().split('\t').collect();
    let col = |n: &str| head.iter().position(|h| *h == n).unwrap();
    let (t, g, c) = (col("timestamp"), col("imu.gyro.y"), col("imu.temperature"));
    let rows: Vec<Vec<f64>> = lines
        .map(|l| l.split('\t').map(|x| x.parse().unwrap()).collect())
        .collect();
    let t0 = rows[0][t];
    rows.iter()
        .map(|r| ((r[t] - t0) * 1e-6, r[g].to_degrees() * 3600.0, r[c]))
        .collect()
}

/// Least squares of `y` on the columns `x` (normal equations, Gaussian
/// elimination with partial pivoting): the residual.
fn residual(x: &[Vec<f64>], y: &[f64]) -> Vec<f64> {
    let m = x.len();
    let mut a = vec![vec![0.0; m + 1]; m];
    for i in 0..m {
        for j in 0..m {
            a[i][j] = x[i].iter().zip(&x[j]).map(|(p, q)| p * q).sum();
        }
        a[i][m] = x[i].iter().zip(y).map(|(p, q)| p * q).sum();
    }
    for k in 0..m {
        let p = (k..m)
            .max_by(|&i, &j| a[i][k].abs().total_cmp(&a[j][k].abs()))
            .unwrap();
        a.swap(k, p);
        let (top, rest) = a.split_at_mut(k + 1);
        let pivot = &top[k];
        for row in rest {
            let f = row[k] / pivot[k];
            row.iter_mut()
                .zip(pivot)
                .skip(k)
                .for_each(|(x, p)| *x -= f * p);
        }
    }
    let mut c = vec![0.0; m];
    for k in (0..m).rev() {
        c[k] = (a[k][m] - (k + 1..m).map(|j| a[k][j] * c[j]).sum::<f64>()) / a[k][k];
    }
    (0..y.len())
        .map(|r| y[r] - (0..m).map(|i| c[i] * x[i][r]).sum::<f64>())
        .collect()
}

/// RMS of the 1 s means of `e` (the gap's averaging).
fn gap(t: &[f64], e: &[f64]) -> f64 {
    let mut sums: Vec<(f64, f64)> = vec![];
    let mut last = i64::MIN;
    for (tk, ek) in t.iter().zip(e) {
        let w = tk.floor() as i64;
        if w != last {
            sums.push((0.0, 0.0));
            last = w;
        }
        let s = sums.last_mut().unwrap();
        s.0 += ek;
        s.1 += 1.0;
    }
    let n = sums.len() as f64;
    (sums.iter().map(|(s, c)| (s / c).powi(2)).sum::<f64>() / n).sqrt()
}

#[test]
fn a_mems_gyro_swept_in_a_chamber_is_explained_as_the_best_cubic_in_temperature() {
    let data = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/measured/tofupilot_imu_thermal/imu_raw_data.csv");
    let d = dir("measured-chamber");
    let out = lab_ok(&[
        "discover",
        "--gyro",
        "mems",
        "--data",
        data.to_str().unwrap(),
        "--columns",
        "t_s=timestamp,rate_dps=imu.gyro.y,temp_c=imu.temperature",
        "--rate-unit",
        "rad/s",
        "--time-unit",
        "us",
        "--out",
        d.to_str().unwrap(),
        "--json",
        "--force",
    ]);
    let j = json(&out);

    let r = rows(&data);
    let t: Vec<f64> = r.iter().map(|x| x.0).collect();
    let y: Vec<f64> = r.iter().map(|x| x.1).collect();
    let poly = |deg: i32| -> f64 {
        let x: Vec<Vec<f64>> = (0..=deg)
            .map(|p| r.iter().map(|x| (x.2 - 20.0).powi(p)).collect())
            .collect();
        gap(&t, &residual(&x, &y))
    };
    let (linear, cubic) = (poly(1), poly(3));
    let after = j["gap_after_dph"].as_f64().unwrap();
    let before = j["gap_before_dph"].as_f64().unwrap();
    eprintln!(
        "gap before {before:.1}, after {after:.1} deg/h; least-squares linear {linear:.1}, cubic {cubic:.1}"
    );
    // The record's own figures: a bias of -1.5e3 deg/h and a swing of
    // 3 deg/s over 92 degC.
    assert!((3000.0..4500.0).contains(&before), "{before}");
    // The tool's fit is generalised least squares under the residual's
    // noise, not ordinary; it must come within 15 % of the best cubic, and
    // do far better than a linear temperature slope.
    assert!(after <= 1.15 * cubic, "{after} against the cubic's {cubic}");
    assert!(after < 0.3 * linear, "{after} against the line's {linear}");
    let found: Vec<&str> = j["found"]
        .as_array()
        .unwrap()
        .iter()
        .map(|f| f["effect"].as_str().unwrap())
        .collect();
    assert!(found.contains(&"bias_temperature"), "{found:?}");
    // What the library's line in temperature leaves is proposed in
    // temperature too.
    let formulas: Vec<&str> = j["found"]
        .as_array()
        .unwrap()
        .iter()
        .filter_map(|f| f["formula"].as_str())
        .collect();
    assert!(
        formulas.iter().any(|f| f.contains("temp_c")),
        "{formulas:?}"
    );
    // The model written leaves a residual that averages zero on its record.
    let (lo, hi) = (
        j["residual_mean"]["lo_dph"].as_f64().unwrap(),
        j["residual_mean"]["hi_dph"].as_f64().unwrap(),
    );
    assert!(lo <= 0.0 && 0.0 <= hi, "{lo} .. {hi}");
}

/// The record's rows `from..to` as a user's converted file, its clock from
/// zero (t_s, rate_dps, temp_c), discovered as a MEMS gyro: the rows and
/// the JSON.
fn discover_part(name: &str, from: usize, to: usize) -> (Vec<(f64, f64, f64)>, serde_json::Value) {
    let data = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/measured/tofupilot_imu_thermal/imu_raw_data.csv");
    let all = rows(&data);
    let t0 = all[from].0;
    let r: Vec<(f64, f64, f64)> = all[from..to.min(all.len())]
        .iter()
        .map(|x| (x.0 - t0, x.1, x.2))
        .collect();
    let d = dir(name);
    let file = d.join("part.csv");
    let mut text = String::from("t_s,rate_dps,temp_c\n");
    for (t, w, c) in &r {
        text.push_str(&format!("{t},{},{c}\n", w / 3600.0));
    }
    std::fs::write(&file, text).unwrap();
    let out = lab_ok(&[
        "discover",
        "--gyro",
        "mems",
        "--data",
        file.to_str().unwrap(),
        "--out",
        d.join("out").to_str().unwrap(),
        "--json",
        "--force",
    ]);
    (r, json(&out))
}

/// The sweep's first half (cooling from 52 to -18 degC and warming back
/// to 18), as a user's converted file whose clock starts at zero: a
/// warm-up from that zero fits the first fall of a bias that follows the
/// temperature, and taken first it leaves the rest to a random walk
/// (restart.rs). The bias follows the temperature: no warm-up is named,
/// and the model leaves less than the least-squares cubic in temperature.
#[test]
fn a_chamber_sweep_starting_hot_is_not_read_as_a_warm_up() {
    let (r, j) = discover_part("measured-chamber-half", 0, 4200);
    let t: Vec<f64> = r.iter().map(|x| x.0).collect();
    let y: Vec<f64> = r.iter().map(|x| x.1).collect();
    let x: Vec<Vec<f64>> = (0..=3)
        .map(|p| r.iter().map(|x| (x.2 - 20.0).powi(p)).collect())
        .collect();
    let cubic = gap(&t, &residual(&x, &y));
    let after = j["gap_after_dph"].as_f64().unwrap();
    let found: Vec<&str> = j["found"]
        .as_array()
        .unwrap()
        .iter()
        .map(|f| f["effect"].as_str().unwrap())
        .collect();
    eprintln!("found {found:?}; gap after {after:.1} deg/h, least-squares cubic {cubic:.1}");
    assert!(!found.contains(&"warm_up"), "{found:?}");
    assert!(found.contains(&"bias_temperature"), "{found:?}");
    assert!(after < cubic, "{after} against the cubic's {cubic}");
    // The warm-up was the first start's, and is said to have gone.
    let dropped = j["dropped"].to_string();
    assert!(dropped.contains("warm_up"), "{dropped}");
}

/// The sweep's second half (warming 18 -> 74 degC, cooling to 36): a
/// sinusoid in time is proposed beside the temperature's terms, and a
/// square in temperature predicted the record as well. A shape of time
/// alone carries to no other run: the term says what it could not be
/// told from.
#[test]
fn a_shape_of_time_says_which_input_term_predicted_as_well() {
    let (_, j) = discover_part("measured-chamber-second-half", 4200, usize::MAX);
    let terms: Vec<&serde_json::Value> = j["found"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|f| f["effect"] == "term")
        .collect();
    let inputs = ["temp_c", "ref_rate_dps", "ref_acc_dps2"];
    let of_time: Vec<&&serde_json::Value> = terms
        .iter()
        .filter(|f| {
            let s = f["formula"].as_str().unwrap();
            !inputs.iter().any(|i| s.contains(i))
        })
        .collect();
    assert!(!of_time.is_empty(), "{terms:?}");
    for f in of_time {
        let rival = &f["rival"];
        let gain = f["validation"]["held_out_gain"].as_f64().unwrap();
        let rg = rival["held_out_gain"].as_f64().unwrap();
        assert!(rival["formula"].as_str().unwrap().contains("temp_c"), "{f}");
        // Within the scatter of the term's own gain (2 sqrt(G)).
        assert!(
            rg >= gain - (0.03 * gain).max(2.0 * gain.sqrt()),
            "{rg} against {gain}"
        );
    }
}
