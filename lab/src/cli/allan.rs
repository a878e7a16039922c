//! `gyro-lab allan`: noise analysis of a rate column of a run file (IEEE
//! 952 Allan variance, noise/): the JSON, allan.csv and the report.

use crate::cli::adev_plot::adev_series;
use crate::cli::args::{Json, OutOpt};
use crate::cli::output::write_report;
use crate::data::allan_file::{self, AllanRow};
use crate::data::run_file::{Column, Series as RunSeries};
use crate::error::LabError;
use crate::noise::analysis::{analyse, sample_period, Allan};
use crate::noise::terms::{self, COUNT, NAMES, SLOPES, UNITS};
use crate::report::document::Report;
use crate::report::plot::Axes;
use crate::report::text::{num, sig};
use clap::Args;
use std::path::PathBuf;

const DPH: f64 = 3600.0;

#[derive(Args, Debug, Clone)]
#[command(mut_arg("out", |a| a.help("Write allan.csv and report.html here")))]
pub struct AllanArgs {
    /// Run file (t_s and the rate column, deg/s).
    #[arg(long)]
    pub data: PathBuf,
    /// The rate column to analyse, deg/s.
    #[arg(long, default_value = Column::Rate.name())]
    pub column: String,
    #[command(flatten)]
    pub out: OutOpt,
    #[command(flatten)]
    pub json: Json,
}

#[derive(serde::Serialize)]
struct TermJson {
    value: f64,
    lo: f64,
    hi: f64,
}

/// The terms as JSON values: {value, lo, hi} or null.
fn terms_json(a: &Allan) -> serde_json::Map<String, serde_json::Value> {
    let mut m = serde_json::Map::new();
    for j in 0..COUNT {
        let v = if a.terms.present[j] {
            serde_json::to_value(TermJson {
                value: terms::to_units(j, a.terms.c[j]),
                lo: terms::to_units(j, a.terms.lo[j]),
                hi: terms::to_units(j, a.terms.hi[j]),
            })
            .unwrap_or(serde_json::Value::Null)
        } else {
            serde_json::Value::Null
        };
        m.insert(NAMES[j].into(), v);
    }
    m
}

pub fn run(a: &AllanArgs) -> Result<(), LabError> {
    let t_start = std::time::Instant::now();
    let big = std::fs::metadata(&a.data).is_ok_and(|m| m.len() > 20_000_000);
    let spinner = if big && !a.json.json {
        let s = indicatif::ProgressBar::new_spinner();
        s.set_message(format!("reading {}", a.data.display()));
        s.enable_steady_tick(std::time::Duration::from_millis(200));
        s
    } else {
        indicatif::ProgressBar::hidden()
    };
    let series = RunSeries::read(&a.data, &a.column)?;
    let read_s = t_start.elapsed().as_secs_f64();
    spinner.set_message("Allan variance");
    let y = &series.values;
    let tau0 = sample_period(&series.t_s).map_err(|e| series.time_error(e.row(), e.to_string()))?;
    let name = a.data.display().to_string();
    let an = analyse(y, tau0)
        .map_err(|e| LabError::input(&a.data, format!("column `{}`: {e}", a.column)))?;
    let compute_s = t_start.elapsed().as_secs_f64() - read_s;
    spinner.finish_and_clear();
    if let Some(dir) = &a.out.out {
        std::fs::create_dir_all(dir).map_err(|e| LabError::io(dir, e))?;
        write_csv(&an, &dir.join("allan.csv"))?;
        write_report(&report(&an, &name, &a.column), &dir.join("report.html"))?;
    }
    let timing = (read_s, compute_s);
    if a.json.json {
        println!("{}", json(&an, &a.column, timing));
        return Ok(());
    }
    print_text(&an, &name, a, timing);
    Ok(())
}

/// The JSON of the analysis (deviations in deg/h), with the read and
/// compute times.
fn json(an: &Allan, column: &str, (read_s, compute_s): (f64, f64)) -> serde_json::Value {
    let dph = |v: &[f64]| -> Vec<f64> { v.iter().map(|v| v.sqrt() * DPH).collect() };
    let (adev, lo, hi) = (dph(&an.avar), dph(&an.avar_lo), dph(&an.avar_hi));
    let mut units = serde_json::Map::new();
    for j in 0..COUNT {
        units.insert(NAMES[j].into(), UNITS[j].into());
    }
    serde_json::json!({
        "taus_s": an.taus,
        "adev_dph": adev,
        "adev_lo_dph": lo,
        "adev_hi_dph": hi,
        "terms": terms_json(an),
        "units": units,
        "confidence": terms::CONF,
        "edf": an.terms.edf,
        "noise_type": an.terms.dominant.iter().map(|&d| NAMES[d]).collect::<Vec<_>>(),
        "samples": an.n,
        "tau0_s": an.tau0,
        "mean_dps": an.mean_dps,
        "mean_se_dps": an.mean_se_dps,
        "column": column,
        "read_s": read_s,
        "compute_s": compute_s,
    })
}

