//! The Allan deviation plot's series (measured points with intervals, the
//! fitted model and each present term, deg/h), shared by the `allan` and
//! `discover` reports; the `allan` report's marks (the readings on the
//! curve) and its misfit panel.

use crate::noise::analysis::Allan;
use crate::noise::terms::{shape_name, ALL, COUNT, MARKOV, SIN};
use crate::report::annotated::Mark;
use crate::report::plot::Series;
use crate::report::text::num;

const DPH: f64 = 3600.0;

/// 200 log-spaced averaging times over the measured ones.
fn grid(an: &Allan) -> Vec<f64> {
    let (a, b) = (an.taus[0].ln(), an.taus[an.taus.len() - 1].ln());
    (0..=200)
        .map(|i| (a + (b - a) * i as f64 / 200.0).exp())
        .collect()
}

/// Name of a shape on the plot.
fn label(j: usize) -> &'static str {
    match j {
        0 => "quantization / white angle",
        1 => "angle random walk",
        2 => "bias instability",
        3 => "rate random walk",
        4 => "rate ramp",
        SIN => "sinusoid",
        MARKOV => "Markov (correlated)",
        _ => shape_name(j),
    }
}

/// The Allan deviation plot (measured points with intervals, the fitted
/// model and each present term), in deg/h.
pub fn adev_series(an: &Allan, label_: &str, color: usize, terms: bool) -> Vec<Series> {
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
    let mut v = vec![Series::points(label_, pts, Some(errs), color)];
    if terms {
        let grid = grid(an);
        v.push(Series::line(
            "fitted model",
            grid.iter()
                .map(|&t| (t, an.terms.model_at(t).sqrt() * DPH))
                .collect(),
            1,
        ));
        for j in 0..ALL {
            let on = if j < COUNT {
                an.terms.present[j]
            } else {
                an.terms.shapes.c[j] > 0.0
            };
            if on {
                v.push(Series::dashed(
                    label(j),
                    grid.iter()
                        .map(|&t| (t, an.terms.shapes.part(j, t).sqrt() * DPH))
                        .collect(),
                    2 + j,
                ));
            }
        }
    }
    v
}

/// The measured points the model misses (outside their 95 % interval), to
/// draw over the others.
pub fn missed_series(an: &Allan) -> Option<Series> {
    let out = &an.terms.goodness.outside;
    if out.is_empty() {
        return None;
    }
    let pts = out
        .iter()
        .map(|&i| (an.taus[i], an.avar[i].sqrt() * DPH))
        .collect();
    let errs = out
        .iter()
        .map(|&i| (an.avar_lo[i].sqrt() * DPH, an.avar_hi[i].sqrt() * DPH))
        .collect();
    Some(Series::points("missed by the model", pts, Some(errs), 3))
}

/// The conventional readings on the curve: the -1/2 line through the
/// -1/2 region (dotted) with N at tau = 1 s, and the floor.
pub fn reading_marks(an: &Allan) -> (Vec<Series>, Vec<Mark>) {
    let r = &an.readings;
    let mut series = vec![];
    let mut marks = vec![];
    if let (Some(n), Some((a, b))) = (r.arw_dpsh, r.arw_region_s) {
        // sigma(tau) = N 60 / sqrt(tau) deg/h, drawn over the region and to
        // 1 s.
        let (lo, hi) = (a.min(1.0), b.max(1.0));
        let line: Vec<(f64, f64)> = (0..=20)
            .map(|i| {
                let t = (lo.ln() + (hi.ln() - lo.ln()) * i as f64 / 20.0).exp();
                (t, n * 60.0 / t.sqrt())
            })
            .collect();
        series.push(Series::dashed("-1/2 line read at 1 s", line, 7));
        marks.push(Mark {
            x: 1.0,
            y: n * 60.0,
            label: format!("N = {} deg/sqrt(h)", num(n)),
            color: 7,
        });
    }
    marks.push(Mark {
        x: r.floor_tau_s,
        y: r.floor_dph,
        label: format!(
            "floor {} deg/h: B {} {}",
            num(r.floor_dph),
            if r.resolved { "=" } else { "<=" },
            num(r.bias_instability_dph)
        ),
        color: 5,
    });
    (series, marks)
}

/// The misfit panel: the normalised residual (measured - model) / sd of
/// each Allan-variance estimate, with the +-1.96 band a right model keeps
/// to 95 % of the time.
pub fn misfit_series(an: &Allan) -> Vec<Series> {
    let g = &an.terms.goodness;
    let n = an.taus.len();
    let inside: Vec<(f64, f64)> = (0..n)
        .filter(|i| !g.outside.contains(i))
        .map(|i| (an.taus[i], g.z[i]))
        .collect();
    let missed: Vec<(f64, f64)> = g.outside.iter().map(|&i| (an.taus[i], g.z[i])).collect();
    let (a, b) = (an.taus[0], an.taus[n - 1]);
    let mut v = vec![Series::points("(measured - model) / sd", inside, None, 0)];
    if !missed.is_empty() {
        v.push(Series::points("missed by the model", missed, None, 3));
    }
    v.push(Series::line("model", vec![(a, 0.0), (b, 0.0)], 1));
    v.push(Series::dashed("+-1.96 sd", vec![(a, 1.96), (b, 1.96)], 7));
    v.push(Series::dashed("", vec![(a, -1.96), (b, -1.96)], 7));
    v
}
