//! `gyro-lab allan`: noise analysis of a rate column of a run file (IEEE
//! 952 Allan variance, noise/): the JSON, allan.csv and the report.

use crate::cli::adev_plot::{adev_series, misfit_series, missed_series, reading_marks};
use crate::cli::args::{Json, OutOpt, RunRead};
use crate::cli::checks;
use crate::cli::out_path::{self, FileKind};
use crate::cli::output::write_report;
use crate::data::allan_file::{self, AllanRow};
use crate::data::run_file::{Column, Series as RunSeries};
use crate::error::LabError;
use crate::noise::analysis::{analyse, Allan};
use crate::noise::gaps::{fill_gaps, Filled};
use crate::noise::model::Interval;
use crate::noise::record_checks::{self, RecordWarning};
use crate::noise::terms::{
    self, shape_name, COUNT, MARKOV_NAME, NAMES, PLAIN, SIN_NAME, SLOPES, UNITS,
};
use crate::report::document::Report;
use crate::report::plot::Axes;
use crate::report::text::{num, sig};
use clap::Args;
use std::path::PathBuf;

const DPH: f64 = 3600.0;

#[derive(Args, Debug, Clone)]
#[command(mut_arg("out", |a| a.help("A folder: allan.csv and report.html are written in it")))]
pub struct AllanArgs {
    /// Run file (t_s and the rate column; temperature columns where present).
    #[arg(long)]
    pub data: PathBuf,
    /// The rate column to analyse (our name or the file's); less
    /// `ref_rate_dps` where the file has it.
    #[arg(long, default_value = Column::Rate.name())]
    pub column: String,
    #[command(flatten)]
    pub read: RunRead,
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

/// The terms as JSON values: {value, lo, hi, reliable} or null; the
/// sinusoid and the Markov term with each parameter's interval.
fn terms_json(a: &Allan) -> serde_json::Map<String, serde_json::Value> {
    let mut m = serde_json::Map::new();
    let t = &a.terms;
    let iv = |i: &Interval, k: f64| serde_json::json!({"value": i.value * k, "lo": i.lo * k, "hi": i.hi * k});
    for j in 0..COUNT {
        let v = if t.present[j] {
            let mut v = serde_json::to_value(TermJson {
                value: terms::to_units(j, t.c[j]),
                lo: terms::to_units(j, t.lo[j]),
                hi: terms::to_units(j, t.hi[j]),
            })
            .unwrap_or(serde_json::Value::Null);
            v["reliable"] = t.reliable[j].into();
            if j == 2 {
                v["upper_bound"] = t.bias_upper_bound.into();
            }
            if let (1, Some(f)) = (j, &t.arw_filter_s) {
                v["filter_tau_s"] = iv(f, 1.0);
            }
            v
        } else {
            serde_json::Value::Null
        };
        m.insert(NAMES[j].into(), v);
    }
    m.insert(
        SIN_NAME.into(),
        t.sinusoid.as_ref().map_or(serde_json::Value::Null, |s| {
            serde_json::json!({
                "amplitude_dph": iv(&s.amplitude_dps, DPH),
                "frequency_hz": iv(&s.frequency_hz, 1.0),
                "reliable": s.reliable,
            })
        }),
    );
    m.insert(
        MARKOV_NAME.into(),
        t.correlated.as_ref().map_or(serde_json::Value::Null, |c| {
            serde_json::json!({
                "sigma_dph": iv(&c.sigma_dph, 1.0),
                "tau_s": iv(&c.tau_s, 1.0),
                "white_limit_dpsh": iv(&c.white_limit_dpsh, 1.0),
                "reliable": c.reliable,
            })
        }),
    );
    m
}

/// The goodness of fit as JSON.
fn fit_json(an: &Allan) -> serde_json::Value {
    let g = &an.terms.goodness;
    serde_json::json!({
        "consistent": g.consistent,
        "chi2_per_dof": g.chi2_per_dof,
        "chi2_per_dof_limit": g.limit_per_dof,
        "dof": g.dof,
        "outside_taus_s": g.outside.iter().map(|&i| an.taus[i]).collect::<Vec<f64>>(),
        "outside_fraction": g.outside.len() as f64 / an.taus.len().max(1) as f64,
    })
}

/// The conventional readings as JSON.
fn readings_json(an: &Allan) -> serde_json::Value {
    let r = &an.readings;
    serde_json::json!({
        "arw_dpsh": r.arw_dpsh,
        "arw_region_s": r.arw_region_s.map(|(a, b)| vec![a, b]),
        "floor_dph": r.floor_dph,
        "floor_tau_s": r.floor_tau_s,
        "bias_instability_dph": r.bias_instability_dph,
        "resolved": r.resolved,
        "rise_after_floor": r.rise.map(|(t, v)| serde_json::json!({"tau_s": t, "adev_dph": v})),
    })
}

pub fn run(a: &AllanArgs) -> Result<(), LabError> {
    let t_start = std::time::Instant::now();
    let spec = a.read.spec()?;
    if let Some(dir) = &a.out.out {
        out_path::folder(
            "allan",
            dir,
            &[
                ("allan.csv", FileKind::Csv),
                ("report.html", FileKind::Html),
            ],
            &[("--data", &a.data)],
            a.out.force,
        )?;
    }
    let big = std::fs::metadata(&a.data).is_ok_and(|m| m.len() > 20_000_000);
    let spinner = if big && !a.json.json {
        let s = indicatif::ProgressBar::new_spinner();
        s.set_message(format!("reading {}", a.data.display()));
        s.enable_steady_tick(std::time::Duration::from_millis(200));
        s
    } else {
        indicatif::ProgressBar::hidden()
    };
    let mut series = RunSeries::read(&a.data, &a.column, &spec)?;
    let read_s = t_start.elapsed().as_secs_f64();
    spinner.set_message("Allan variance");
    let checked = checks::series(&mut series, &spec)?;
    let mut warnings = checked.warnings.clone();
    // A warm-up the temperatures show settling is left out unless the
    // stretch was given: the noise of the gyro, not its warm-up.
    let warm_up = match spec.from_s {
        None => crate::record::stationarity::settled_from(&checked.drifts),
        Some(_) => None,
    };
    if let Some(from) = warm_up {
        let k = series.t_s.partition_point(|&t| t < from);
        series.keep_from(k);
        warnings.push(crate::record::Warning::new(
            "warm_up",
            format!(
                "analysed from {} s on, after the warm-up the temperatures show ({k} rows left out); --from-s 0 analyses the whole record",
                sig(from)
            ),
        ));
    }
    // The gyro's error, not the table's motion: the output less the
    // reference rate where the file has one.
    let analysed = match &series.reference {
        Some(r) => {
            warnings.extend(record_checks::not_static(r));
            for (v, r) in series.values.iter_mut().zip(r) {
                *v -= r;
            }
            format!("{} - {}", a.column, Column::RefRate.name())
        }
        None => a.column.clone(),
    };
    warnings.extend(crate::record::stationarity::mean_rate(
        &series.t_s,
        &series.values,
    ));
    let filled = fill_gaps(&series.t_s, &series.values)
        .map_err(|e| series.time_error(e.row(), e.to_string()))?;
    let name = a.data.display().to_string();
    let an = analyse(&filled.values, filled.tau0)
        .map_err(|e| LabError::input(&a.data, format!("column `{analysed}`: {e}")))?;
    warnings.extend(record_checks::too_short(&an));
    let compute_s = t_start.elapsed().as_secs_f64() - read_s;
    spinner.finish_and_clear();
    if let Some(dir) = &a.out.out {
        out_path::make(dir)?;
        write_csv(&an, &dir.join("allan.csv"))?;
        write_report(
            &report(&an, &name, &analysed, &warnings),
            &dir.join("report.html"),
        )?;
    }
    let timing = (read_s, compute_s);
    if a.json.json {
        let mut j = json(&an, &a.column, &filled, timing);
        j["analysed"] = analysed.into();
        j["analysed_from_s"] = series.t_s.first().copied().into();
        j["warnings"] = serde_json::to_value(&warnings).unwrap_or_default();
        checked.json(&mut j);
        println!("{j}");
        return Ok(());
    }
    print_text(&an, &name, a, &analysed, timing);
    for w in &warnings {
        println!("WARNING ({}): {}", w.code, w.message);
    }
    if filled.gaps + filled.stretched > 0 {
        println!("{}", gaps_text(&filled));
    }
    Ok(())
}

/// The JSON of the analysis (deviations in deg/h), with the read and
/// compute times.
fn json(
    an: &Allan,
    column: &str,
    filled: &Filled,
    (read_s, compute_s): (f64, f64),
) -> serde_json::Value {
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
        "model_adev_dph": an.terms.model.iter().map(|v| v.sqrt() * DPH).collect::<Vec<f64>>(),
        "fit": fit_json(an),
        "readings": readings_json(an),
        "units": units,
        "confidence": terms::CONF,
        "edf": an.terms.edf,
        "noise_type": an.terms.dominant.iter().map(|&d| shape_name(d)).collect::<Vec<_>>(),
        "samples": an.n,
        "tau0_s": an.tau0,
        "mean_dps": an.mean_dps,
        "mean_se_dps": an.mean_se_dps,
        "column": column,
        "gaps": {
            "count": filled.gaps,
            "stretched_intervals": filled.stretched,
            "filled_samples": filled.filled,
            "filled_fraction": filled.filled_fraction(),
        },
        "read_s": read_s,
        "compute_s": compute_s,
    })
}

