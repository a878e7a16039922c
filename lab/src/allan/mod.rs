//! `gyro-lab allan`: noise analysis of a rate record (IEEE 952 Allan
//! variance method, docs/noise.md): overlapping Allan deviation at
//! log-spaced averaging times with chi-square intervals from Greenhall's
//! degrees of freedom, and the noise terms fitted to the whole curve.

pub mod adev;
pub mod bench;
pub mod edf;
pub mod terms;

use crate::data::allan_file::{self, AllanRow};
use crate::data::run_file::{Column, Series as RunSeries};
use crate::error::LabError;
use crate::report::{num, sig, Axes, Report, Series};
use clap::Args;
use std::path::PathBuf;
use terms::{TermFit, COUNT, NAMES, SLOPES, UNITS};

/// Averaging times per decade.
pub const PER_DECADE: usize = 10;
/// Largest deviation of a sample interval from the median interval, relative.
pub const SAMPLING_TOLERANCE: f64 = 0.01;

/// The analysis of one record.
pub struct Allan {
    pub tau0: f64,
    pub n: usize,
    pub ms: Vec<usize>,
    pub taus: Vec<f64>,
    /// Overlapping Allan variance, (deg/s)^2, and its 95 % interval.
    pub avar: Vec<f64>,
    pub avar_lo: Vec<f64>,
    pub avar_hi: Vec<f64>,
    pub terms: TermFit,
    /// Mean rate, deg/s, and its standard error: the fitted model's Allan
    /// deviation at the record's length (for white noise exactly the
    /// standard error of the mean; it holds for correlated noise too).
    pub mean_dps: f64,
    pub mean_se_dps: f64,
}

/// Why a record cannot be analysed.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum AllanError {
    /// Fewer than 3 samples (this many).
    TooShort(usize),
    /// Every sample the same.
    Constant,
}

impl std::fmt::Display for AllanError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            AllanError::TooShort(n) => write!(
                f,
                "{n} samples: too short for even one averaging time (3 needed for tau = tau0)"
            ),
            AllanError::Constant => f.write_str(
                "the record is constant: its Allan deviation is zero, there is no noise to analyse",
            ),
        }
    }
}

/// Analyses `y` sampled every `tau0` s (the units of `y` carry through:
/// deg/s for the reported terms; the mean's standard error in `y`'s unit).
pub fn analyse(y: &[f64], tau0: f64) -> Result<Allan, AllanError> {
    let n = y.len();
    if n < 3 {
        return Err(AllanError::TooShort(n));
    }
    let first = y[0];
    if y.iter().all(|&v| v == first) {
        return Err(AllanError::Constant);
    }
    let ms = adev::averaging_factors(n, PER_DECADE);
    let taus: Vec<f64> = ms.iter().map(|&m| m as f64 * tau0).collect();
    let avar = adev::oavar(y, &ms);
    let terms = terms::fit(&taus, &avar, &ms, n + 1);
    let (mut lo, mut hi) = (vec![], vec![]);
    for (i, &a) in avar.iter().enumerate() {
        let (l, h) = edf::interval(a.sqrt(), terms.edf[i], terms::CONF);
        lo.push(l * l);
        hi.push(h * h);
    }
    let mean = y.iter().sum::<f64>() / n as f64;
    let mean_se = terms.model_at(n as f64 * tau0).sqrt();
    Ok(Allan {
        tau0,
        n,
        ms,
        taus,
        avar,
        avar_lo: lo,
        avar_hi: hi,
        terms,
        mean_dps: mean,
        mean_se_dps: mean_se,
    })
}

/// The sample period of `t` (the median interval), checked: every interval
/// within [`SAMPLING_TOLERANCE`] of it. The error names the row.
pub fn sample_period(series: &RunSeries) -> Result<f64, LabError> {
    let t = &series.t_s;
    if t.len() < 2 {
        return Ok(1.0);
    }
    let mut d: Vec<f64> = t.windows(2).map(|w| w[1] - w[0]).collect();
    let mut sorted = d.clone();
    sorted.sort_by(f64::total_cmp);
    let med = sorted[sorted.len() / 2];
    if med.is_nan() || med <= 0.0 {
        return Err(series.time_error(1, "time does not increase"));
    }
    for (k, h) in d.iter_mut().enumerate() {
        if (*h - med).abs() > SAMPLING_TOLERANCE * med {
            return Err(series.time_error(
                k + 1,
                format!(
                    "sampling not uniform: interval {} s where the median is {} s (tolerance {} %); \
                     the Allan variance needs uniform samples",
                    *h,
                    med,
                    SAMPLING_TOLERANCE * 100.0
                ),
            ));
        }
    }
    Ok(med)
}

