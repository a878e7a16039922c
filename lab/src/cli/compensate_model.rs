//! `gyro-lab compensate --coeffs model.toml`: a model from `discover`
//! applied to a run. The model's output is the reference rate plus its
//! effects and terms; what it adds to the reference is the gyro's error
//! it explains, and that is taken off the output: the compensated rate is
//! the output less (the model's output less the reference). The firmware
//! applies no such model: this is the lab's correction, for checking a
//! model on another run or cleaning a record before a noise analysis.

use crate::cli::checks;
use crate::cli::model_file::read_model_file;
use crate::cli::out_path;
use crate::cli::output::write_report;
use crate::data::read_spec::ReadSpec;
use crate::data::run_file::{Column, Reference, RunFile, RunText};
use crate::error::LabError;
use crate::model::gyro_kind::GyroKind;
use crate::model::inputs::Inputs;
use crate::model::ranges::Extent;
use crate::report::document::Report;
use crate::report::plot::{thin, Axes, Series};
use crate::report::text::sig;
use crate::report::verdict::Verdict;
use std::path::Path;

/// What `compensate` was asked to do.
pub struct Target<'a> {
    pub coeffs: &'a Path,
    pub data: &'a Path,
    pub out: &'a Path,
    pub report: bool,
    pub json: bool,
}

/// Writes the run back with the compensated rate, the coefficients named
/// in its first comment line (the run's own comments after it).
pub fn write_back(
    coeffs: &Path,
    data: &Path,
    out: &Path,
    text: &RunText,
    comp: &[f64],
) -> Result<(), LabError> {
    let comment = format!(
        "gyro-lab compensate: {} applied to {}",
        coeffs.display(),
        data.display()
    );
    crate::data::atomic::write(
        out,
        text.text_with(&comment, &[(Column::CompensatedRate, comp)]),
    )
}

/// The window the summary's means are taken over, s.
pub const WINDOW_S: f64 = 60.0;

/// Means of `x` over windows of [`WINDOW_S`]: (mid time, mean).
fn window_means(t: &[f64], x: &[f64]) -> Vec<(f64, f64)> {
    let mut out = vec![];
    let mut k = 0;
    while k < t.len() {
        let end = t[k] + WINDOW_S;
        let j = k + t[k..].partition_point(|&s| s < end);
        let n = (j - k) as f64;
        out.push((0.5 * (t[k] + t[j - 1]), x[k..j].iter().sum::<f64>() / n));
        k = j;
    }
    out
}

/// RMS of values, and the mean with its standard error (of the means).
fn rms_mean(m: &[(f64, f64)]) -> (f64, f64, f64) {
    let n = m.len().max(1) as f64;
    let mean = m.iter().map(|p| p.1).sum::<f64>() / n;
    let rms = (m.iter().map(|p| p.1 * p.1).sum::<f64>() / n).sqrt();
    let sd = (m.iter().map(|p| (p.1 - mean).powi(2)).sum::<f64>() / (n - 1.0).max(1.0)).sqrt();
    (rms, mean, sd / n.sqrt())
}

