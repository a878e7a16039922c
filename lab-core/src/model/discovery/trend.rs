//! What the inputs explain that the noise model could absorb. A slow
//! noise (a rate random walk, a flicker) fitted to a residual takes any
//! smooth wander as its own, so a model that leaves a bow the temperature
//! explains can be judged "at its noise". Here the residual after the
//! model is asked directly: does a simple function of an input (a
//! polynomial of degree two or three in a temperature, or its rate of
//! change) predict blocks of the record it was not fitted on, beyond the
//! residual's white noise? Where it does, what is left is named, with the
//! function, the reduction it makes and the slow noise that would
//! otherwise have carried it: whether the record can tell the two apart is
//! said, not decided silently for the noise.

use super::unexplained::{Correlate, Span, Unexplained};
use super::windows::Windows;
use crate::data::run_file::Column;
use crate::model::inputs::Inputs;
use crate::model::proposal::validation::{cross_validate, stats, FOLDS, THRESHOLD};
use std::collections::BTreeMap;

/// A temperature must span this much over the record for a function of
/// it to be asked, degC (below, a function of it is a constant).
pub const MIN_SPAN_C: f64 = 1.0;
/// The function must explain at least this share of the residual's
/// variance (window means) to be more than a detail.
pub const MIN_SHARE: f64 = 0.05;

/// A function of the inputs that predicts what the model leaves.
#[derive(Clone, Debug)]
pub struct InputTrend {
    /// The function in the term language (a polynomial about the
    /// temperature's mean, or its rate of change).
    pub formula: String,
    pub input: String,
    /// Held-out reduction in white-noise variances (blocked
    /// cross-validation, proposal/validation.rs).
    pub held_out_gain: f64,
    /// RMS of the residual's window means without and with it, deg/h.
    pub rms_before_dph: f64,
    pub rms_after_dph: f64,
    /// Its fitted values per window, deg/s.
    pub fitted: Vec<f64>,
    /// The coefficients (`a1`, `a2`, .., deg/h per unit of each power)
    /// and their 95 % intervals under white noise.
    pub params: BTreeMap<String, f64>,
    pub intervals: BTreeMap<String, (f64, f64)>,
}

/// The white noise of window means: the scatter of their first
/// differences (median absolute, robust to steps), over sqrt(2).
fn white_sd(x: &[f64]) -> f64 {
    let mut d: Vec<f64> = x.windows(2).map(|w| (w[1] - w[0]).abs()).collect();
    if d.is_empty() {
        return 0.0;
    }
    let k = d.len() / 2;
    let med = *d.select_nth_unstable_by(k, f64::total_cmp).1;
    med / (0.674_489_750 * std::f64::consts::SQRT_2)
}

fn centred(mut x: Vec<f64>, keep: &[bool]) -> Vec<f64> {
    let (s, n) = x
        .iter()
        .zip(keep)
        .filter(|p| *p.1)
        .fold((0.0, 0.0), |a, p| (a.0 + p.0, a.1 + 1.0));
    let m = if n > 0.0 { s / n } else { 0.0 };
    x.iter_mut().for_each(|v| *v -= m);
    x
}

/// The candidate functions: per temperature spanning [`MIN_SPAN_C`], a
/// line, a square and a square with a cube about its mean (window means),
/// and its rate of change.
fn candidates(inp: &Inputs, win: &Windows) -> Vec<(String, String, Vec<Vec<f64>>)> {
    let mut out = vec![];
    let mut temps: Vec<(&str, &[f64])> = vec![];
    if let Some(t) = &inp.temp {
        temps.push((Column::Temp.name(), t));
    }
    if let Some((a, b)) = &inp.mono {
        temps.push((Column::MonoA.name(), a));
        temps.push((Column::MonoB.name(), b));
    }
    if let Some(c) = &inp.case {
        temps.push((Column::Case.name(), c));
    }
    for (name, x) in temps {
        let m = win.mean(x);
        let (lo, hi) = m.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |a, &v| {
            (a.0.min(v), a.1.max(v))
        });
        if hi - lo < MIN_SPAN_C || hi.is_nan() || lo.is_nan() {
            continue;
        }
        let mean = m.iter().sum::<f64>() / m.len() as f64;
        let p = |k: i32| m.iter().map(|v| (v - mean).powi(k)).collect::<Vec<f64>>();
        let c = format!("{mean:.2}");
        // Linear alone (a temperature the library has no linear effect
        // of), then the curvature the library has none of.
        out.push((name.to_owned(), format!("a1*({name} - {c})"), vec![p(1)]));
        out.push((name.to_owned(), format!("a1*({name} - {c})^2"), vec![p(2)]));
        out.push((
            name.to_owned(),
            format!("a1*({name} - {c})^2 + a2*({name} - {c})^3"),
            vec![p(2), p(3)],
        ));
        let rate = crate::model::inputs::centered_slope(
            &inp.t,
            x,
            crate::model::inputs::RATE_HALF_WIDTH_S,
        );
        out.push((
            name.to_owned(),
            format!("a1*ddt({name})"),
            vec![win.mean(&rate)],
        ));
    }
    out
}

