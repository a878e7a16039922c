//! `gyro-lab bench allan`: recovery of known noise terms from the project's
//! own generators (`gyro_sim::noise`) over seeds, each term alone and
//! in combinations; `gyro-lab bench allan-speed`: the time for 10^7
//! samples against the O(N m) definition on 10^5.

use super::terms::{self, COUNT, NAMES, UNITS};
use super::{adev, analyse};
use crate::data::csv_writer::CellFormat::{Exp, Fixed};
use crate::data::run_file::{Column, RunWriter, Series as RunSeries};
use crate::error::LabError;
use clap::Args;
use gyro_sim::{NoiseParams, RateNoise};
use indicatif::{ProgressBar, ProgressStyle};

/// A record of known terms: (Q arcsec, N deg/sqrt(h), B deg/h, K
/// deg/h/sqrt(h), R deg/h^2), zero where absent.
#[derive(Clone, Copy, Debug)]
pub struct Scenario {
    pub name: &'static str,
    pub truth: [f64; COUNT],
}

/// 1 s samples, 2e5 of them (55 h): each term of a scenario dominates the
/// curve over at least a decade and a half of averaging time (a term seen
/// over less is honestly often reported absent).
pub const TAU0_S: f64 = 1.0;
pub const SAMPLES: usize = 200_000;

pub const SCENARIOS: [Scenario; 9] = [
    Scenario {
        name: "white",
        truth: [0.0, 0.05, 0.0, 0.0, 0.0],
    },
    Scenario {
        name: "flicker",
        truth: [0.0, 0.0, 0.1, 0.0, 0.0],
    },
    Scenario {
        name: "random walk",
        truth: [0.0, 0.0, 0.0, 0.5, 0.0],
    },
    Scenario {
        name: "quantization + white",
        truth: [20.0, 0.1, 0.0, 0.0, 0.0],
    },
    Scenario {
        name: "white + ramp",
        truth: [0.0, 0.05, 0.0, 0.0, 0.5],
    },
    Scenario {
        name: "white + flicker",
        truth: [0.0, 0.02, 0.1, 0.0, 0.0],
    },
    Scenario {
        name: "white + random walk",
        truth: [0.0, 0.05, 0.0, 0.5, 0.0],
    },
    Scenario {
        name: "white + flicker + random walk",
        truth: [0.0, 0.006, 0.1, 0.2, 0.0],
    },
    Scenario {
        name: "quantization + white + flicker",
        truth: [20.0, 0.1, 0.5, 0.0, 0.0],
    },
];

/// The generator's parameters for a scenario (rate in deg/s).
pub fn noise_params(truth: &[f64; COUNT], record_s: f64) -> NoiseParams {
    NoiseParams {
        q_deg: truth[0] / 3600.0,
        n_dps_rts: NoiseParams::arw_from_dpsh(truth[1]),
        b_dps: NoiseParams::b_from_dph(truth[2]),
        k_dps_rts: NoiseParams::k_from_dphsh(truth[3]),
        r_dps2: truth[4] / 3600.0 / 3600.0,
        flicker_max_tau_s: 10.0 * record_s,
    }
}

pub fn record(truth: &[f64; COUNT], n: usize, tau0: f64, seed: u64) -> Vec<f64> {
    let mut g = RateNoise::new(noise_params(truth, n as f64 * tau0), tau0, seed);
    (0..n).map(|_| g.sample()).collect()
}

#[derive(Args, Debug, Clone)]
pub struct AllanBenchArgs {
    #[arg(long, default_value_t = 100)]
    pub seeds: u64,
    #[arg(long)]
    pub json: bool,
}

#[derive(serde::Serialize, Default, Clone)]
struct Row {
    scenario: &'static str,
    /// Per term: seeds where it was reported and its interval held the
    /// truth (present terms), or where it was reported (absent terms).
    recovered: [Option<u64>; COUNT],
    false_reports: [Option<u64>; COUNT],
    /// Mean of the reported value over the seeds that reported it.
    mean_value: [Option<f64>; COUNT],
}