#[derive(Args, Debug, Clone)]
pub struct AllanArgs {
    /// Run file (t_s and the rate column, deg/s).
    #[arg(long)]
    pub data: PathBuf,
    /// The rate column to analyse, deg/s.
    #[arg(long, default_value = Column::Rate.name())]
    pub column: String,
    /// Write allan.csv and report.html here.
    #[arg(long)]
    pub out: Option<PathBuf>,
    #[arg(long)]
    pub json: bool,
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

const DPH: f64 = 3600.0;

pub fn run(a: &AllanArgs) -> Result<(), LabError> {
    let t_start = std::time::Instant::now();
    let big = std::fs::metadata(&a.data).is_ok_and(|m| m.len() > 20_000_000);
    let spinner = if big && !a.json {
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
    let tau0 = sample_period(&series)?;
    let name = a.data.display().to_string();
    let an = analyse(y, tau0)
        .map_err(|e| LabError::input(&a.data, format!("column `{}`: {e}", a.column)))?;
    let compute_s = t_start.elapsed().as_secs_f64() - read_s;
    spinner.finish_and_clear();
    let adev: Vec<f64> = an.avar.iter().map(|v| v.sqrt() * DPH).collect();
    let lo: Vec<f64> = an.avar_lo.iter().map(|v| v.sqrt() * DPH).collect();
    let hi: Vec<f64> = an.avar_hi.iter().map(|v| v.sqrt() * DPH).collect();
    if let Some(dir) = &a.out {
        std::fs::create_dir_all(dir).map_err(|e| LabError::io(dir, e))?;
        write_csv(&an, &dir.join("allan.csv"))?;
        let html = dir.join("report.html");
        report(&an, &name, &a.column)
            .write(&html)
            .map_err(|e| LabError::io(&html, e))?;
    }
    if a.json {
        let mut units = serde_json::Map::new();
        for j in 0..COUNT {
            units.insert(NAMES[j].into(), UNITS[j].into());
        }
        let j = serde_json::json!({
            "taus_s": an.taus,
            "adev_dph": adev,
            "adev_lo_dph": lo,
            "adev_hi_dph": hi,
            "terms": terms_json(&an),
            "units": units,
            "confidence": terms::CONF,
            "edf": an.terms.edf,
            "noise_type": an.terms.dominant.iter().map(|&d| NAMES[d]).collect::<Vec<_>>(),
            "samples": an.n,
            "tau0_s": an.tau0,
            "mean_dps": an.mean_dps,
            "mean_se_dps": an.mean_se_dps,
            "column": a.column,
            "read_s": read_s,
            "compute_s": compute_s,
        });
        println!("{j}");
        return Ok(());
    }
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
    if let Some(dir) = &a.out {
        println!(
            "written: {}, {}",
            dir.join("allan.csv").display(),
            dir.join("report.html").display()
        );
    }
    Ok(())
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

/// The Allan deviation plot (measured points with intervals, the fitted
/// model and each present term), in deg/h.
pub fn adev_series(an: &Allan, label: &str, color: usize, terms: bool) -> Vec<Series> {
    let pts: Vec<(f64, f64)> = an
        .taus
        .iter()
        .zip(&an.avar)
        .map(|(t, v)| (*t, v.sqrt() * DPH))
        .collect();
    let errs: Vec<(f64, f64)> = an
        .avar_lo
        .iter()
        .zip(&an.avar_hi)
        .map(|(l, h)| (l.sqrt() * DPH, h.sqrt() * DPH))
        .collect();
    let mut v = vec![Series::points(label, pts, Some(errs), color)];
    if terms {
        let grid: Vec<f64> = (0..=200)
            .map(|i| {
                let (a, b) = (an.taus[0].ln(), an.taus[an.taus.len() - 1].ln());
                (a + (b - a) * i as f64 / 200.0).exp()
            })
            .collect();
        v.push(Series::line(
            "fitted model",
            grid.iter()
                .map(|&t| (t, an.terms.model_at(t).sqrt() * DPH))
                .collect(),
            1,
        ));
        for j in 0..COUNT {
            if an.terms.present[j] {
                v.push(Series::dashed(
                    NAMES[j],
                    grid.iter()
                        .map(|&t| (t, (an.terms.c[j] * terms::basis(j, t)).sqrt() * DPH))
                        .collect(),
                    2 + j,
                ));
            }
        }
    }
    v
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
