//! The reports of `compensate`: a scale-factor table on a validation run
//! (the error before and after against time and coil temperature, the RMS
//! of 60 s means with its standard error, the spans outside the calibrated
//! range), or RLG thermal coefficients on a chamber run (the drift before
//! and after against time and temperature, against the noise floor).

use super::thermal::means_over_time;
use super::{against_floor, warnings, MAX_POINTS};
use crate::calibration::scale_factor::diagnostics::{by_temperature, TempBin};
use crate::calibration::scale_factor::residual::WindowMean;
use crate::calibration::scale_factor::validation::Validation;
use crate::calibration::thermal::figures::window_means;
use crate::calibration::thermal::fit::ThermalData;
use crate::calibration::thermal::summary::{CompensateSummary, WINDOW_S};
use crate::report::document::Report;
use crate::report::plot::{thin, Axes, Series};
use crate::report::verdict::Verdict;

fn sf_verdict((coeffs, data): &(String, String), v: &Validation) -> Verdict {
    let mut r = Verdict::new();
    r.text(&format!(
        "Applied the scale-factor table of {coeffs} to {data} as the firmware does (its fixed-point \
         code): "
    ))
    .count("table_nodes", v.table_nodes)
    .text(" nodes calibrated over ")
    .range("calibrated_range_c", v.calibrated_range_c, 2)
    .text(" degC, coil sensor lag ")
    .num("sensor_lag_s", v.sensor_lag_s, 1)
    .text(" s; ")
    .count("rows", v.rows)
    .text(" rows over ")
    .num("duration_s", v.duration_s, 0)
    .text(" s, ")
    .count("windows", v.windows)
    .text(" whole 60 s windows at a constant rate. Scale-factor error, RMS of 60 s means: before ")
    .num("raw_ppm", v.raw_ppm.value, 2)
    .text(" +- ")
    .num("raw_ppm_se", v.raw_ppm.se, 2)
    .text(" ppm, after ")
    .num("comp_ppm", v.comp_ppm.value, 3)
    .text(" +- ")
    .num("comp_ppm_se", v.comp_ppm.se, 3)
    .text(" ppm against a noise floor of ")
    .num("noise_floor_ppm.value", v.noise_floor_ppm.value, 3)
    .text(&format!(
        " ppm: {}.",
        against_floor(v.comp_ppm.value / v.noise_floor_ppm.value)
    ));
    warnings(&mut r, &v.warnings);
    r
}

fn pts(w: &[WindowMean], x: impl Fn(&WindowMean) -> f64) -> Vec<(f64, f64)> {
    thin(w.iter().map(|m| (x(m), m.ppm)).collect(), MAX_POINTS)
}

/// 1 degC bins of 60 s means against the coil sensor, mean +- 1 s.e.
fn binned(label: &str, w: &[WindowMean], color: usize) -> Series {
    let pts: Vec<(f64, f64)> = w.iter().map(|m| (m.extra, m.ppm)).collect();
    let bins: Vec<TempBin> = by_temperature(&pts, |_| 0.0);
    let se = |b: &TempBin| if b.se.is_finite() { b.se } else { 0.0 };
    Series::points(
        label,
        bins.iter().map(|b| (b.t_c, b.ppm)).collect(),
        Some(
            bins.iter()
                .map(|b| (b.ppm - se(b), b.ppm + se(b)))
                .collect(),
        ),
        color,
    )
}

