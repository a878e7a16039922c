//! `gyro-lab bench`: the benches of bench/ (the estimators against the
//! simulators' truth, over seeds), their tables on the terminal and their
//! JSON line.

use crate::cli::args::Json;
use crate::cli::output::{print_json, progress_bar};
use clap::{Args, Subcommand};
use gyro_lab_core::bench::allan::{
    against_definition, judge, recovery, speed_record, truth_present, Recovery, Scenario,
    Selection, SAMPLES, SCENARIOS, SHORT, SPEED_TAU0_S, TAU0_S,
};
use gyro_lab_core::bench::lockin::{table, RECORDS};
use gyro_lab_core::bench::scale_factor::{self, ScaleFactorBench};
use gyro_lab_core::data::csv_writer::CellFormat::{Exp, Fixed};
use gyro_lab_core::data::run_file::{Column, RunWriter, Series};
use gyro_lab_core::data::source::Source;
use gyro_lab_core::error::LabError;
use gyro_lab_core::noise::analysis::{analyse, Allan};
use gyro_lab_core::noise::terms::{
    to_units, ALL, COUNT, MARKOV, MARKOV_NAME, NAMES, SIN, SIN_NAME, UNITS,
};
use gyro_lab_core::sim::scale_factor_rig::RigParams;

#[derive(Subcommand)]
pub enum BenchCmd {
    /// Lock-in: exact harmonic relation next to the published approximate formula.
    Lockin(LockinBenchArgs),
    /// FOG scale factor: raw, classic multi-point and continuous rotation on one simulated gyro.
    ScaleFactor(ScaleFactorBenchArgs),
    /// Allan terms recovered from the project's noise generators, over seeds.
    Allan(AllanBenchArgs),
    /// Allan analysis time on 10^7 samples against the O(N m) definition.
    AllanSpeed(SpeedArgs),
    /// Discovery on randomized runs with hidden effects: the confusion table.
    Discover(crate::cli::discover::bench::DiscoverBenchArgs),
    /// The recorder on a ten-minute capture: the CPU it needs at the board's rate.
    Record(crate::cli::bench_record::RecordBenchArgs),
    /// The online eps^2 correction over the vibration envelope: the table of issue 23.
    Eps2(crate::cli::bench_eps2::Eps2BenchArgs),
    /// The dithered RLG through the firmware's stripping: ARW against the physics, rate error through the lock-in zones.
    Dither(crate::cli::bench_dither::DitherBenchArgs),
}

pub fn run(cmd: &BenchCmd) -> Result<(), LabError> {
    match cmd {
        BenchCmd::Lockin(a) => lockin(a),
        BenchCmd::ScaleFactor(a) => scale_factor(a),
        BenchCmd::Allan(a) => allan(a),
        BenchCmd::AllanSpeed(a) => allan_speed(a),
        BenchCmd::Discover(a) => crate::cli::discover::bench::discover(a),
        BenchCmd::Record(a) => crate::cli::bench_record::run(a),
        BenchCmd::Eps2(a) => crate::cli::bench_eps2::run_bench(a),
        BenchCmd::Dither(a) => crate::cli::bench_dither::run_bench(a),
    }
}

#[derive(Args, Debug, Clone)]
pub struct LockinBenchArgs {
    /// Simulated records per ratio and record kind.
    #[arg(long, default_value_t = 8)]
    pub seeds: u64,
    #[command(flatten)]
    pub json: Json,
}

