//! `gyro-lab bench`: the benches of bench/ (the estimators against the
//! simulators' truth, over seeds), their tables on the terminal and their
//! JSON line.

use crate::bench::allan::{
    against_definition, recovery, speed_record, Recovery, SAMPLES, SCENARIOS, SPEED_TAU0_S, TAU0_S,
};
use crate::bench::discover_summary::summarize;
use crate::bench::discover_trials::{run_all, trials, TrialCounts};
use crate::bench::lockin::{table, RECORDS};
use crate::bench::scale_factor::{self, ScaleFactorBench};
use crate::cli::args::{Json, Seed};
use crate::cli::output::{print_json, progress_bar};
use crate::data::csv_writer::CellFormat::{Exp, Fixed};
use crate::data::run_file::{Column, RunWriter, Series};
use crate::error::LabError;
use crate::noise::analysis::analyse;
use crate::noise::terms::{COUNT, NAMES, UNITS};
use crate::sim::scale_factor_rig::RigParams;
use clap::{Args, Subcommand};

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
    Discover(DiscoverBenchArgs),
    /// The recorder on a ten-minute capture: the CPU it needs at the board's rate.
    Record(crate::cli::bench_record::RecordBenchArgs),
    /// The online eps^2 correction over the vibration envelope: the table of issue 23.
    Eps2(crate::cli::bench_eps2::Eps2BenchArgs),
}

pub fn run(cmd: &BenchCmd) -> Result<(), LabError> {
    match cmd {
        BenchCmd::Lockin(a) => lockin(a),
        BenchCmd::ScaleFactor(a) => scale_factor(a),
        BenchCmd::Allan(a) => allan(a),
        BenchCmd::AllanSpeed(a) => allan_speed(a),
        BenchCmd::Discover(a) => discover(a),
        BenchCmd::Record(a) => crate::cli::bench_record::run(a),
        BenchCmd::Eps2(a) => crate::cli::bench_eps2::run_bench(a),
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
}

#[derive(Args, Debug, Clone)]
pub struct AllanBenchArgs {
    #[arg(long, default_value_t = 100)]
    pub seeds: u64,
    #[command(flatten)]
    pub json: Json,
}

/// Short names of the noise terms for the table's columns.
const SHORT: [&str; COUNT] = ["Q", "N", "B", "K", "R"];

fn allan(a: &AllanBenchArgs) -> Result<(), LabError> {
    if a.seeds == 0 || a.seeds > 10_000 {
        return Err(LabError::Usage(format!("--seeds {}: 1..=10000", a.seeds)));
    }
    let bar = progress_bar(
        a.seeds * SCENARIOS.len() as u64,
        "{bar:40} {pos}/{len} records {eta}",
        a.json.json,
    );
    let r = recovery(a.seeds, || bar.inc(1)).map_err(|e| LabError::Bench(e.to_string()))?;
    bar.finish_and_clear();
    let n = a.seeds;
    if !a.json.json {
        print_allan(&r, n);
    }
    println!(
        "{}",
        serde_json::json!({
            "seeds": n, "samples": SAMPLES, "tau0_s": TAU0_S, "terms": NAMES,
            "rows": r.rows, "recovered": r.recovered, "recovered_of": r.recovered_of,
            "false_reports": r.false_reports, "false_reports_of": r.false_reports_of
        })
    );
    Ok(())
}

fn print_allan(r: &Recovery, n: u64) {
    println!(
        "Allan terms from the project's generators: {} samples at {} s, {n} seeds per scenario; 95 % intervals",
        SAMPLES, TAU0_S
    );
    println!("cells: truth -> seeds whose interval holds it / mean value; absent terms: seeds that reported them");
    print!("{:<32}", "scenario");
    for j in 0..COUNT {
        print!(" {:>24}", format!("{} ({})", SHORT[j], UNITS[j]));
    }
    println!();
    for (row, sc) in r.rows.iter().zip(SCENARIOS) {
        print!("{:<32}", row.scenario);
        for j in 0..COUNT {
            let cell = match (row.recovered[j], row.false_reports[j]) {
                (Some(c), _) => format!(
                    "{} -> {c}/{n} {:.3}",
                    sc.truth[j],
                    row.mean_value[j].unwrap_or(f64::NAN)
                ),
                (_, Some(c)) => format!("absent: {c}/{n}"),
                _ => "-".into(),
            };
            print!(" {cell:>24}");
        }
        println!();
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
    let series = Series::read(&path, Column::Rate.name())?;
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

#[derive(Args, Debug, Clone)]
pub struct DiscoverBenchArgs {
    /// Trials per effect of the library (12 effects).
    #[arg(long, default_value_t = 18)]
    pub per_effect: u64,
    /// Trials with nothing missing, with two effects, with collinear ones.
    #[arg(long, default_value_t = 24)]
    pub nothing: u64,
    #[arg(long, default_value_t = 12)]
    pub pairs: u64,
    #[arg(long, default_value_t = 12)]
    pub collinear: u64,
    #[command(flatten)]
    pub seed: Seed,
    #[command(flatten)]
    pub json: Json,
}

fn discover(a: &DiscoverBenchArgs) -> Result<(), LabError> {
    let list = trials(&TrialCounts {
        per_effect: a.per_effect,
        nothing: a.nothing,
        pairs: a.pairs,
        collinear: a.collinear,
        seed: a.seed.seed,
    });
    let bar = progress_bar(
        list.len() as u64,
        "{bar:40} {pos}/{len} trials {eta}",
        a.json.json,
    );
    let outcomes = run_all(&list, || bar.inc(1));
    bar.finish_and_clear();
    let s = summarize(&outcomes);
    if !a.json.json {
        println!("discovery on {} randomized trials (hidden effect, drawn parameters and seed; nominal noise)", outcomes.len());
        for (row, cols) in &s.confusion {
            let cells: Vec<String> = cols
                .iter()
                .filter(|(k, _)| *k != "trials")
                .map(|(k, v)| format!("{k} {v}"))
                .collect();
            println!(
                "  {:<52} {:>3} trials: {}",
                row,
                cols.get("trials").copied().unwrap_or(0),
                cells.join(", ")
            );
        }
        println!(
            "single hidden effect named right: {}/{} ({:.1} %); with every parameter within 10 %: {}; the gap to reality shrunk 80 %: {}",
            s.single_named_right,
            s.single,
            100.0 * s.single_named_right as f64 / s.single.max(1) as f64,
            s.single_params_ok,
            s.single_gap_ok
        );
        println!(
            "a false effect named: {}/{} ({:.1} %) of the randomized trials; nothing missing and nothing named: {}/{}; both of two hidden found: {}/{}; collinear reported ambiguous: {}/{}",
            s.false_effect_named,
            s.randomized,
            100.0 * s.false_effect_named as f64 / s.randomized.max(1) as f64,
            s.nothing_missing_clean,
            a.nothing,
            s.two_hidden_both_found,
            a.pairs,
            s.collinear_ambiguous,
            a.collinear
        );
    }
    println!(
        "{}",
        serde_json::json!({
            "trials": outcomes.len(),
            "single": s.single,
            "single_named_right": s.single_named_right,
            "single_params_ok": s.single_params_ok,
            "single_gap_ok": s.single_gap_ok,
            "randomized": s.randomized,
            "false_effect_named": s.false_effect_named,
            "nothing_missing_clean": s.nothing_missing_clean,
            "two_hidden_both_found": s.two_hidden_both_found,
            "collinear_ambiguous": s.collinear_ambiguous,
            "confusion": s.confusion,
            "outcomes": outcomes,
        })
    );
    Ok(())
}