/// What filling the record's gaps did, and what it costs.
fn gaps_text(f: &Filled) -> String {
    let mut parts = vec![];
    if f.gaps > 0 {
        parts.push(format!(
            "gaps: {} in the record (samples lost on the way), {} samples ({:.3} % of the series) filled \
             with the rate over each gap; the angle is kept, so averages spanning a gap are right, but the \
             noise inside the gaps is missing and deviations at averaging times shorter than a gap read low \
             by up to that share",
            f.gaps,
            f.filled,
            100.0 * f.filled_fraction()
        ));
    }
    if f.stretched > 0 {
        parts.push(format!(
            "{} interval(s) longer than the sample period by less than half of one (a frame spanning \
             closures the board missed; no sample lost): resampled through the angle",
            f.stretched
        ));
    }
    parts.join("; ")
}

/// The figures a user looks for first, in words: the angle random walk
/// and the bias instability (fitted, with their intervals, and as read off
/// the curve), and any slower term the curve shows.
fn headline(an: &Allan) -> String {
    let t = &an.terms;
    let term = |j: usize| -> String {
        if t.present[j] {
            format!(
                "{} {} [{} .. {}] {}{}",
                PLAIN[j],
                num(terms::to_units(j, t.c[j])),
                num(terms::to_units(j, t.lo[j])),
                num(terms::to_units(j, t.hi[j])),
                UNITS[j],
                if t.reliable[j] { "" } else { " (unreliable)" }
            )
        } else {
            format!("no {} (the curve shows no slope {})", PLAIN[j], SLOPES[j])
        }
    };
    let r = &an.readings;
    let n_read = r
        .arw_dpsh
        .map_or("no -1/2 region to read N from".into(), |n| {
            format!("N = {} deg/sqrt(h) read at 1 s", num(n))
        });
    let b_read = if r.resolved {
        format!(
            "B = {} deg/h read off the floor",
            num(r.bias_instability_dph)
        )
    } else {
        format!(
            "B <= {} deg/h (the floor is not resolved: an upper bound)",
            num(r.bias_instability_dph)
        )
    };
    let slow: Vec<String> = [0, 3, 4]
        .into_iter()
        .filter(|&j| t.present[j])
        .map(term)
        .collect();
    format!(
        "In short: {}; {}. Read off the curve: {n_read}; {b_read}.{}",
        term(1),
        term(2),
        if slow.is_empty() {
            " No quantization, rate random walk or rate ramp shows.".to_owned()
        } else {
            format!(" Also: {}.", slow.join("; "))
        }
    )
}