fn lockin(a: &LockinBenchArgs) -> Result<(), LabError> {
    if a.seeds == 0 || a.seeds > 1000 {
        return Err(LabError::Usage(format!("--seeds {}: 1..1000", a.seeds)));
    }
    let mut out = serde_json::Map::new();
    for (key, rec, title) in RECORDS {
        let rows = table(rec, a.seeds);
        if !a.json.json {
            println!(
                "lock-in, {title}, K = 2000 /deg, Omega_I = 1 deg/s, {} records each",
                a.seeds
            );
            println!(
                "{:>8} {:>10} | {:>10} {:>10} {:>10} | {:>10} {:>10} {:>10} | {:>12} {:>11}",
                "OI/OL",
                "OL deg/s",
                "S rms%",
                "S max%",
                "S 1sig%",
                "S+Q rms%",
                "S+Q max%",
                "S+Q 1sig%",
                "approx mean%",
                "approx max%"
            );
            for r in &rows {
                println!(
                    "{:>8.0} {:>10.4} | {:>10.3} {:>10.3} {:>10.3} | {:>10.3} {:>10.3} {:>10.3} | {:>12.2} {:>11.2}",
                    r.ratio,
                    r.lock_in_dps,
                    r.exact_rms_pct,
                    r.exact_max_pct,
                    r.exact_std_pct,
                    r.pair_rms_pct,
                    r.pair_max_pct,
                    r.pair_std_pct,
                    r.approx_mean_pct,
                    r.approx_max_pct
                );
            }
        }
        let rows = serde_json::to_value(&rows).map_err(|e| LabError::Io {
            file: None,
            msg: e.to_string(),
        })?;
        out.insert(key.into(), rows);
    }
    println!("{}", serde_json::Value::Object(out));
    Ok(())
}

#[derive(Args, Debug, Clone)]
pub struct ScaleFactorBenchArgs {
    /// Seeds (gyro noise and sensor noise) to average over.
    #[arg(long, default_value_t = 20)]
    pub seeds: u64,
    #[command(flatten)]
    pub json: Json,
}

fn scale_factor(a: &ScaleFactorBenchArgs) -> Result<(), LabError> {
    if a.seeds == 0 || a.seeds > 1000 {
        return Err(LabError::Usage(format!("--seeds {}: 1..=1000", a.seeds)));
    }
    let bar = progress_bar(a.seeds, "{bar:40} seed {pos}/{len} {eta}", a.json.json);
    let j = scale_factor::run(a.seeds, || bar.inc(1))
        .map_err(|e| LabError::Bench(format!("bench scale-factor: {e}")))?;
    bar.finish_and_clear();
    if !a.json.json {
        print_scale_factor(&j);
    }
    print_json(&j)
}

fn print_scale_factor(j: &ScaleFactorBench) {
    let n = j.seeds;
    let (knee_true, lag_true) = (j.knee_true_c, RigParams::default().tau_sensor_s);
    let (bracketed, one_knee) = (j.multipoint_knee_bracketed, j.continuous_one_knee);
    let (covers, lag_covers) = (j.continuous_ci_covers, j.sensor_lag_ci_covers);
    println!("FOG scale factor over temperature, {n} seeds; true knee {knee_true} degC, sensor lag {lag_true} s");
    println!("validation run: steps profile, -100 deg/s only; RMS of the scale-factor error over 60 s means");
    println!(
        "{:<34} {:>22} {:>18}",
        "calibration", "validation ppm", "knee"
    );
    println!(
        "{:<34} {:>10.2} +- {:<8.2} {:>18}",
        "raw (nominal scale factor)", j.validation_raw_ppm.mean, j.validation_raw_ppm.sd, "-"
    );
    println!(
        "{:<34} {:>10.2} +- {:<8.2} {:>18}",
        "classic multi-point (5 plateaus)",
        j.validation_multipoint_ppm.mean,
        j.validation_multipoint_ppm.sd,
        format!("bracketed {bracketed}/{n}")
    );
    println!(
        "{:<34} {:>10.3} +- {:<8.3} {:>18}",
        "continuous rotation",
        j.validation_continuous_ppm.mean,
        j.validation_continuous_ppm.sd,
        format!("found {one_knee}/{n}")
    );
    println!(
        "continuous: knee error {:.3} degC mean, {:.3} max; 95 % interval {:.2} degC wide, covers the truth in {covers}/{n}",
        j.continuous_knee_abs_err_c.mean, j.continuous_knee_abs_err_c.max, j.continuous_knee_ci_width_c.mean
    );
    println!(
        "continuous: sensor lag {:.2} +- {:.2} s (truth {}), interval covers in {lag_covers}/{n}; worst validation {:.3} ppm",
        j.sensor_lag_s.mean, j.sensor_lag_s.sd, lag_true, j.validation_continuous_ppm.max
    );
    println!(
        "no-knee gyro fitted with no knee: {}/{n}",
        j.no_knee_fitted_without_knee
    );
    print_families(j);
}

