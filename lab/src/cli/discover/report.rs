//! The discovery report (on the lab's one report writer, report/).

use crate::cli::adev_plot::adev_series;
use crate::model::discovery::{Discovery, Run, WINDOW_S};
use crate::model::effects::Effect;
use crate::noise::terms;
use crate::report::document::Report;
use crate::report::plot::{Axes, Series};
use crate::report::text::{num, sig};
use std::path::Path;

const DPH: f64 = 3600.0;

/// At most this many points per time plot (window means thinned evenly).
const MAX_POINTS: usize = 2000;

fn scale(v: &[f64]) -> Vec<f64> {
    v.iter().map(|x| x * DPH).collect()
}

fn thin(t: &[f64], y: &[f64]) -> Vec<(f64, f64)> {
    let step = t.len().div_ceil(MAX_POINTS).max(1);
    t.iter()
        .zip(y)
        .step_by(step)
        .map(|(a, b)| (*a, *b))
        .collect()
}

/// The residual over time before and after, and where it disagrees.
fn residual_section(r: &mut Report, d: &Discovery) {
    let win = &d.windows;
    let before = win.mean(&d.residual_before);
    let after = win.mean(&d.residual_after);
    r.heading("Residual before and after");
    r.plot(
        &Axes {
            title: "measured - model, 1 s means".into(),
            x_label: "time since power-on, s".into(),
            y_label: "residual, deg/h".into(),
            log_x: false,
            log_y: false,
        },
        &[
            Series::line("before", thin(&win.t, &scale(&before)), 0),
            Series::line("after", thin(&win.t, &scale(&after)), 1),
        ],
        "The residual averaged over the gap's windows, before and after the found effects were added.",
    );
    if !d.disagreements.is_empty() {
        let rows: Vec<Vec<String>> = d
            .disagreements
            .iter()
            .map(|s| vec![sig(s.from_s), sig(s.to_s), num(s.peak_dph)])
            .collect();
        r.table(
            &["from, s", "to, s", "peak residual (60 s mean), deg/h"],
            &rows,
        );
    }
}

/// The residual's Allan deviation before and after, against the floor.
fn allan_section(r: &mut Report, d: &Discovery) {
    if let (Some(a), Some(b)) = (&d.allan_before, &d.allan_after) {
        r.heading("Allan deviation before and after, against the noise floor");
        let mut s = adev_series(a, "before", 0, false);
        s.extend(adev_series(b, "after", 1, false));
        let floor: Vec<(f64, f64)> = a
            .taus
            .iter()
            .map(|&t| {
                let v: f64 = (0..3).map(|j| a.terms.c[j] * terms::basis(j, t)).sum();
                (t, v.sqrt() * DPH)
            })
            .collect();
        s.push(Series::dashed("noise floor", floor, 7));
        r.plot(
            &Axes {
                title: "Allan deviation of the residual".into(),
                x_label: "averaging time tau, s".into(),
                y_label: "Allan deviation, deg/h".into(),
                log_x: true,
                log_y: true,
            },
            &s,
            "A missing effect lifts the residual's Allan deviation above the noise floor (quantization, angle \
             random walk, bias instability) at long averaging; once it is in the model the curve comes down.",
        );
    }
}

/// The table of the effects found.
fn found_section(r: &mut Report, d: &Discovery) {
    r.heading("Effects found");
    if d.found.is_empty() {
        r.paragraph("Nothing is missing: no effect of the library beats the noise.");
    } else {
        let rows: Vec<Vec<String>> = d
            .found
            .iter()
            .map(|e| {
                let p: Vec<String> = e
                    .params
                    .iter()
                    .map(|(n, v, lo, hi)| {
                        format!("{n} = {} [{} .. {}]", sig(*v), sig(*lo), sig(*hi))
                    })
                    .collect();
                vec![
                    e.effect.name().into(),
                    p.join("; "),
                    format!("{:.1}", e.delta_bic),
                    format!("{:.1} %", 100.0 * e.explained_share),
                ]
            })
            .collect();
        r.table(
            &[
                "effect",
                "parameters (95 % interval)",
                "BIC change",
                "share of residual variance",
            ],
            &rows,
        );
    }
}

/// Each effect found against the residual it explains.
fn effect_plots(r: &mut Report, d: &Discovery, run: &Run) {
    let win = &d.windows;
    let after = win.mean(&d.residual_after);
    for e in &d.found {
        // The effect's contribution against the residual it explains (the
        // residual after, plus the effect back).
        let params = e.params.iter().map(|p| (p.0.to_owned(), p.1)).collect();
        let c = e.effect.contribution(&run.inputs, &params);
        let cw = win.mean(&c);
        let partial: Vec<f64> = after.iter().zip(&cw).map(|(a, b)| a + b).collect();
        let pts = thin(&scale(&cw), &scale(&partial));
        let (lo, hi) = cw
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| {
                (a.min(*x), b.max(*x))
            });
        r.plot(
            &Axes {
                title: format!("{}: regressor against residual", e.effect.name()),
                x_label: format!("{} contribution, deg/h", e.effect.name()),
                y_label: "residual with it, deg/h".into(),
                log_x: false,
                log_y: false,
            },
            &[
                Series::points("1 s means", pts, None, 0),
                Series::line("fitted", vec![(lo * DPH, lo * DPH), (hi * DPH, hi * DPH)], 1),
            ],
            &format!(
                "The residual the {} explains (after the model, with this effect put back) against the effect's \
                 fitted contribution: the points lie along the line when the effect is what was missing.",
                e.effect.name()
            ),
        );
    }
}

/// Groups of effects the run cannot tell apart, and the effects skipped.
fn ambiguous_and_skipped(r: &mut Report, d: &Discovery) {
    if !d.selection.ambiguous.is_empty() {
        r.heading("Effects this run cannot tell apart");
        let rows: Vec<Vec<String>> = d
            .selection
            .ambiguous
            .iter()
            .map(|g| {
                vec![
                    Effect::names(&g.effects, " / "),
                    format!("{:.3}", g.correlation.get(1).copied().unwrap_or(1.0)),
                    g.suggestion.clone(),
                ]
            })
            .collect();
        r.table(
            &[
                "effects",
                "correlation",
                "a test profile that separates them",
            ],
            &rows,
        );
    }
    if !d.skipped.is_empty() {
        r.note(&format!(
            "Skipped (the run lacks their inputs): {}.",
            d.skipped
                .iter()
                .map(|(e, c)| {
                    let names: Vec<&str> = c.iter().map(|c| c.name()).collect();
                    format!("{} ({})", e.name(), names.join(", "))
                })
                .collect::<Vec<_>>()
                .join("; ")
        ));
    }
}

pub fn report(d: &Discovery, run: &Run, data: &Path) -> Report {
    let mut r = Report::new(&format!("What the model misses: {}", data.display()));
    r.paragraph(&format!(
        "{} gyro, {} rows ({} s windows: {}). Gap (RMS of {WINDOW_S} s means of measured - model): {} deg/h \
         before, {} deg/h after; noise floor there {} deg/h (the Allan noise terms of the residual).",
        d.gyro.name(),
        run.inputs.len(),
        WINDOW_S,
        d.windows.len(),
        num(d.gap_before_dph),
        num(d.gap_after_dph),
        num(d.noise_floor_dph)
    ));
    residual_section(&mut r, d);
    allan_section(&mut r, d);
    found_section(&mut r, d);
    effect_plots(&mut r, d, run);
    ambiguous_and_skipped(&mut r, d);
    r
}