/// The verdict on the fit, one sentence.
fn verdict(an: &Allan) -> String {
    let g = &an.terms.goodness;
    let out: Vec<String> = g.outside.iter().map(|&i| sig(an.taus[i])).collect();
    if g.consistent && out.is_empty() {
        format!(
            "The model fits: it passes through every measured 95 % interval (chi-square per degree of freedom {:.2}, \
             at most {:.2} for a right model).",
            g.chi2_per_dof, g.limit_per_dof
        )
    } else if g.consistent {
        format!(
            "The model fits within the scatter the estimates' correlation allows (chi-square per degree of freedom \
             {:.2}, at most {:.2} for a right model); it leaves the measured 95 % interval at {} of {} averaging \
             times: {} s.",
            g.chi2_per_dof,
            g.limit_per_dof,
            out.len(),
            an.taus.len(),
            out.join(", ")
        )
    } else {
        format!(
            "THE MODEL DOES NOT FIT this curve: chi-square per degree of freedom {:.2} where a right model stays \
             below {:.2}; it leaves the measured 95 % interval at {} of {} averaging times: {} s. Something there \
             is none of the IEEE 952 terms (or not in the form fitted); the intervals below are widened by the \
             misfit and the terms carrying those averaging times are marked unreliable.",
            g.chi2_per_dof,
            g.limit_per_dof,
            out.len(),
            an.taus.len(),
            out.join(", ")
        )
    }
}