pub fn run(a: &Target, spec: &ReadSpec) -> Result<(), LabError> {
    let text = std::fs::read_to_string(a.coeffs)
        .map_err(|e| LabError::input(a.coeffs, format!("cannot read: {e}")))?;
    let gyro = toml::from_str::<toml::Table>(&text)
        .ok()
        .and_then(|t| t.get("gyro")?.as_str().and_then(GyroKind::from_name))
        .ok_or_else(|| {
            LabError::input(
                a.coeffs,
                "a gyro_model needs `gyro = \"fog\"|\"rlg\"|\"mems\"`",
            )
        })?;
    let file = read_model_file(a.coeffs, gyro)?;
    let optional = [
        Column::Temp,
        Column::MonoA,
        Column::MonoB,
        Column::Case,
        Column::RefAcc,
    ];
    let (mut run_text, []) = RunFile::read(a.data, spec, Reference::ZeroIfAbsent, 2, [])?;
    run_text.fill_optional(&optional)?;
    let checked = checks::run(&mut run_text.run, spec)?;
    let r = &run_text.run;
    let mono = r.t_mono_a_c.clone().zip(r.t_mono_b_c.clone());
    let inp = Inputs::new(
        r.t_s.clone(),
        r.ref_rate_dps.clone(),
        r.temp_c.clone(),
        mono,
        r.t_case_c.clone(),
        r.ref_acc_dps2.clone(),
    );
    if let Some((e, cols)) = file.model.missing_inputs(&inp).first() {
        let names: Vec<&str> = cols.iter().map(|c| c.name()).collect();
        return Err(LabError::input(
            a.data,
            format!(
                "the model's effect `{}` needs column(s) {} that this run lacks",
                e.name(),
                names.join(", ")
            ),
        ));
    }
    let extent = Extent {
        grade: crate::model::grade::Grade::Navigation,
        record_s: inp.t.last().copied().unwrap_or(0.0) - inp.t.first().copied().unwrap_or(0.0),
        temp_c: inp.temp.as_ref().map(|v| {
            v.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |a, &x| {
                (a.0.min(x), a.1.max(x))
            })
        }),
    };
    file.check_on_run(&extent)?;
    file.check_terms(&inp)?;
    let sim = file.model.evaluate(&inp);
    let comp: Vec<f64> = r
        .rate_dps
        .iter()
        .zip(&sim)
        .zip(&r.ref_rate_dps)
        .map(|((y, s), w)| y - (s - w))
        .collect();
    write_back(a.coeffs, a.data, a.out, &run_text, &comp)?;
    let dph = |x: &[f64]| -> Vec<f64> {
        x.iter()
            .zip(&r.ref_rate_dps)
            .map(|(v, w)| (v - w) * 3600.0)
            .collect()
    };
    let before = window_means(&r.t_s, &dph(&r.rate_dps));
    let after = window_means(&r.t_s, &dph(&comp));
    let (rms_b, mean_b, _) = rms_mean(&before);
    let (rms_a, mean_a, se_a) = rms_mean(&after);
    let names: Vec<String> = file
        .model
        .effects
        .iter()
        .map(|e| e.effect.name().to_owned())
        .chain(file.model.terms.iter().map(|t| t.formula.clone()))
        .collect();
    let report_path = a.report.then(|| out_path::report_beside(a.out));
    if let Some(p) = &report_path {
        let mut rep = Report::new(&format!(
            "Model {} applied to {}",
            a.coeffs.display(),
            a.data.display()
        ));
        let mut v = Verdict::new();
        v.text(&format!(
            "The {} model of {} ({}) applied to {}: what it adds to the reference rate taken off the output. Output less reference, RMS of {} s means: before ",
            gyro.name(),
            a.coeffs.display(),
            if names.is_empty() { "no effects".into() } else { names.join(", ") },
            a.data.display(),
            WINDOW_S
        ))
        .num("rms_before_dph", rms_b, 4)
        .text(" deg/h, after ")
        .num("rms_after_dph", rms_a, 4)
        .text(" deg/h; the mean after ")
        .num("mean_after_dph", mean_a, 4)
        .text(" +- ")
        .num("mean_after_se_dph", se_a, 4)
        .text(" deg/h.");
        for w in &checked.warnings {
            v.warning(w.code, &w.message);
        }
        rep.verdict(&v);
        rep.plot(
            &Axes::linear("Output less reference", "time, s", "deg/h"),
            &[
                Series::line("before", thin(before.clone(), 2000), 0),
                Series::line("after the model", thin(after.clone(), 2000), 1),
            ],
            &format!("Means over {WINDOW_S} s windows of the output less the reference rate, before and after the model's correction."),
        );
        write_report(&rep, p)?;
    }
    let j = serde_json::json!({
        "kind": "gyro_model",
        "gyro": gyro.name(),
        "applied": names,
        "window_s": WINDOW_S,
        "rms_before_dph": rms_b,
        "rms_after_dph": rms_a,
        "mean_before_dph": mean_b,
        "mean_after_dph": mean_a,
        "mean_after_se_dph": se_a,
        "out": a.out.display().to_string(),
        "report": report_path.as_ref().map(|p| p.display().to_string()),
    });
    if a.json {
        let mut j = j;
        checked.json(&mut j);
        println!("{j}");
        return Ok(());
    }
    checked.print();
    println!(
        "model {} ({}): output less reference, RMS of {} s means {} -> {} deg/h (mean after {} +- {})",
        a.coeffs.display(),
        if names.is_empty() { "no effects".into() } else { names.join(", ") },
        WINDOW_S,
        sig(rms_b),
        sig(rms_a),
        sig(mean_a),
        sig(se_a)
    );
    println!("written: {}", a.out.display());
    if let Some(p) = report_path {
        println!("report: {}", p.display());
    }
    Ok(())
}
