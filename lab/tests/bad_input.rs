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

/// A run file with every column the commands read, `n` rows of a static
/// gyro in a slowly warming chamber.
fn run_rows(n: usize) -> String {
    (0..n)
        .map(|k| {
            let t = k as f64;
            let temp = 20.0 + t * 0.01;
            format!(
                "{t},0.0041781,{},{temp},{temp},{},{temp}\n",
                0.0041781 + 1e-5 * (t * 0.7).sin(),
                temp + 0.1
            )
        })
        .collect()
}

const RUN_HEADER: &str = "t_s,ref_rate_dps,rate_dps,temp_c,t_mono_a_c,t_mono_b_c,t_case_c\n";

/// Every command that reads a data file, on `data`, writing under `out`.
fn commands(data: &str, out: &str) -> Vec<Vec<String>> {
    let coeffs = concat!(env!("CARGO_MANIFEST_DIR"), "/../config/rlg_thermal.toml");
    let raw = write("raw.bin", "");
    [
        vec!["allan", "--data", data],
        vec![
            "fit",
            "thermal",
            "--data",
            data,
            "--out",
            &format!("{out}/c.toml"),
        ],
        vec![
            "fit",
            "scale-factor",
            "--data",
            data,
            "--out",
            &format!("{out}/sf.toml"),
        ],
        vec![
            "compensate",
            "--coeffs",
            coeffs,
            "--data",
            data,
            "--out",
            &format!("{out}/o.csv"),
        ],
        vec!["discover", "--gyro", "fog", "--data", data, "--out", out],
        vec!["record", "--from", &raw, "--reference", data, "--out", out],
    ]
    .iter()
    .map(|c| c.iter().map(|s| s.to_string()).collect())
    .collect()
}

/// A row with one cell too many (or too few) would shift the columns after
/// it: every command refuses it at its line, exit 2, one line.
#[test]
fn every_command_refuses_a_row_with_a_wrong_cell_count() {
    let rows = run_rows(400);
    let mut lines: Vec<&str> = rows.lines().collect();
    let extra = format!("{},7", lines[9]);
    let short = lines[20].rsplit_once(',').unwrap().0.to_string();
    lines[9] = &extra;
    let with_extra = format!("# a comment\n{RUN_HEADER}{}\n", lines.join("\n"));
    lines[9] = rows.lines().nth(9).unwrap();
    lines[20] = &short;
    let with_short = format!("{RUN_HEADER}{}\n", lines.join("\n"));
    let out = std::env::temp_dir().join(format!("gyro-lab-width-{}", std::process::id()));
    let out = out.display().to_string();
    // The extra cell on file line 12 (comment, header, then row 10), as
    // field 8; the short row on line 22, its field 7 missing.
    for (name, text, pos) in [
        ("extra.csv", with_extra, ":12:8"),
        ("short_row.csv", with_short, ":22:7"),
    ] {
        let p = write(name, &text);
        for cmd in commands(&p, &out) {
            let args: Vec<&str> = cmd.iter().map(String::as_str).collect();
            let (code, err) = lab(&args);
            assert_eq!(code, 2, "{args:?}: {err}");
            assert_eq!(err.trim_end().lines().count(), 1, "{args:?}: {err}");
            assert!(err.contains(&format!("{p}{pos}")), "{args:?}: {err}");
            assert!(err.contains("where the header has 7"), "{args:?}: {err}");
        }
    }
}

/// A missing column is placed at the header's line, after the comments.
#[test]
fn a_missing_column_names_the_header_line() {
    let text = format!(
        "# comment 1\n# comment 2\n\n{}{}",
        RUN_HEADER.replace("rate_dps,temp_c", "rate_x,temp_c"),
        run_rows(400)
    );
    let p = write("nocol.csv", &text);
    let out = std::env::temp_dir().join(format!("gyro-lab-nocol-{}", std::process::id()));
    let out = out.display().to_string();
    // Every command but `record`, whose reference needs no `rate_dps`.
    for cmd in commands(&p, &out).into_iter().take(5) {
        let args: Vec<&str> = cmd.iter().map(String::as_str).collect();
        let (code, err) = lab(&args);
        assert_eq!(code, 2, "{args:?}: {err}");
        assert!(err.contains(&format!("{p}:4")), "{args:?}: {err}");
        assert!(err.contains("missing column `rate_dps`"), "{args:?}: {err}");
    }
}

/// A finite value no gyro, table or sensor gives (1e300 deg/s, 5000 degC)
/// is refused at its cell: summed, it would turn every answer into
/// infinity or nothing.
#[test]
fn values_no_instrument_gives_are_refused_at_their_cell() {
    let rows = run_rows(400);
    let mut lines: Vec<&str> = rows.lines().collect();
    lines[30] = "30,0.0041781,1e300,20.3,20.3,20.4,20.3";
    let huge = write("huge.csv", &format!("{RUN_HEADER}{}\n", lines.join("\n")));
    let out = std::env::temp_dir().join(format!("gyro-lab-huge-{}", std::process::id()));
    let out = out.display().to_string();
    for cmd in commands(&huge, &out).into_iter().take(5) {
        let args: Vec<&str> = cmd.iter().map(String::as_str).collect();
        let (code, err) = lab(&args);
        assert_eq!(code, 2, "{args:?}: {err}");
        assert!(err.contains(&format!("{huge}:32:3")), "{args:?}: {err}");
        assert!(err.contains("outside the rates"), "{args:?}: {err}");
    }
}