/// The readings, one sentence.
fn readings_text(an: &Allan) -> String {
    let r = &an.readings;
    let n = match (r.arw_dpsh, r.arw_region_s) {
        (Some(n), Some((a, b))) => format!(
            "N = {} deg/sqrt(h) on the -1/2 line through {} .. {} s read at 1 s",
            num(n),
            sig(a),
            sig(b)
        ),
        _ => "no -1/2 region, so no N reading".into(),
    };
    let b = if r.resolved {
        format!(
            "floor {} deg/h at {} s, B = floor/0.664 = {} deg/h (the curve turns up after it)",
            num(r.floor_dph),
            sig(r.floor_tau_s),
            num(r.bias_instability_dph)
        )
    } else {
        let after = match r.rise {
            Some((t, v)) => format!(
                "the curve rises after it (to {} deg/h at {} s) but within the 95 % intervals, not beyond the floor's",
                num(v),
                sig(t)
            ),
            None => "the curve does not rise after it".into(),
        };
        format!(
            "lowest point {} deg/h at {} s; {after}, so the floor is not resolved and B <= {} deg/h is only an \
             upper bound",
            num(r.floor_dph),
            sig(r.floor_tau_s),
            num(r.bias_instability_dph)
        )
    };
    format!("Readings off the curve: {n}; {b}.")
}

/// The rows of the terms table (and of the terminal's list).
fn term_rows(an: &Allan) -> Vec<Vec<String>> {
    let t = &an.terms;
    let row = |name: &str, slope: &str, v: f64, lo: f64, hi: f64, unit: &str, rel: bool| {
        vec![
            name.to_owned(),
            slope.to_owned(),
            num(v),
            num(lo),
            num(hi),
            unit.to_owned(),
            if rel { "yes".into() } else { "no".into() },
        ]
    };
    let mut rows: Vec<Vec<String>> = (0..COUNT)
        .map(|j| {
            if t.present[j] {
                let bounded = j == 2 && t.bias_upper_bound;
                row(
                    if bounded {
                        "bias instability (upper bound: floor not resolved)"
                    } else {
                        PLAIN[j]
                    },
                    SLOPES[j],
                    terms::to_units(j, t.c[j]),
                    terms::to_units(j, t.lo[j]),
                    terms::to_units(j, t.hi[j]),
                    UNITS[j],
                    t.reliable[j],
                )
            } else {
                vec![
                    PLAIN[j].into(),
                    SLOPES[j].into(),
                    "absent".into(),
                    "-".into(),
                    "-".into(),
                    UNITS[j].into(),
                    "-".into(),
                ]
            }
        })
        .collect();
    if let Some(f) = &t.arw_filter_s {
        rows.push(row(
            "  white noise filter time constant",
            "bends -1/2 at short tau",
            f.value,
            f.lo,
            f.hi,
            "s",
            true,
        ));
    }
    match &t.sinusoid {
        Some(s) => {
            let a = &s.amplitude_dps;
            rows.push(row(
                "sinusoid amplitude",
                "bump, then -1",
                a.value * DPH,
                a.lo * DPH,
                a.hi * DPH,
                "deg/h",
                s.reliable,
            ));
            let f = &s.frequency_hz;
            rows.push(row(
                "sinusoid frequency",
                "bump at 0.37/f",
                f.value,
                f.lo,
                f.hi,
                "Hz",
                s.reliable,
            ));
        }
        None => rows.push(vec![
            "sinusoid".into(),
            "bump".into(),
            "absent".into(),
            "-".into(),
            "-".into(),
            "-".into(),
            "-".into(),
        ]),
    }
    match &t.correlated {
        Some(c) => {
            let s = &c.sigma_dph;
            rows.push(row(
                "correlated (Markov) sigma",
                "+1/2 .. -1/2",
                s.value,
                s.lo,
                s.hi,
                "deg/h",
                c.reliable,
            ));
            let tc = &c.tau_s;
            rows.push(row(
                "correlated (Markov) time",
                "hump at 1.89 T",
                tc.value,
                tc.lo,
                tc.hi,
                "s",
                c.reliable,
            ));
            let w = &c.white_limit_dpsh;
            rows.push(row(
                "  its white limit N = q T",
                "-1/2 at tau >> T",
                w.value,
                w.lo,
                w.hi,
                "deg/sqrt(h)",
                c.reliable,
            ));
        }
        None => rows.push(vec![
            "correlated (Markov)".into(),
            "hump".into(),
            "absent".into(),
            "-".into(),
            "-".into(),
            "-".into(),
            "-".into(),
        ]),
    }
    rows
}

