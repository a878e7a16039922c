//! The report of `fit thermal`: the verdict; the drift against time before
//! and after (the model, and the classic cubic for comparison); the
//! coefficients with their 95 % intervals; the residual's Allan deviation
//! against the noise floor; the temperatures and the thermal difference.

use super::{against_floor, warnings, MAX_POINTS};
use crate::calibration::thermal::figures::window_means;
use crate::calibration::thermal::fit::ThermalData;
use crate::calibration::thermal::summary::{FitSummary, WINDOW_S};
use crate::commands::adev_plot::adev_series;
use crate::noise::analysis::analyse;
use crate::noise::terms;
use crate::report::document::Report;
use crate::report::plot::{thin, Axes, Series};
use crate::report::text::sig;
use crate::report::verdict::Verdict;

const DPH: f64 = 3600.0;

/// (time h, value) of the `WINDOW_S` means of `x`.
pub fn means_over_time(t: &[f64], x: &[f64]) -> Vec<(f64, f64)> {
    let tm = window_means(t, t, WINDOW_S);
    let xm = window_means(t, x, WINDOW_S);
    tm.iter().zip(&xm).map(|(a, b)| (a / 3600.0, *b)).collect()
}

fn verdict(s: &FitSummary) -> Verdict {
    let mut v = Verdict::new();
    let se = s.std_100s_se_dph;
    v.text(
        "Fitted the RLG thermal bias model B = bias0 + K1 dT + K2 grad(dT) + K3 dT^2 + K4 T_K + \
         K5 (1 - exp(-t/tau_warm)) (dT the monoblock sensors' difference, T_K the case sensor in degC) on ",
    )
    .count("rows", s.rows)
    .text(" rows over ")
    .num("duration_s", s.duration_s, 0)
    .text(" s; monoblock sensor A ")
    .range("mono_a_range_c", s.mono_a_range_c, 1)
    .text(" degC, case ")
    .range("case_range_c", s.case_range_c, 1)
    .text(" degC. Drift, std of 100 s means: raw ")
    .num("raw_std_100s_dph", s.raw_std_100s_dph, 4)
    .text(" +- ")
    .num("std_100s_se_dph.0", se[0], 4)
    .text(" deg/h, the classic one-sensor cubic ")
    .num("cubic_std_100s_dph", s.cubic_std_100s_dph, 4)
    .text(" deg/h, the model's residual ")
    .num("residual_std_100s_dph", s.residual_std_100s_dph, 4)
    .text(" +- ")
    .num("std_100s_se_dph.1", se[1], 4)
    .text(" deg/h against a noise floor of ")
    .num("noise_floor_100s_dph", s.noise_floor_100s_dph, 4)
    .text(" +- ")
    .num("std_100s_se_dph.3", se[3], 4)
    .text(&format!(
        " deg/h: {}. The warm-up time constant is ",
        against_floor(s.residual_std_100s_dph / s.noise_floor_100s_dph)
    ))
    .num("coefficients.tau_warm_s", s.coefficients.tau_warm_s, 0)
    .text(" s.");
    warnings(&mut v, &s.warnings);
    v
}

fn coefficient_table(r: &mut Report, s: &FitSummary) {
    let names = [
        ("bias0", "deg/h"),
        ("K1 (dT)", "deg/h per degC"),
        ("K2 (grad dT)", "deg/h per degC/s"),
        ("K3 (dT^2)", "deg/h per degC^2"),
        ("K4 (case temperature T_K, degC)", "deg/h per degC"),
        ("K5 (warm-up)", "deg/h"),
        ("tau_warm", "s"),
    ];
    let v = s.coefficients.values();
    let e = s.coefficient_se.map(|c| c.values());
    let rows: Vec<Vec<String>> = names
        .iter()
        .enumerate()
        .map(|(k, (n, u))| {
            let (se, lo, hi) = match e {
                Some(e) => (sig(e[k]), sig(v[k] - 1.96 * e[k]), sig(v[k] + 1.96 * e[k])),
                None => ("-".into(), "-".into(), "-".into()),
            };
            vec![(*n).into(), sig(v[k]), se, lo, hi, (*u).into()]
        })
        .collect();
    r.table(
        &[
            "coefficient",
            "value",
            "standard error",
            "95 % low",
            "95 % high",
            "unit",
        ],
        &rows,
    );
    r.note(
        "Standard errors from the least-squares covariance with the residual's variance inflated for its \
         correlation (batch means of 100 s); tau_warm's from the curvature of the residual sum in ln(tau).",
    );
}

