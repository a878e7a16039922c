//! `gyro-lab bench dither`: the dithered RLG through the firmware's
//! stripping against the physics (bench/dither.rs): the ARW table on random
//! draws across the acceptance ranges, the rate error through the static
//! band and the dynamic lock-in zones; then the JSON line.

use crate::cli::args::Json;
use crate::cli::output::{print_json, progress_bar};
use clap::Args;
use gyro_lab_core::bench::dither::{
    arw_plan, arw_row, rate_plan, rate_row, run_all, ArwRow, RateRow,
};
use gyro_lab_core::error::LabError;

#[derive(Args, Debug, Clone)]
pub struct DitherBenchArgs {
    /// Random draws across the acceptance ranges for the ARW table.
    #[arg(long, default_value_t = 24)]
    pub points: usize,
    /// Simulated seconds per ARW point.
    #[arg(long, default_value_t = 300.0)]
    pub duration_s: f64,
    /// Seed of the draws (and, from it, each point's own).
    #[arg(long, default_value_t = 33)]
    pub seed: u64,
    /// Amplitude noise fractions of the rate sweep (0: none).
    #[arg(long, value_delimiter = ',', default_values_t = vec![0.0, 0.02, 0.05])]
    pub rate_noise: Vec<f64>,
    /// Simulated seconds per point of the rate sweep.
    #[arg(long, default_value_t = 20.0)]
    pub rate_duration_s: f64,
    /// Leave the rate sweep out.
    #[arg(long)]
    pub no_rate_sweep: bool,
    /// Threads (default: the cores available).
    #[arg(long)]
    pub threads: Option<usize>,
    #[command(flatten)]
    pub json: Json,
}

#[derive(serde::Serialize)]
struct Summary {
    points: usize,
    within_20pct: usize,
    worst_ratio: Option<f64>,
    ratio_mean: Option<f64>,
    ratio_rms_dev: Option<f64>,
    covered_95: usize,
    residual_counts_rms_max: f64,
    mean_error_within_3_se: usize,
    rate_points_within_3_se_of_prediction: usize,
    rate_points: usize,
}

#[derive(serde::Serialize)]
struct Out {
    arw: Vec<ArwRow>,
    rate: Vec<RateRow>,
    summary: Summary,
}

fn opt(v: Option<f64>, p: usize) -> String {
    v.map_or("-".into(), |v| format!("{v:.p$}"))
}