fn print_text(an: &Allan, name: &str, a: &AllanArgs, (read_s, compute_s): (f64, f64)) {
    println!(
        "{}: column `{}`, {} samples at {} s ({:.4} h); {} averaging times {} .. {} s",
        name,
        a.column,
        an.n,
        sig(an.tau0),
        an.n as f64 * an.tau0 / 3600.0,
        an.taus.len(),
        sig(an.taus[0]),
        sig(an.taus[an.taus.len() - 1])
    );
    println!(
        "mean rate {:.6e} +- {:.2e} deg/s (standard error from the noise model at the record length)",
        an.mean_dps, an.mean_se_dps
    );
    println!("IEEE 952 terms (95 % intervals; fitted to the whole curve):");
    for j in 0..COUNT {
        if an.terms.present[j] {
            println!(
                "  {:<24} {:>12} [{} .. {}] {}   (slope {})",
                NAMES[j],
                num(terms::to_units(j, an.terms.c[j])),
                num(terms::to_units(j, an.terms.lo[j])),
                num(terms::to_units(j, an.terms.hi[j])),
                UNITS[j],
                SLOPES[j]
            );
        } else {
            println!(
                "  {:<24} absent (the curve does not show slope {})",
                NAMES[j], SLOPES[j]
            );
        }
    }
    println!("read {read_s:.2} s, computed {compute_s:.2} s");
    if let Some(dir) = &a.out.out {
        println!(
            "written: {}, {}",
            dir.join("allan.csv").display(),
            dir.join("report.html").display()
        );
    }
}

fn write_csv(an: &Allan, path: &std::path::Path) -> Result<(), LabError> {
    let rows: Vec<AllanRow> = (0..an.taus.len())
        .map(|i| AllanRow {
            tau_s: an.taus[i],
            adev_dph: an.avar[i].sqrt() * DPH,
            adev_lo_dph: an.avar_lo[i].sqrt() * DPH,
            adev_hi_dph: an.avar_hi[i].sqrt() * DPH,
            edf: an.terms.edf[i],
            noise_type: NAMES[an.terms.dominant[i]],
            model_adev_dph: an.terms.model[i].sqrt() * DPH,
        })
        .collect();
    allan_file::write(path, &rows)
}

fn report(an: &Allan, name: &str, column: &str) -> Report {
    let mut r = Report::new(&format!("Allan deviation of {column} in {name}"));
    r.paragraph(&format!(
        "{} samples every {} s ({:.4} h). Overlapping Allan deviation at {} averaging times from {} s to a third \
         of the record ({} s), with 95 % chi-square intervals from Greenhall's equivalent degrees of freedom of \
         the noise types the fitted model holds at each averaging time.",
        an.n,
        sig(an.tau0),
        an.n as f64 * an.tau0 / 3600.0,
        an.taus.len(),
        sig(an.taus[0]),
        sig(an.taus[an.taus.len() - 1])
    ));
    r.heading("Allan deviation and the fitted noise terms");
    r.plot(
        &Axes {
            title: "Allan deviation".into(),
            x_label: "averaging time tau, s".into(),
            y_label: "Allan deviation, deg/h".into(),
            log_x: true,
            log_y: true,
        },
        &adev_series(an, "measured (95 % interval)", 0, true),
        "Measured overlapping Allan deviation with its 95 % intervals, the fitted model (solid) and each term \
         the curve shows (dashed).",
    );
    r.heading("IEEE 952 noise terms");
    let rows: Vec<Vec<String>> = (0..COUNT)
        .map(|j| {
            if an.terms.present[j] {
                vec![
                    NAMES[j].into(),
                    SLOPES[j].into(),
                    num(terms::to_units(j, an.terms.c[j])),
                    num(terms::to_units(j, an.terms.lo[j])),
                    num(terms::to_units(j, an.terms.hi[j])),
                    UNITS[j].into(),
                ]
            } else {
                vec![
                    NAMES[j].into(),
                    SLOPES[j].into(),
                    "absent".into(),
                    "-".into(),
                    "-".into(),
                    UNITS[j].into(),
                ]
            }
        })
        .collect();
    r.table(
        &["term", "slope", "value", "95 % low", "95 % high", "unit"],
        &rows,
    );
    r.note(
        "The terms are fitted to the whole curve by weighted least squares with non-negative coefficients. A term \
         is reported only if it carries at least half of the model at some measured averaging time and its \
         interval excludes zero; otherwise it is absent, not small. Bias instability includes the 0.664 factor \
         (B = floor / 0.664). Units: quantization in arcsec of angle; angle random walk in deg/sqrt(h); bias \
         instability in deg/h; rate random walk in deg/h/sqrt(h); rate ramp in deg/h^2.",
    );
    r.paragraph(&format!(
        "Mean rate {:.6e} deg/s, standard error {:.2e} deg/s (the fitted model's Allan deviation at the record's \
         length).",
        an.mean_dps, an.mean_se_dps
    ));
    r
}