/// The model families' table: per coil, the model chosen against the
/// truth's, the knee, the curvature, the table and the validation.
fn print_families(j: &ScaleFactorBench) {
    let n = j.seeds;
    println!();
    println!(
        "model families (fit: cycle -40..+60 degC, +-100 deg/s, 0.01 deg/sqrt(h); validation: steps, -100 deg/s; RMS of 60 s means)"
    );
    let head = [
        "coil",
        "expected",
        "right",
        "chosen K/P/PK",
        "knee err degC mean/max (CI covers)",
        "top coefficient mean vs truth (CI covers)",
        "table nodes / spacing degC / max err ppm",
        "validation ppm mean +- sd (max)",
    ];
    let mut rows: Vec<Vec<String>> = vec![head.iter().map(|h| h.to_string()).collect()];
    for r in &j.families {
        let knee = if r.knee_abs_err_c.n > 0 {
            format!(
                "{:.3} / {:.3} ({}/{})",
                r.knee_abs_err_c.mean, r.knee_abs_err_c.max, r.knee_ci_covers, r.knee_abs_err_c.n
            )
        } else {
            "-".into()
        };
        let curv = if r.curvature.n > 0 {
            format!(
                "{:.3e} vs {:.1e} ({}/{})",
                r.curvature.mean, r.curvature_truth, r.curvature_ci_covers, r.curvature.n
            )
        } else {
            "-".into()
        };
        rows.push(vec![
            r.coil.to_string(),
            format!("{} {}", r.expected_model, r.expected_degree),
            format!("{}/{n}", r.right_model),
            format!("{}/{}/{}", r.chosen[0], r.chosen[1], r.chosen[2]),
            knee,
            curv,
            format!(
                "{:.0} / {:.2} / {:.3}",
                r.table_nodes.mean, r.table_spacing_c.mean, r.tabulation_ppm.max
            ),
            format!(
                "{:.3} +- {:.3} ({:.3})",
                r.validation_ppm.mean, r.validation_ppm.sd, r.validation_ppm.max
            ),
        ]);
    }
    let widths: Vec<usize> = (0..head.len())
        .map(|c| rows.iter().map(|r| r[c].len()).max().unwrap_or(0))
        .collect();
    for r in &rows {
        let cells: Vec<String> = r
            .iter()
            .zip(&widths)
            .enumerate()
            .map(|(c, (x, &w))| {
                if c < 2 {
                    format!("{x:<w$}")
                } else {
                    format!("{x:>w$}")
                }
            })
            .collect();
        println!("{}", cells.join("  "));
    }
}

#[derive(Args, Debug, Clone)]
pub struct AllanBenchArgs {
    /// Records per noise-term combination (each its own seed).
    #[arg(long, default_value_t = 100)]
    pub seeds: u64,
    /// The first seed (seeds first..first + seeds): another set of seeds
    /// checks that nothing was tuned to the default ones.
    #[arg(long, default_value_t = 1)]
    pub first_seed: u64,
    /// Only the scenarios whose name contains this.
    #[arg(long, default_value = "")]
    pub only: String,
    /// List each record where a present term's interval missed the truth.
    #[arg(long)]
    pub misses: bool,
    #[command(flatten)]
    pub json: Json,
}

fn allan(a: &AllanBenchArgs) -> Result<(), LabError> {
    if a.seeds == 0 || a.seeds > 10_000 {
        return Err(LabError::Usage(format!("--seeds {}: 1..=10000", a.seeds)));
    }
    let bar = progress_bar(
        a.seeds
            * SCENARIOS
                .iter()
                .filter(|s| s.name.contains(a.only.as_str()))
                .count() as u64,
        "{bar:40} {pos}/{len} records {eta}",
        a.json.json,
    );
    let sel = Selection {
        first_seed: a.first_seed,
        seeds: a.seeds,
        only: a.only.clone(),
    };
    let r = recovery(&sel, |sc, seed, an| {
        if a.misses {
            bar.suspend(|| print_misses(sc, seed, an));
        }
        bar.inc(1)
    })
    .map_err(|e| LabError::Bench(e.to_string()))?;
    bar.finish_and_clear();
    let n = a.seeds;
    if !a.json.json {
        print_allan(&r, n);
    }
    println!(
        "{}",
        serde_json::json!({
            "seeds": n, "first_seed": a.first_seed, "samples": SAMPLES, "tau0_s": TAU0_S,
            "terms": NAMES.iter().chain(&[SIN_NAME, MARKOV_NAME]).collect::<Vec<_>>(),
            "rows": r.rows, "recovered": r.recovered, "recovered_of": r.recovered_of,
            "false_reports": r.false_reports, "false_reports_of": r.false_reports_of
        })
    );
    Ok(())
}