pub fn run_bench(a: &DitherBenchArgs) -> Result<(), LabError> {
    if a.points > 10_000 || !(a.duration_s >= 10.0 && a.duration_s <= 1e5) {
        return Err(LabError::Usage(
            "--points at most 10000, --duration-s 10..1e5".into(),
        ));
    }
    if !(a.rate_duration_s >= 5.0 && a.rate_duration_s <= 1e5)
        || a.rate_noise.iter().any(|n| !(0.0..=0.2).contains(n))
    {
        return Err(LabError::Usage(
            "--rate-duration-s 5..1e5, --rate-noise within 0..0.2".into(),
        ));
    }
    let threads = a
        .threads
        .unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |p| p.get()));
    let arw_jobs = arw_plan(a.points, a.seed, a.duration_s);
    let rate_jobs = if a.no_rate_sweep {
        vec![]
    } else {
        rate_plan(&a.rate_noise, a.rate_duration_s, a.seed)
    };
    let total = (arw_jobs.len() + rate_jobs.len()) as u64;
    let bar = progress_bar(total, "{bar:40} {pos}/{len} {eta}", a.json.json);
    let tick = |_: usize, _: &gyro_lab_core::sim::dither_run::DitherSummary| bar.inc(1);
    let arw_s =
        run_all(&arw_jobs, threads, &tick).map_err(|e| LabError::Bench(format!("{e:?}")))?;
    let rate_s =
        run_all(&rate_jobs, threads, &tick).map_err(|e| LabError::Bench(format!("{e:?}")))?;
    bar.finish_and_clear();
    let arw: Vec<ArwRow> = arw_jobs
        .iter()
        .zip(&arw_s)
        .map(|(j, s)| arw_row(j, s))
        .collect();
    let rate: Vec<RateRow> = rate_jobs
        .iter()
        .zip(&rate_s)
        .map(|(j, s)| rate_row(j, s))
        .collect();
    let ratios: Vec<f64> = arw.iter().filter_map(|r| r.ratio).collect();
    let mean = (!ratios.is_empty()).then(|| ratios.iter().sum::<f64>() / ratios.len() as f64);
    let summary = Summary {
        points: arw.len(),
        within_20pct: ratios.iter().filter(|r| (*r - 1.0).abs() <= 0.2).count(),
        worst_ratio: ratios
            .iter()
            .copied()
            .max_by(|x, y| (x - 1.0).abs().total_cmp(&(y - 1.0).abs())),
        ratio_mean: mean,
        ratio_rms_dev: mean.map(|m| {
            (ratios.iter().map(|r| (r - m) * (r - m)).sum::<f64>() / ratios.len() as f64).sqrt()
        }),
        covered_95: arw.iter().filter(|r| r.covered).count(),
        residual_counts_rms_max: arw
            .iter()
            .map(|r| r.dither_residual_counts_rms)
            .fold(0.0, f64::max),
        mean_error_within_3_se: arw
            .iter()
            .filter(|r| r.mean_rate_error_dph.abs() <= 3.0 * r.mean_rate_error_stderr_dph)
            .count(),
        rate_points_within_3_se_of_prediction: rate
            .iter()
            .filter(|r| {
                (r.mean_rate_error_dph - r.predicted_rate_error_dph).abs()
                    <= 3.0 * r.mean_rate_error_stderr_dph
            })
            .count(),
        rate_points: rate.len(),
    };
    if !a.json.json {
        println!(
            "ARW: {} random draws across the acceptance ranges, {} s each (Allan analysis from 20 ms)",
            arw.len(),
            a.duration_s
        );
        println!(
            "{:>6} {:>5} {:>5} {:>5} {:>5} {:>8} | {:>9} {:>9} {:>9} {:>9} {:>6} {:>3} | {:>7} {:>16} {:>5} {:>6}",
            "OL", "Od", "fd", "K", "noise", "rate", "ARW", "lo", "hi", "pred", "ratio", "in",
            "resid", "mean err dph", "sigma", "kappa"
        );
        for r in &arw {
            println!(
                "{:>6.3} {:>5.0} {:>5.0} {:>5.0} {:>5.3} {:>8.4} | {:>9} {:>9} {:>9} {:>9.6} {:>6} {:>3} | {:>7.4} {:>+8.4}+-{:<7.4} {:>5.1} {:>6.2}",
                r.lock_in_dps,
                r.dither_dps,
                r.dither_hz,
                r.counts_per_deg,
                r.noise_frac,
                r.rate_dps,
                opt(r.arw_dpsh, 6),
                opt(r.arw_lo_dpsh, 6),
                opt(r.arw_hi_dpsh, 6),
                r.arw_predicted_dpsh,
                opt(r.ratio, 3),
                if r.covered { "y" } else { "n" },
                r.dither_residual_counts_rms,
                r.mean_rate_error_dph,
                r.mean_rate_error_stderr_dph,
                r.crossing_phase_rms_rad,
                r.zone_kappa
            );
        }
        if !rate.is_empty() {
            println!(
                "rate error: K 500 fringes/deg, lock-in 0.2 deg/s, dither 100 deg/s at 500 Hz (zones at whole deg/s), {} s each",
                a.rate_duration_s
            );
            println!(
                "{:>6} {:>8} {:>6} | {:>12} {:>9} {:>12} {:>5} {:>10} {:>8}",
                "noise",
                "rate",
                "zones",
                "err dph",
                "se",
                "predicted",
                "zone",
                "res LI dph",
                "kappa"
            );
            for r in &rate {
                println!(
                    "{:>6.3} {:>8.4} {:>6.3} | {:>+12.4} {:>9.4} {:>+12.4} {:>5} {:>10.4} {:>8.2}",
                    r.noise_frac,
                    r.rate_dps,
                    r.rate_in_zones,
                    r.mean_rate_error_dph,
                    r.mean_rate_error_stderr_dph,
                    r.predicted_rate_error_dph,
                    r.dynamic_zone,
                    r.residual_lock_in_dph,
                    r.zone_kappa
                );
            }
        }
        let s = &summary;
        println!(
            "summary: ARW within 20 % of the prediction on {}/{} (mean ratio {}, rms deviation {}, worst {}); prediction inside the 95 % interval on {}/{}; residual dither at most {:.4} counts rms; mean error within 3 standard errors of zero on {}/{}; rate sweep within 3 standard errors of the prediction on {}/{}",
            s.within_20pct,
            s.points,
            opt(s.ratio_mean, 3),
            opt(s.ratio_rms_dev, 3),
            opt(s.worst_ratio, 3),
            s.covered_95,
            s.points,
            s.residual_counts_rms_max,
            s.mean_error_within_3_se,
            s.points,
            s.rate_points_within_3_se_of_prediction,
            s.rate_points
        );
    }
    print_json(&Out { arw, rate, summary })
}
