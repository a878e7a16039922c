//! How far a residual stands above its own noise: the gap (the RMS of its
//! window means), the noise floor there, and the stretches where it stands
//! out.

use super::noise_model::{markov_mean_var, NoiseModel};
use super::white::white_var_of_diffs;
use super::windows::Windows;
use crate::noise::analysis::{analyse, Allan};
use crate::noise::gaps::fill_gaps;
use crate::noise::terms;

/// A stretch where the model and the data disagree.
#[derive(Clone, Debug, serde::Serialize)]
pub struct Disagreement {
    pub from_s: f64,
    pub to_s: f64,
    /// Largest smoothed residual there, deg/h.
    pub peak_dph: f64,
}

/// RMS of the window means of `r` (deg/s) in deg/h.
pub fn gap(win: &Windows, r: &[f64]) -> f64 {
    let m = win.mean(r);
    (m.iter().map(|v| v * v).sum::<f64>() / m.len().max(1) as f64).sqrt() * 3600.0
}

/// The Allan analysis of a residual when its sampling allows.
pub fn allan_of(t: &[f64], r: &[f64]) -> Option<Allan> {
    if t.len() < 10 {
        return None;
    }
    // Lost frames leave whole-sample gaps; the residual's noise model is
    // read from the series made uniform (noise/gaps.rs).
    let f = fill_gaps(t, r).ok()?;
    analyse(&f.values, f.tau0).ok()
}

/// The noise of a mean over `tau` from a residual's Allan model
/// (quantization 2Q^2/tau^2, the variance of a mean of white angle noise;
/// angle random walk N^2/tau; bias instability its floor), deg/h; a robust
/// scatter of first differences when the Allan analysis is not possible.
fn noise_at(a: Option<&Allan>, t: &[f64], r: &[f64], tau: f64) -> f64 {
    if let Some(a) = a {
        let c = &a.terms.c;
        let v = 2.0 * c[0] / (tau * tau) + c[1] / tau + c[2] * terms::basis(2, tau);
        if v > 0.0 {
            return v.sqrt() * 3600.0;
        }
    }
    let d2: Vec<f64> = r.windows(2).map(|w| (w[1] - w[0]).powi(2)).collect();
    let sigma = white_var_of_diffs(&d2).unwrap_or(0.0).sqrt();
    let dt = (t[t.len() - 1] - t[0]) / (t.len() - 1).max(1) as f64;
    sigma * (dt / tau).min(1.0).sqrt() * 3600.0
}

/// The noise floor of the gap over windows `win` of `window_s`: the
/// measured Allan deviation at the window (a periodic error, the FOG's
/// under vibration, averages out of a window mean and out of it; it reads
/// white angle noise sqrt(3/2) high), robustly (the median of the squared
/// differences of consecutive window means, so slow effects and a few
/// steps are differenced away), or the Allan model's noise of a window
/// mean where that is lower, deg/h.
pub fn noise_floor(
    win: &Windows,
    allan: Option<&Allan>,
    t: &[f64],
    r: &[f64],
    window_s: f64,
) -> f64 {
    let model_floor = noise_at(allan, t, r, window_s);
    let means = win.mean(r);
    let d2: Vec<f64> = means.windows(2).map(|p| (p[1] - p[0]).powi(2)).collect();
    let measured = white_var_of_diffs(&d2).map_or(f64::INFINITY, |v| v.sqrt() * 3600.0);
    if d2.len() >= 10 {
        measured.min(model_floor)
    } else {
        model_floor
    }
}

/// The stretches where the residual smoothed over `smooth_s` stands more
/// than three floors out; the floor there is the Allan noise terms
/// (quantization, angle random walk, bias instability: a missing effect's
/// drift shows as the others) at `smooth_s`.
pub fn disagreements(
    t: &[f64],
    r: &[f64],
    allan: Option<&Allan>,
    smooth_s: f64,
) -> Vec<Disagreement> {
    let smooth = Windows::new(t, smooth_s);
    let sm = smooth.mean(r);
    let floor_s = noise_at(allan, t, r, smooth_s);
    let mut disagreements: Vec<Disagreement> = vec![];
    let half = 0.5 * smooth_s;
    // A window's span, clipped to the record (a record shorter than a window
    // is one window).
    let (t_first, t_last) = (t[0], t[t.len() - 1]);
    let span = |t: f64| ((t - half).max(t_first), (t + half).min(t_last));
    for (i, v) in sm.iter().enumerate() {
        let dph = v * 3600.0;
        if dph.abs() > 3.0 * floor_s {
            let t = smooth.t[i];
            // Stretches a smoothing window or two apart are one.
            match disagreements.last_mut() {
                Some(d) if span(t).0 <= d.to_s + 2.0 * smooth_s => {
                    d.to_s = span(t).1;
                    if dph.abs() > d.peak_dph.abs() {
                        d.peak_dph = dph;
                    }
                }
                _ => disagreements.push(Disagreement {
                    from_s: span(t).0,
                    to_s: span(t).1,
                    peak_dph: dph,
                }),
            }
        }
    }
    disagreements
}

/// The mean square the noise alone leaves in the gap's window means (once
/// the constant every fit carries has taken its level), and that mean
/// square's variance over this record, both in (deg/s)^2 and (deg/s)^4:
/// the white noise of each kept window; each correlated process's
/// variance of a window mean less that of the record's mean (physics.md
/// 3's Markov terms, the flicker's sum of them); the random walk's wander
/// about its mean, K^2 T/6. The variance: 2 v^2 tau/n for a process of
/// window-mean variance v correlated over tau windows (1 for the white),
/// K^4 T^2/45 for the walk (the Karhunen-Loeve eigenvalues of a demeaned
/// Brownian motion, K^2 T^2/(pi j)^2), their standard deviations added (an
/// upper bound).
pub fn expected_gap(noise: &NoiseModel, win: &Windows, keep: &[bool]) -> (f64, f64) {
    let kept: Vec<usize> = (0..win.len()).filter(|&k| keep[k]).collect();
    let n = kept.len().max(1) as f64;
    if win.len() < 2 {
        return (noise.white, 2.0 * noise.white * noise.white / n);
    }
    let span = win.t[win.len() - 1] - win.t[0];
    let mut counts = win.count.clone();
    counts.sort_by(f64::total_cmp);
    let nominal = counts[counts.len() / 2].max(1e-9);
    let white = kept
        .iter()
        .map(|&k| noise.white * nominal / win.count[k].max(1e-9))
        .sum::<f64>()
        / n;
    let spacing = (span / (win.len() - 1) as f64).max(1e-9);
    let mut mean = white;
    let mut sd = (2.0 * white * white / n).sqrt();
    for (tc, v) in noise.processes(span) {
        let vw = v * (markov_mean_var(spacing / tc) - markov_mean_var(span / tc)).max(0.0);
        mean += vw;
        let corr = (tc / spacing).clamp(1.0, n);
        sd += (2.0 * vw * vw * corr / n).sqrt();
    }
    let k2 = noise.random_walk;
    mean += k2 * span / 6.0;
    sd += k2 * span / 45f64.sqrt();
    (mean, sd * sd)
}
