//! `gyro-lab bench eps2`: the eps^2 correction over the vibration envelope
//! (bench/eps2.rs), one row per point, then the JSON line.

use crate::cli::args::Json;
use crate::cli::output::{print_json, progress_bar};
use clap::Args;
use gyro_lab_core::bench::eps2::{envelope, run, summarize, Eps2Plan, Eps2Progress, Eps2Row};
use gyro_lab_core::error::LabError;
use std::sync::Mutex;

#[derive(Args, Debug, Clone)]
pub struct Eps2BenchArgs {
    /// Standard error of the share left to average each point to (a
    /// quarter of the 1 % it is judged against).
    #[arg(long, default_value_t = 0.0025)]
    pub se: f64,
    /// Simulated seconds per point at most.
    #[arg(long, default_value_t = 100_000.0)]
    pub max_s: f64,
    /// Peak angular accelerations to run, deg/s^2 (default: the envelope's).
    #[arg(long, value_delimiter = ',')]
    pub eps_dps2: Vec<f64>,
    /// Oscillation frequencies to run, Hz (default: the envelope's).
    #[arg(long, value_delimiter = ',')]
    pub hz: Vec<f64>,
    /// DAC latencies to run, closures (default: 0 and 1).
    #[arg(long, value_delimiter = ',')]
    pub dac_latency: Vec<u32>,
    /// Instruments to run by phi0 in eighths of pi: 6 (3pi/4 at 12.5 kHz),
    /// 7 (7pi/8 at 6.25 kHz) (default: both).
    #[arg(long, value_delimiter = ',')]
    pub phi0_eighths: Vec<u32>,
    /// Threads (default: the cores available).
    #[arg(long)]
    pub threads: Option<usize>,
    /// Seed of the detector noise (the vibrating rig and its twin at rest
    /// draw the same; another seed is an independent measurement).
    #[arg(long, default_value_t = gyro_sim::vibration_drift::EPS2_NOISE_SEED)]
    pub seed: u64,
    #[command(flatten)]
    pub json: Json,
}

fn keep<T: PartialEq>(list: &[T], v: T) -> bool {
    list.is_empty() || list.contains(&v)
}

fn label(r: &Eps2Row) -> String {
    let s = r.spec;
    format!(
        "{:.0}pi/8 {:>5.0} Hz L{} {:>3.0} Hz {:>6.0}",
        s.phi0_eighths(),
        s.closure_hz,
        s.dac_latency,
        s.freq_hz,
        s.eps_dps2
    )
}

fn row_line(r: &Eps2Row) -> String {
    format!(
        "{:<34} {:>12.6} {:>12.6} {:>12.7} {:>+8.3} {:>6.3} {:>8.5} {:>8.0}{}",
        label(r),
        r.uncorrected_dph,
        r.formula_dph,
        r.corrected_dph,
        r.share_left * 100.0,
        r.share_left_se * 100.0,
        r.loop_gain,
        r.seconds,
        if r.converged { "" } else { " (time limit)" }
    )
}

pub fn run_bench(a: &Eps2BenchArgs) -> Result<(), LabError> {
    if !(a.se.is_finite() && a.se > 0.0 && a.se <= 1.0) {
        return Err(LabError::Usage(format!("--se {}: 0 < se <= 1", a.se)));
    }
    if !(a.max_s.is_finite() && a.max_s > 0.0 && a.max_s <= 1e6) {
        return Err(LabError::Usage(format!(
            "--max-s {}: 0 < s <= 1e6",
            a.max_s
        )));
    }
    let points: Vec<_> = envelope()
        .into_iter()
        .filter(|p| {
            keep(&a.eps_dps2, p.eps_dps2)
                && keep(&a.hz, p.freq_hz)
                && keep(&a.dac_latency, p.dac_latency)
                && keep(&a.phi0_eighths, p.phi0_eighths().round() as u32)
        })
        .collect();
    if points.is_empty() {
        return Err(LabError::Usage(
            "no point of the envelope matches --eps-dps2/--hz/--dac-latency/--phi0-eighths \
             (1000,5000,20000,50000; 20,60,200; 0,1; 6,7)"
                .into(),
        ));
    }
    let threads = a
        .threads
        .unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |p| p.get()))
        .clamp(1, 64);
    let bar = progress_bar(
        points.len() as u64,
        "{bar:40} {pos}/{len} points {elapsed_precise} {msg}",
        a.json.json,
    );
    let header = format!(
        "{:<34} {:>12} {:>12} {:>12} {:>8} {:>6} {:>8} {:>8}",
        "point (phi0 closure latency f eps)",
        "uncorr deg/h",
        "formula",
        "corrected",
        "left %",
        "SE %",
        "gain",
        "sim s"
    );
    if !a.json.json {
        println!("eps^2 correction over the envelope: {} points, each to a standard error of {:.3} % of the formula (at most {} simulated s), {threads} threads", points.len(), a.se * 100.0, a.max_s);
        if bar.is_hidden() {
            println!("{header}");
        } else {
            bar.println(&header);
        }
    }
    let running = Mutex::new(std::collections::BTreeMap::new());
    let progress = |p: Eps2Progress| match p {
        Eps2Progress::Done(i, r) => {
            // A hidden bar (stderr not a terminal) prints nothing itself.
            if !a.json.json {
                if bar.is_hidden() {
                    println!("{}", row_line(&r));
                } else {
                    bar.println(row_line(&r));
                }
            }
            if let Ok(mut m) = running.lock() {
                m.remove(&i);
            }
            bar.inc(1);
        }
        Eps2Progress::Running {
            index,
            share_left_se,
            seconds,
        } => {
            if let Ok(mut m) = running.lock() {
                m.insert(index, (share_left_se, seconds));
                let msg: Vec<String> = m
                    .iter()
                    .map(|(i, (se, s))| format!("#{i}: SE {:.3} % at {s:.0} s", se * 100.0))
                    .collect();
                bar.set_message(msg.join(", "));
            }
        }
    };
    let plan = Eps2Plan {
        se_target: a.se,
        max_seconds: a.max_s,
        threads,
        seed: a.seed,
    };
    let rows = run(&points, plan, &progress)
        .map_err(|e| LabError::Bench(format!("bench eps2: loop configuration {e:?}")))?;
    bar.finish_and_clear();
    let s = summarize(&rows);
    if !a.json.json {
        println!("in the envelope's order:");
        println!("{header}");
        for r in &rows {
            println!("{}", row_line(r));
        }
        println!(
            "worst share left {:+.3} % +- {:.3} %; {} of {} points above 1 %; worst loop-gain error {:.3} %; {} points stopped at the time limit",
            s.worst_share_left * 100.0,
            s.worst_share_left_se * 100.0,
            s.points_over_1pct,
            s.points,
            s.worst_gain_error * 100.0,
            s.not_converged
        );
    }
    print_json(&serde_json::json!({
        "eps2_points": s.points,
        "eps2_worst_share_left": s.worst_share_left,
        "eps2_worst_share_left_se": s.worst_share_left_se,
        "eps2_points_over_1pct": s.points_over_1pct,
        "eps2_worst_gain_error": s.worst_gain_error,
        "eps2_not_converged": s.not_converged,
        "se_target": a.se,
        "rows": rows,
    }))
}