fn allan_plot(r: &mut Report, d: &ThermalData, s: &FitSummary) {
    let n = d.t.len();
    if n < 10 {
        return;
    }
    let tau0 = (d.t[n - 1] - d.t[0]) / (n - 1) as f64;
    let raw: Vec<f64> = d.drift_dph.iter().map(|x| x / DPH).collect();
    let res: Vec<f64> = s.residual_dph.iter().map(|x| x / DPH).collect();
    let (Ok(a_raw), Ok(a_res)) = (analyse(&raw, tau0), analyse(&res, tau0)) else {
        return;
    };
    let mut series = adev_series(&a_raw, "raw drift", 7, false);
    series.extend(adev_series(&a_res, "residual after the model", 0, false));
    let floor: Vec<(f64, f64)> = a_res
        .taus
        .iter()
        .map(|&t| {
            let v: f64 = (0..3).map(|j| a_res.terms.c[j] * terms::basis(j, t)).sum();
            (t, v.sqrt() * DPH)
        })
        .collect();
    series.push(Series::dashed(
        "noise floor (quantization, ARW, bias instability)",
        floor,
        1,
    ));
    r.plot(
        &Axes {
            title: "Allan deviation of the residual against the noise floor".into(),
            x_label: "averaging time tau, s".into(),
            y_label: "Allan deviation, deg/h".into(),
            log_x: true,
            log_y: true,
        },
        &series,
        "The residual's Allan deviation (95 % intervals) against the noise terms fitted to it: where the \
         residual rises above the floor at long averaging, the model misses a slow thermal effect; the raw \
         drift's deviation shows what was removed.",
    );
}

/// The report of a thermal fit on the run `name`.
pub fn report(name: &str, d: &ThermalData, s: &FitSummary) -> Report {
    let mut r = Report::new(&format!("RLG thermal bias model: {name}"));
    r.verdict(&verdict(s));
    r.heading("Drift before and after");
    r.plot(
        &Axes::linear("Drift against time, 100 s means", "time, h", "drift, deg/h"),
        &[
            Series::line("raw drift", means_over_time(&d.t, &d.drift_dph), 7),
            Series::line(
                "after the classic cubic",
                means_over_time(&d.t, &s.cubic_residual_dph),
                3,
            ),
            Series::line(
                "after the model",
                means_over_time(&d.t, &s.residual_dph),
                0,
            ),
        ],
        "Output minus the reference rate, before and after the fitted thermal model (and after the \
         classic one-sensor cubic, for comparison), 100 s means.",
    );
    r.heading("Coefficients");
    coefficient_table(&mut r, s);
    r.heading("Residual against the noise floor");
    allan_plot(&mut r, d, s);
    r.heading("Temperatures and the thermal difference");
    let th = |x: &[f64]| {
        thin(
            d.t.iter()
                .map(|t| t / 3600.0)
                .zip(x.iter().copied())
                .collect(),
            MAX_POINTS,
        )
    };
    r.plot(
        &Axes::linear("Temperatures", "time, h", "temperature, degC"),
        &[
            Series::line("monoblock A", th(&d.a), 0),
            Series::line("monoblock B", th(&d.b), 1),
            Series::dashed("case", th(&d.case), 2),
        ],
        "The two monoblock sensors and the case sensor over the run.",
    );
    let dt: Vec<f64> = d.a.iter().zip(&d.b).map(|(a, b)| a - b).collect();
    r.plot(
        &Axes::linear("Thermal difference", "time, h", "dT = T_a - T_b, degC"),
        &[Series::line("dT", th(&dt), 0)],
        "The difference of the two monoblock sensors: the model's K1, K3 and (through its rate) K2 terms \
         stand on it; a term whose regressor hardly moves is not resolved.",
    );
    r
}
