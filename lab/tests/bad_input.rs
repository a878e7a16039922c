//! Bad input: one line on stderr naming file, line and column; exit status 2.

use std::process::Command;

fn lab(args: &[&str]) -> (i32, String) {
    let out = Command::new(env!("CARGO_BIN_EXE_gyro-lab"))
        .args(args)
        .output()
        .expect("run gyro-lab");
    let err = String::from_utf8_lossy(&out.stderr).into_owned();
    (out.status.code().unwrap_or(-1), err)
}

fn write(name: &str, text: &str) -> String {
    let dir = std::env::temp_dir().join(format!("gyro-lab-bad-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let p = dir.join(name);
    std::fs::write(&p, text).unwrap();
    p.display().to_string()
}

#[test]
fn lockin_bad_files() {
    let good_rows: String = (0..100)
        .map(|k| format!("{},{}\n", 1.0 + k as f64 * 5e-5, (k as f64).sin()))
        .collect();
    let cases = [
        (
            "nonnumeric.csv",
            format!("# comment\nt_s,signal\n0,1\n1e-4,abc\n{good_rows}"),
            ":4:2",
            "abc",
        ),
        (
            "nan.csv",
            format!("t_s,signal\n0,NaN\n{good_rows}"),
            ":2:2",
            "finite",
        ),
        (
            "missing.csv",
            format!("t_s,sig\n{good_rows}"),
            ":1",
            "missing column `signal`",
        ),
        (
            "time.csv",
            format!("t_s,signal\n{good_rows}1.001,0\n"),
            ":102:1",
            "does not increase",
        ),
        (
            "short.csv",
            "t_s,signal\n0,0\n1,1\n".to_owned(),
            "",
            "at least",
        ),
    ];
    for (name, text, pos, what) in cases {
        let p = write(name, &text);
        let (code, err) = lab(&["lockin", "--data", &p, "--pulses-per-deg", "2000"]);
        assert_eq!(code, 2, "{name}: {err}");
        assert_eq!(err.trim_end().lines().count(), 1, "{name}: {err}");
        assert!(err.contains(&format!("{p}{pos}")), "{name}: {err}");
        assert!(err.contains(what), "{name}: {err}");
    }
    let (code, err) = lab(&[
        "lockin",
        "--data",
        "/nonexistent/x.csv",
        "--pulses-per-deg",
        "2000",
    ]);
    assert_eq!(code, 2);
    assert!(err.contains("/nonexistent/x.csv"));
}
