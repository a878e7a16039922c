//! `compensate` with a model from `discover` (`kind = "gyro_model"`)
//! applied to a run. The model's output is the reference rate plus its
//! effects and terms; what it adds to the reference is the gyro's error
//! it explains, and that is taken off the output: the compensated rate is
//! the output less (the model's output less the reference). The firmware
//! applies no such model: this is the lab's correction, for checking a
//! model on another run or cleaning a record before a noise analysis.

use super::outcome::{CompensateOutcome, Request};
use crate::commands::checks;
use crate::commands::model_file::ModelFile;
use crate::data::run_file::{Column, Reference, RunFile};
use crate::error::LabError;
use crate::model::gyro_kind::GyroKind;
use crate::model::inputs::Inputs;
use crate::model::ranges::Extent;
use crate::report::document::Report;
use crate::report::plot::{thin, Axes, Series};
use crate::report::text::sig;
use crate::report::verdict::Verdict;

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

/// The model applied to the run.
pub fn apply<'a>(
    req: &Request<'a>,
    file: &ModelFile,
    gyro: GyroKind,
) -> Result<CompensateOutcome<'a>, LabError> {
    let optional = [
        Column::Temp,
        Column::MonoA,
        Column::MonoB,
        Column::Case,
        Column::RefAcc,
    ];
    let (mut run_text, []) = RunFile::read(req.source, req.spec, Reference::ZeroIfAbsent, 2, [])?;
    run_text.fill_optional(&optional)?;
    let checked = checks::run(&mut run_text.run, req.spec)?;
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
        return Err(req.source.origin().whole(format!(
            "the model's effect `{}` needs column(s) {} that this run lacks",
            e.name(),
            names.join(", ")
        )));
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
    let coeffs = req.coeffs_name;
    let data = req.source.name();
    let report = req.report.then(|| {
        let mut rep = Report::new(&format!("Model {coeffs} applied to {data}"));
        let mut v = Verdict::new();
        v.text(&format!(
            "The {} model of {coeffs} ({}) applied to {data}: what it adds to the reference rate taken off the output. Output less reference, RMS of {} s means: before ",
            gyro.name(),
            if names.is_empty() { "no effects".into() } else { names.join(", ") },
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
        rep
    });
    let mut json = serde_json::json!({
        "kind": "gyro_model",
        "gyro": gyro.name(),
        "applied": names,
        "window_s": WINDOW_S,
        "rms_before_dph": rms_b,
        "rms_after_dph": rms_a,
        "mean_before_dph": mean_b,
        "mean_after_dph": mean_a,
        "mean_after_se_dph": se_a,
    });
    checked.json(&mut json);
    let mut text = checked.lines();
    text.push(format!(
        "model {coeffs} ({}): output less reference, RMS of {} s means {} -> {} deg/h (mean after {} +- {})",
        if names.is_empty() { "no effects".into() } else { names.join(", ") },
        WINDOW_S,
        sig(rms_b),
        sig(rms_a),
        sig(mean_a),
        sig(se_a)
    ));
    Ok(CompensateOutcome {
        run: run_text,
        comp_dps: comp,
        json,
        text,
        report,
        comment: String::new(),
    })
}