/// One line per present term whose interval missed the truth.
fn print_misses(sc: &Scenario, seed: u64, an: &Allan) {
    let present = truth_present(&sc.truth);
    let t = &sc.truth;
    for (j, &(reported, held, _)) in judge(an, t).iter().enumerate() {
        if !present[j] || held {
            continue;
        }
        let tf = &an.terms;
        let what = match j {
            SIN => tf.sinusoid.map_or("not reported".into(), |s| {
                let a = s.amplitude_dps;
                let f = s.frequency_hz;
                format!(
                    "amplitude {:.3} [{:.3}, {:.3}] deg/h, f {:.6} [{:.6}, {:.6}] Hz",
                    a.value * 3600.0,
                    a.lo * 3600.0,
                    a.hi * 3600.0,
                    f.value,
                    f.lo,
                    f.hi
                )
            }),
            MARKOV => tf.correlated.map_or("not reported".into(), |m| {
                let (s, c) = (m.sigma_dph, m.tau_s);
                format!(
                    "sigma {:.4} [{:.4}, {:.4}] deg/h, T {:.2} [{:.2}, {:.2}] s",
                    s.value, s.lo, s.hi, c.value, c.lo, c.hi
                )
            }),
            j if reported => format!(
                "{:.4} [{:.4}, {:.4}]",
                to_units(j, tf.c[j]),
                to_units(j, tf.lo[j]),
                to_units(j, tf.hi[j])
            ),
            _ => "not reported".into(),
        };
        let truth = match j {
            SIN => t
                .sinusoid
                .map_or(String::new(), |(a, f)| format!("{a} deg/h at {f} Hz")),
            MARKOV => t
                .markov
                .map_or(String::new(), |(s, c)| format!("{s} deg/h, {c} s")),
            j => format!("{}", t.laws[j]),
        };
        println!(
            "miss: {} seed {seed} {}: truth {truth}; {what}; chi2/dof {:.2}{}",
            sc.name,
            SHORT[j],
            tf.goodness.chi2_per_dof,
            if tf.goodness.consistent {
                ""
            } else {
                " (inconsistent)"
            }
        );
    }
}

fn print_allan(r: &Recovery, n: u64) {
    println!(
        "Allan terms from the project's generators: {} samples at {} s, {n} seeds per scenario; 95 % intervals",
        SAMPLES, TAU0_S
    );
    println!(
        "cells: truth -> seeds whose intervals hold it / mean value (S: sinusoid amplitude deg/h and frequency; \
         M: Markov sigma deg/h and correlation time); absent terms: seeds that reported them"
    );
    let unit = |j: usize| if j < COUNT { UNITS[j] } else { "deg/h" };
    print!("{:<34}", "scenario");
    for (j, short) in SHORT.iter().enumerate().take(ALL) {
        print!(" {:>22}", format!("{short} ({})", unit(j)));
    }
    println!(" {:>10} {:>8}", "consistent", "filter");
    for row in &r.rows {
        let Some(sc) = SCENARIOS.iter().find(|s| s.name == row.scenario) else {
            continue;
        };
        print!("{:<34}", row.scenario);
        let truth = |j: usize| match j {
            SIN => sc.truth.sinusoid.map_or(0.0, |s| s.0),
            MARKOV => sc.truth.markov.map_or(0.0, |m| m.0),
            j => sc.truth.laws[j],
        };
        for j in 0..ALL {
            let cell = match (row.recovered[j], row.false_reports[j]) {
                (Some(c), _) => format!(
                    "{} -> {c}/{n} {:.3}",
                    truth(j),
                    row.mean_value[j].unwrap_or(f64::NAN)
                ),
                (_, Some(c)) => format!("absent: {c}/{n}"),
                _ => "-".into(),
            };
            print!(" {cell:>22}");
        }
        println!(
            " {:>10} {:>8}",
            format!("{}/{n}", row.consistent),
            format!("{}/{n}", row.filter_reports)
        );
    }
    let (rec, rec_n, fp, fp_n) = (
        r.recovered,
        r.recovered_of,
        r.false_reports,
        r.false_reports_of,
    );
    println!(
        "present terms recovered within their interval: {rec}/{rec_n} ({:.1} %); absent terms reported: {fp}/{fp_n} ({:.1} %)",
        100.0 * rec as f64 / rec_n.max(1) as f64,
        100.0 * fp as f64 / fp_n.max(1) as f64
    );
}