/// The function of the inputs that best predicts `after` (window means of
/// the residual after the model, deg/s) out of sample, where one passes
/// [`THRESHOLD`] white-noise variances and explains [`MIN_SHARE`] of it.
pub fn input_trend(
    inp: &Inputs,
    win: &Windows,
    after: &[f64],
    keep: &[bool],
) -> Option<InputTrend> {
    let n = after.len();
    if n < 4 * FOLDS {
        return None;
    }
    let sd = white_sd(after);
    if sd.is_nan() || sd <= 0.0 {
        return None;
    }
    let kept = |x: &[f64]| -> Vec<f64> {
        x.iter()
            .zip(keep)
            .map(|(v, &k)| if k { *v } else { 0.0 })
            .collect()
    };
    let y = kept(&centred(after.to_vec(), keep));
    let yw: Vec<f64> = y.iter().map(|v| v / sd).collect();
    let total: f64 = y.iter().map(|v| v * v).sum();
    let mut best: Option<(f64, InputTrend)> = None;
    for (input, formula, cols) in candidates(inp, win) {
        let cols: Vec<Vec<f64>> = cols.into_iter().map(|c| kept(&centred(c, keep))).collect();
        let st = stats(&cols, &yw, FOLDS);
        let (gain, _) = cross_validate(std::slice::from_ref(&st), FOLDS);
        let Some((beta, red)) = st.fit(None) else {
            continue;
        };
        let share = red * sd * sd / total.max(f64::MIN_POSITIVE);
        if gain < THRESHOLD || share < MIN_SHARE {
            continue;
        }
        // The simplest of those that pass: fewer columns unless more
        // predict clearly better (by the threshold again).
        let better = match &best {
            None => true,
            Some((g, b)) => gain > g + THRESHOLD || (gain > *g && b.formula.len() >= formula.len()),
        };
        if !better {
            continue;
        }
        let fitted: Vec<f64> = (0..n)
            .map(|i| sd * cols.iter().zip(&beta).map(|(c, b)| c[i] * b).sum::<f64>())
            .collect();
        let rms = |v: &dyn Fn(usize) -> f64| {
            let (s, m) = (0..n)
                .filter(|&i| keep[i])
                .fold((0.0f64, 0.0f64), |a, i| (a.0 + v(i) * v(i), a.1 + 1.0));
            (s / m.max(1.0)).sqrt() * 3600.0
        };
        // Coefficients in deg/h, 95 % intervals from (X'X)^-1 of the
        // whitened columns (unit noise variance).
        let (xx, _) = st.sums(None);
        let m = beta.len();
        let mut params = BTreeMap::new();
        let mut intervals = BTreeMap::new();
        for j in 0..m {
            let e: Vec<f64> = (0..m).map(|i| f64::from(u8::from(i == j))).collect();
            let var = crate::model::proposal::validation::solve(&xx, &e).map_or(f64::NAN, |v| v[j]);
            let (v, h) = (
                beta[j] * sd * 3600.0,
                1.96 * var.max(0.0).sqrt() * sd * 3600.0,
            );
            params.insert(format!("a{}", j + 1), v);
            intervals.insert(format!("a{}", j + 1), (v - h, v + h));
        }
        let t = InputTrend {
            formula,
            input,
            held_out_gain: gain,
            rms_before_dph: rms(&|i| y[i]),
            rms_after_dph: rms(&|i| y[i] - fitted[i]),
            fitted,
            params,
            intervals,
        };
        best = Some((gain, t));
    }
    best.map(|b| b.1)
}

impl InputTrend {
    /// What is left, said: the function, what it takes off, and the slow
    /// noise (`slow`: the fitted random walk, deg/h/sqrt(h), and bias
    /// instability, deg/h) that otherwise carried it.
    pub fn unexplained(&self, win: &Windows, slow: (f64, f64)) -> Unexplained {
        let t = &win.t;
        let mut spans: Vec<Span> = vec![];
        let block = 60usize.min(t.len().max(1));
        for (b, c) in self.fitted.chunks(block).enumerate() {
            let (a, e) = (b * block, b * block + c.len() - 1);
            let m = c.iter().sum::<f64>() / c.len() as f64 * 3600.0;
            let rms = self.rms_before_dph - self.rms_after_dph;
            if m.abs() < rms.max(0.0) {
                continue;
            }
            match spans.last_mut() {
                Some(s) if s.to_s >= t[a] - 1.0 => {
                    s.to_s = t[e];
                    if m.abs() > s.peak_dph.abs() {
                        s.peak_dph = m;
                    }
                }
                _ => spans.push(Span {
                    from_s: t[a],
                    to_s: t[e],
                    peak_dph: m,
                }),
            }
        }
        let excess = (self.rms_before_dph.powi(2) - self.rms_after_dph.powi(2))
            .max(0.0)
            .sqrt();
        Unexplained {
            excess_dph: excess,
            spans,
            correlates: vec![Correlate {
                input: self.formula.clone(),
                correlation: (excess / self.rms_before_dph.max(f64::MIN_POSITIVE)).min(1.0),
            }],
            carried_by: vec![format!(
                "a function of `{}`, {}, predicts blocks of the record it was not fitted on by {:.0} white-noise variances (threshold {THRESHOLD}) and takes the residual's RMS from {:.4} to {:.4} deg/h; the noise model would carry it as a random walk of {} deg/h/sqrt(h) and a bias instability of {} deg/h. Where `{}` moves one way only, this record cannot tell a slow noise from an effect of it: the effect is the physical reading, the noise the cautious one",
                self.input,
                self.formula,
                self.held_out_gain,
                self.rms_before_dph,
                self.rms_after_dph,
                crate::report::text::sig(slow.0),
                crate::report::text::sig(slow.1),
                self.input
            )],
            spikes: 0,
            input_function: Some(self.formula.clone()),
        }
    }
}