fn print_text(
    an: &Allan,
    name: &str,
    a: &AllanArgs,
    analysed: &str,
    (read_s, compute_s): (f64, f64),
) {
    println!(
        "{}: `{}`, {} samples at {} s ({:.4} h); {} averaging times {} .. {} s",
        name,
        analysed,
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
    println!("{}", headline(an));
    println!("{}", verdict(an));
    println!("IEEE 952 terms (95 % intervals; fitted to the whole curve; absent: the curve does not show it):");
    for r in term_rows(an) {
        if r[2] == "absent" {
            println!(
                "  {:<34} absent (the curve does not show slope {})",
                r[0], r[1]
            );
        } else {
            println!(
                "  {:<34} {:>12} [{} .. {}] {}{}",
                r[0],
                r[2],
                r[3],
                r[4],
                r[5],
                if r[6] == "no" { "  (unreliable)" } else { "" }
            );
        }
    }
    println!("{}", readings_text(an));
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
            noise_type: shape_name(an.terms.dominant[i]),
            model_adev_dph: an.terms.model[i].sqrt() * DPH,
        })
        .collect();
    allan_file::write(path, &rows)
}

fn report(an: &Allan, name: &str, column: &str, warnings: &[RecordWarning]) -> Report {
    let mut r = Report::new(&format!("Allan deviation of {column} in {name}"));
    for w in warnings {
        r.paragraph(&format!("WARNING ({}): {}.", w.code, w.message));
    }
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
    r.paragraph(&headline(an));
    r.heading("Does the model fit?");
    r.paragraph(&verdict(an));
    r.heading("Allan deviation, the fitted noise terms and the readings");
    let mut series = adev_series(an, "measured (95 % interval)", 0, true);
    if let Some(m) = missed_series(an) {
        series.insert(1, m);
    }
    let (lines, marks) = reading_marks(an);
    series.extend(lines);
    r.plot_annotated(
        &Axes {
            title: "Allan deviation".into(),
            x_label: "averaging time tau, s".into(),
            y_label: "Allan deviation, deg/h".into(),
            log_x: true,
            log_y: true,
        },
        &series,
        &marks,
        "Measured overlapping Allan deviation with its 95 % intervals (points the model misses in orange), the \
         fitted model (solid) and each term it holds (dashed); the conventional readings: the -1/2 line read at \
         tau = 1 s and the floor.",
    );
    r.paragraph(&readings_text(an));
    r.heading("Where the model misses");
    r.plot_annotated(
        &Axes {
            title: "Normalised residual of the Allan variance".into(),
            x_label: "averaging time tau, s".into(),
            y_label: "(measured - model) / sd".into(),
            log_x: true,
            log_y: false,
        },
        &misfit_series(an),
        &[],
        "The measured Allan variance less the model's, in standard deviations of the estimate (from its \
         equivalent degrees of freedom): a right model keeps within the dashed band at 95 % of the averaging times \
         (neighbours correlate, so a run of points on one side is common); where points leave it, the model misses \
         the curve there.",
    );
    r.heading("IEEE 952 noise terms");
    r.table(
        &[
            "term",
            "slope",
            "value",
            "95 % low",
            "95 % high",
            "unit",
            "reliable",
        ],
        &term_rows(an),
    );
    r.note(
        "The terms are fitted to the whole curve by weighted least squares with non-negative coefficients; the \
         sinusoid's frequency, the Markov correlation time and the white noise's filter time constant are searched. \
         A term is reported only if it carries at least half of the model at some measured averaging time and the \
         curve needs it (its interval excludes zero, or leaving it out costs the fit far more than chance); \
         otherwise it is absent, not small. A -1 slope is quantization or white angle noise (one shape). The \
         intervals are widened by the chi-square in excess of a right model's, where the term carries the model \
         and overall, and to the values the missed points ask for; a term is unreliable where it carries \
         averaging times the model misses. Bias instability includes the 0.664 factor (B = floor / 0.664). Units: \
         quantization in arcsec of angle; angle random walk in deg/sqrt(h); bias instability in deg/h; rate random \
         walk in deg/h/sqrt(h); rate ramp in deg/h^2.",
    );
    r.paragraph(&format!(
        "Mean rate {:.6e} deg/s, standard error {:.2e} deg/s (the fitted model's Allan deviation at the record's \
         length).",
        an.mean_dps, an.mean_se_dps
    ));
    r
}