#[derive(Args, Debug, Clone)]
pub struct SpeedArgs {
    /// Samples of the long record.
    #[arg(long, default_value_t = 10_000_000)]
    pub samples: usize,
    #[command(flatten)]
    pub json: Json,
}

/// The time to read a record as the `allan` command does: written to a
/// scratch run file, read back.
fn csv_read_s(y: &[f64], tau0: f64) -> Result<f64, LabError> {
    let dir = std::env::temp_dir().join(format!("gyro-lab-allan-speed-{}", std::process::id()));
    std::fs::create_dir_all(&dir)?;
    let path = dir.join("long.csv");
    let mut w = RunWriter::create(
        &path,
        "",
        &[(Column::Time, Fixed(2)), (Column::Rate, Exp(9))],
    )?;
    for (k, v) in y.iter().enumerate() {
        w.row(&[(k + 1) as f64 * tau0, *v])?;
    }
    w.finish()?;
    let t1 = std::time::Instant::now();
    let series = Series::read(
        Source::File(&path),
        Column::Rate.name(),
        &Default::default(),
    )?;
    let read_s = t1.elapsed().as_secs_f64();
    let _ = std::fs::remove_dir_all(&dir);
    if series.values.len() != y.len() {
        return Err(LabError::Io {
            file: None,
            msg: format!("read {} rows of {}", series.values.len(), y.len()),
        });
    }
    Ok(read_s)
}

/// Times the analysis of a long record (10^7 samples at 100 Hz, 28 h:
/// white, flicker and random walk), the CSV read of that record, and the
/// O(N m) definition on 10^5 samples against the fast estimator there.
fn allan_speed(a: &SpeedArgs) -> Result<(), LabError> {
    let n = a.samples.max(1000);
    let y = speed_record(n);
    let t0 = std::time::Instant::now();
    let an = analyse(&y, SPEED_TAU0_S).map_err(|e| LabError::Bench(e.to_string()))?;
    let fast_s = t0.elapsed().as_secs_f64();
    let read_s = csv_read_s(&y, SPEED_TAU0_S)?;
    let def = against_definition(&y);
    let (ref_s, fast_small_s, worst) = (def.reference_s, def.fast_s, def.max_rel_diff);
    let j = serde_json::json!({
        "allan_1e7_s": fast_s,
        "allan_read_1e7_s": read_s,
        "allan_reference_1e5_s": ref_s,
        "allan_fast_1e5_s": fast_small_s,
        "allan_speedup_vs_reference_1e5": ref_s / fast_small_s.max(1e-9),
        "allan_1e7_vs_reference_1e5": fast_s / ref_s.max(1e-9),
        "allan_reference_max_rel_diff": worst,
        "samples": n,
        "taus": an.taus.len(),
    });
    if !a.json.json {
        println!(
            "{n} samples: Allan deviation and terms in {fast_s:.3} s; CSV read {read_s:.3} s; the O(N m) definition on \
             1e5 samples {ref_s:.2} s (fast estimator there {fast_small_s:.4} s, largest relative difference {worst:.1e})"
        );
    }
    println!("{j}");
    Ok(())
}