pub fn run(a: &AllanBenchArgs) -> Result<(), LabError> {
    if a.seeds == 0 || a.seeds > 10_000 {
        return Err(LabError::Usage(format!("--seeds {}: 1..=10000", a.seeds)));
    }
    let bar = if a.json {
        ProgressBar::hidden()
    } else {
        let b = ProgressBar::new(a.seeds * SCENARIOS.len() as u64);
        b.set_style(
            ProgressStyle::with_template("{bar:40} {pos}/{len} records {eta}")
                .unwrap_or(ProgressStyle::default_bar()),
        );
        b
    };
    let mut rows = vec![];
    for sc in SCENARIOS {
        let mut row = Row {
            scenario: sc.name,
            ..Row::default()
        };
        let mut sums = [0.0; COUNT];
        for j in 0..COUNT {
            if sc.truth[j] > 0.0 {
                row.recovered[j] = Some(0);
            } else {
                row.false_reports[j] = Some(0);
            }
        }
        for seed in 1..=a.seeds {
            let y = record(&sc.truth, SAMPLES, TAU0_S, seed);
            let an = analyse(&y, TAU0_S).map_err(|e| LabError::Bench(e.to_string()))?;
            for j in 0..COUNT {
                let t = &an.terms;
                if !t.present[j] {
                    continue;
                }
                let (v, lo, hi) = (
                    terms::to_units(j, t.c[j]),
                    terms::to_units(j, t.lo[j]),
                    terms::to_units(j, t.hi[j]),
                );
                if sc.truth[j] > 0.0 {
                    sums[j] += v;
                    if lo <= sc.truth[j] && sc.truth[j] <= hi {
                        row.recovered[j] = row.recovered[j].map(|c| c + 1);
                    }
                } else {
                    row.false_reports[j] = row.false_reports[j].map(|c| c + 1);
                }
            }
            bar.inc(1);
        }
        for j in 0..COUNT {
            if sc.truth[j] > 0.0 {
                row.mean_value[j] = Some(sums[j] / a.seeds as f64);
            }
        }
        rows.push(row);
    }
    bar.finish_and_clear();
    let n = a.seeds;
    let (mut rec, mut rec_n, mut fp, mut fp_n) = (0, 0, 0, 0);
    for r in &rows {
        for j in 0..COUNT {
            if let Some(c) = r.recovered[j] {
                rec += c;
                rec_n += n;
            }
            if let Some(c) = r.false_reports[j] {
                fp += c;
                fp_n += n;
            }
        }
    }
    if !a.json {
        println!(
            "Allan terms from the project's generators: {} samples at {} s, {n} seeds per scenario; 95 % intervals",
            SAMPLES, TAU0_S
        );
        println!("cells: truth -> seeds whose interval holds it / mean value; absent terms: seeds that reported them");
        print!("{:<32}", "scenario");
        for j in 0..COUNT {
            print!(" {:>24}", format!("{} ({})", short(j), UNITS[j]));
        }
        println!();
        for (r, sc) in rows.iter().zip(SCENARIOS) {
            print!("{:<32}", r.scenario);
            for j in 0..COUNT {
                let cell = match (r.recovered[j], r.false_reports[j]) {
                    (Some(c), _) => format!(
                        "{} -> {c}/{n} {:.3}",
                        sc.truth[j],
                        r.mean_value[j].unwrap_or(f64::NAN)
                    ),
                    (_, Some(c)) => format!("absent: {c}/{n}"),
                    _ => "-".into(),
                };
                print!(" {cell:>24}");
            }
            println!();
        }
        println!(
            "present terms recovered within their interval: {rec}/{rec_n} ({:.1} %); absent terms reported: {fp}/{fp_n} ({:.1} %)",
            100.0 * rec as f64 / rec_n.max(1) as f64,
            100.0 * fp as f64 / fp_n.max(1) as f64
        );
    }
    println!(
        "{}",
        serde_json::json!({
            "seeds": n, "samples": SAMPLES, "tau0_s": TAU0_S, "terms": NAMES,
            "rows": rows, "recovered": rec, "recovered_of": rec_n, "false_reports": fp, "false_reports_of": fp_n
        })
    );
    Ok(())
}

fn short(j: usize) -> &'static str {
    ["Q", "N", "B", "K", "R"][j]
}

#[derive(Args, Debug, Clone)]
pub struct SpeedArgs {
    /// Samples of the long record.
    #[arg(long, default_value_t = 10_000_000)]
    pub samples: usize,
    #[arg(long)]
    pub json: bool,
}

/// Times the analysis of a long record (10^7 samples at 100 Hz, 28 h:
/// white, flicker and random walk), the CSV read of that record, and the
/// O(N m) definition on 10^5 samples against the fast estimator there.
pub fn speed(a: &SpeedArgs) -> Result<(), LabError> {
    let n = a.samples.max(1000);
    let tau0 = 0.01;
    let truth = [0.0, 0.1, 0.05, 0.02, 0.0];
    let y = record(&truth, n, tau0, 1);
    let t0 = std::time::Instant::now();
    let an = analyse(&y, tau0).map_err(|e| LabError::Bench(e.to_string()))?;
    let fast_s = t0.elapsed().as_secs_f64();
    // The CSV read of the same record.
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
    let series = RunSeries::read(&path, Column::Rate.name())?;
    let read_s = t1.elapsed().as_secs_f64();
    let _ = std::fs::remove_dir_all(&dir);
    if series.values.len() != n {
        return Err(LabError::Io {
            file: None,
            msg: format!("read {} rows of {n}", series.values.len()),
        });
    }
    // The definition on 10^5 samples, at the same averaging factors the
    // fast estimator uses there, and the fast one on the same record.
    let small = &y[..100_000.min(n)];
    let ms = adev::averaging_factors(small.len(), super::PER_DECADE);
    let t2 = std::time::Instant::now();
    let reference = adev::oavar_reference(small, &ms);
    let ref_s = t2.elapsed().as_secs_f64();
    let t3 = std::time::Instant::now();
    let fast = adev::oavar(small, &ms);
    let fast_small_s = t3.elapsed().as_secs_f64();
    let worst = reference
        .iter()
        .zip(&fast)
        .map(|(r, f)| (r - f).abs() / r)
        .fold(0.0, f64::max);
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
    if !a.json {
        println!(
            "{n} samples: Allan deviation and terms in {fast_s:.3} s; CSV read {read_s:.3} s; the O(N m) definition on \
             1e5 samples {ref_s:.2} s (fast estimator there {fast_small_s:.4} s, largest relative difference {worst:.1e})"
        );
    }
    println!("{j}");
    Ok(())
}