/// The report of a scale-factor table applied to a run; `names`: the
/// coefficient file and the run.
pub fn scale_factor(names: &(String, String), v: &Validation) -> Report {
    let mut r = Report::new(&format!("Scale-factor compensation: {}", names.1));
    r.verdict(&sf_verdict(names, v));
    let hours = |m: &WindowMean| m.t_s / 3600.0;
    let bands = |r: &mut Vec<Series>| {
        if !v.out_of_range_spans.is_empty() {
            r.push(Series::bands(
                "coil outside the calibrated range",
                v.out_of_range_spans
                    .iter()
                    .map(|s| (s.from_s / 3600.0, s.to_s / 3600.0))
                    .collect(),
                1,
            ));
        }
    };
    r.heading("Before and after, against time");
    let mut s = vec![
        Series::line("before (nominal scale factor)", pts(&v.before, hours), 7),
        Series::line("after (the table)", pts(&v.after, hours), 0),
    ];
    bands(&mut s);
    r.plot(
        &Axes::linear(
            "Scale-factor error before and after, 60 s means",
            "time, h",
            "scale-factor error, ppm",
        ),
        &s,
        "The run's scale-factor error (output over reference rate, minus 1) in whole 60 s windows at a \
         constant rate, with the nominal scale factor and through the firmware's table (the means joined).",
    );
    let mut s = vec![Series::line("after (the table)", pts(&v.after, hours), 0)];
    bands(&mut s);
    let shaded = if v.out_of_range_spans.is_empty() {
        "the coil stayed inside the calibrated range"
    } else {
        "shaded, the spans where the coil was outside the calibrated range (the table held its end values)"
    };
    r.plot(
        &Axes::linear("After compensation", "time, h", "scale-factor error, ppm"),
        &s,
        &format!("The compensated error alone, at its own scale; {shaded}."),
    );
    r.heading("Before and after, against coil temperature");
    let (lo, hi) = (v.calibrated_range_c[0], v.calibrated_range_c[1]);
    let outside = |s: &mut Vec<Series>| {
        let (a, b) = v
            .after
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), m| {
                (a.min(m.extra), b.max(m.extra))
            });
        let mut spans = vec![];
        if a < lo {
            spans.push((a, lo));
        }
        if b > hi {
            spans.push((hi, b));
        }
        if !spans.is_empty() {
            s.push(Series::bands("outside the calibrated range", spans, 1));
        }
    };
    let mut s = vec![
        binned("before, 1 degC bins (+-1 s.e.)", &v.before, 7),
        binned("after, 1 degC bins (+-1 s.e.)", &v.after, 0),
    ];
    outside(&mut s);
    r.plot(
        &Axes::linear(
            "Scale-factor error against coil temperature",
            "coil sensor, degC",
            "scale-factor error, ppm",
        ),
        &s,
        "The same windows binned by the coil sensor's mean over each (1 degC bins, mean and standard \
         error): before, the scale factor's temperature dependence; after, what the table leaves.",
    );
    let mut s = vec![binned("after, 1 degC bins (+-1 s.e.)", &v.after, 0)];
    outside(&mut s);
    r.plot(
        &Axes::linear(
            "After compensation, against coil temperature",
            "coil sensor, degC",
            "scale-factor error, ppm",
        ),
        &s,
        "The compensated error against the coil sensor: a slope or a bend here is a knee or curvature the \
         table lacks, or a lag it has wrong.",
    );
    r.heading("Figures");
    r.table(
        &["RMS of 60 s means", "ppm", "standard error, ppm"],
        &[
            vec![
                "before".into(),
                format!("{:.3}", v.raw_ppm.value),
                format!("{:.3}", v.raw_ppm.se),
            ],
            vec![
                "after".into(),
                format!("{:.4}", v.comp_ppm.value),
                format!("{:.4}", v.comp_ppm.se),
            ],
            vec![
                "noise floor".into(),
                format!("{:.4}", v.noise_floor_ppm.value),
                format!("{:.4}", v.noise_floor_ppm.se),
            ],
        ],
    );
    if v.out_of_range_spans.is_empty() {
        r.paragraph("The coil stayed inside the calibrated range over the whole run.");
    } else {
        let rows: Vec<Vec<String>> = v
            .out_of_range_spans
            .iter()
            .map(|s| {
                vec![
                    format!("{:.0}", s.from_s),
                    format!("{:.0}", s.to_s),
                    format!("{:.2} .. {:.2}", s.min_c, s.max_c),
                ]
            })
            .collect();
        r.table(
            &[
                "outside the calibrated range: from, s",
                "to, s",
                "coil sensor, degC",
            ],
            &rows,
        );
    }
    r
}

fn th_verdict((coeffs, data): &(String, String), s: &CompensateSummary) -> Verdict {
    let mut v = Verdict::new();
    v.text(&format!(
        "Applied the RLG thermal coefficients of {coeffs} to {data} as the firmware does (its \
         fixed-point code): "
    ))
    .count("rows", s.rows)
    .text(" rows over ")
    .num("duration_s", s.duration_s, 0)
    .text(" s. Drift, std of 100 s means: before ")
    .num("raw_std_100s_dph", s.raw_std_100s_dph, 4)
    .text(" +- ")
    .num("raw_std_100s_se_dph", s.raw_std_100s_se_dph, 4)
    .text(" deg/h, after ")
    .num("comp_std_100s_dph", s.comp_std_100s_dph, 4)
    .text(" +- ")
    .num("comp_std_100s_se_dph", s.comp_std_100s_se_dph, 4)
    .text(" deg/h against a noise floor of ")
    .num("noise_floor_100s_dph", s.noise_floor_100s_dph, 4)
    .text(&format!(" deg/h: {}", against_floor(s.comp_over_floor)));
    if let Some(c) = s.cubic_std_100s_dph {
        v.text(" (the classic cubic leaves ")
            .num("cubic_std_100s_dph", c, 4)
            .text(" deg/h)");
    }
    v.text(".");
    if let Some(range) = &s.calibrated_range {
        v.text(" The fit saw monoblock A ")
            .range("calibrated_range.mono_a_c", range.mono_a_c, 1)
            .text(" degC; ")
            .count("out_of_range_spans.length", s.out_of_range_spans.len())
            .text(" span(s) of this run lay outside it.");
    }
    warnings(&mut v, &s.warnings);
    v
}

/// The report of RLG thermal coefficients applied to a chamber run.
pub fn thermal(names: &(String, String), d: &ThermalData, s: &CompensateSummary) -> Report {
    let mut r = Report::new(&format!("RLG thermal compensation: {}", names.1));
    r.verdict(&th_verdict(names, s));
    r.heading("Before and after");
    let mut series = vec![
        Series::line("before", means_over_time(&d.t, &d.drift_dph), 7),
        Series::line("after", means_over_time(&d.t, &s.comp_drift_dph), 0),
    ];
    if !s.out_of_range_spans.is_empty() {
        series.push(Series::bands(
            "outside the fit's temperatures",
            s.out_of_range_spans
                .iter()
                .map(|x| (x.from_s / 3600.0, x.to_s / 3600.0))
                .collect(),
            1,
        ));
    }
    r.plot(
        &Axes::linear("Drift against time, 100 s means", "time, h", "drift, deg/h"),
        &series,
        "Output minus the reference rate before and after the firmware's compensation, 100 s means; \
         shaded, any span where the run left the temperatures the fit saw (the model extrapolated).",
    );
    let ta = window_means(&d.t, &d.a, WINDOW_S);
    let before = window_means(&d.t, &d.drift_dph, WINDOW_S);
    let after = window_means(&d.t, &s.comp_drift_dph, WINDOW_S);
    r.plot(
        &Axes::linear(
            "Drift against temperature, 100 s means",
            "monoblock sensor A, degC",
            "drift, deg/h",
        ),
        &[
            Series::points("before", ta.iter().copied().zip(before).collect(), None, 7),
            Series::points("after", ta.iter().copied().zip(after).collect(), None, 0),
        ],
        "The same means against the monoblock temperature: what is left after compensation should not \
         follow the temperature.",
    );
    r.table(
        &["std of 100 s means", "deg/h", "standard error, deg/h"],
        &[
            vec![
                "before".into(),
                format!("{:.4}", s.raw_std_100s_dph),
                format!("{:.4}", s.raw_std_100s_se_dph),
            ],
            vec![
                "after".into(),
                format!("{:.4}", s.comp_std_100s_dph),
                format!("{:.4}", s.comp_std_100s_se_dph),
            ],
            vec![
                "noise floor".into(),
                format!("{:.4}", s.noise_floor_100s_dph),
                format!("{:.4}", s.noise_floor_100s_se_dph),
            ],
        ],
    );
    match &s.calibrated_range {
        None => r.paragraph(
            "The coefficient file does not state the temperatures its fit saw (written before they were \
             kept): no check of the calibrated range.",
        ),
        Some(_) if s.out_of_range_spans.is_empty() => {
            r.paragraph("The run stayed inside the temperatures the fit saw.")
        }
        Some(_) => {
            let rows: Vec<Vec<String>> = s
                .out_of_range_spans
                .iter()
                .map(|x| {
                    vec![
                        format!("{:.0}", x.from_s),
                        format!("{:.0}", x.to_s),
                        format!("{:.2} .. {:.2}", x.min_c, x.max_c),
                    ]
                })
                .collect();
            r.table(
                &[
                    "outside the fit's temperatures: from, s",
                    "to, s",
                    "monoblock A, degC",
                ],
                &rows,
            )
        }
    }
    r
}
