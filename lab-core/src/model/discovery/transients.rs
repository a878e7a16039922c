//! Transient events in a residual (after a first fit): spikes (a few
//! windows far outside the noise) and steps (the level jumping). Spikes
//! are left out of the fit; steps are offered to it as terms no name
//! explains. Either way they are reported as unexplained spans, and no
//! smooth effect is bent to follow them.

use super::windows::Windows;

/// Longest spike, windows: a longer excursion is a disturbance, for the
/// shapes and the block test.
pub const MAX_SPIKE_WINDOWS: usize = 5;
/// A spike stands this many robust sigmas from its neighbourhood.
pub const SPIKE_SIGMAS: f64 = 8.0;
/// Steps: the level before and after compared over this many windows ...
pub const STEP_WINDOWS: usize = 30;
/// ... and a step stands this many robust sigmas of that difference out.
pub const STEP_SIGMAS: f64 = 10.0;
/// Most steps offered.
pub const MAX_STEPS: usize = 4;

/// Spikes (window index ranges, inclusive) and step times, s.
#[derive(Clone, Debug, Default)]
pub struct Transients {
    pub spikes: Vec<(usize, usize)>,
    pub steps: Vec<f64>,
}

impl Transients {
    /// Windows to keep in the fit (spikes out).
    pub fn keep(&self, n: usize) -> Vec<bool> {
        let mut k = vec![true; n];
        for &(a, b) in &self.spikes {
            for v in k.iter_mut().take(b + 1).skip(a) {
                *v = false;
            }
        }
        k
    }
}

fn median(v: &mut [f64]) -> f64 {
    if v.is_empty() {
        return 0.0;
    }
    v.sort_by(f64::total_cmp);
    v[v.len() / 2]
}

/// Robust white scatter of a window mean, from its neighbours'
/// differences (noise_floor.rs's `white_var_of_diffs`).
pub fn white_sigma(e: &[f64]) -> f64 {
    let d2: Vec<f64> = e.windows(2).map(|p| (p[1] - p[0]).powi(2)).collect();
    super::white::white_var_of_diffs(&d2).unwrap_or(0.0).sqrt()
}

/// The times of the `most` largest jumps of `e`'s level (the mean over
/// [`STEP_WINDOWS`] after against before), each the largest within that
/// many windows, standing `sigmas` robust sigmas of that difference out
/// and six white sigmas of it (`sigma` a window's white scatter).
pub fn step_peaks(win: &Windows, e: &[f64], sigma: f64, sigmas: f64, most: usize) -> Vec<f64> {
    let n = e.len();
    let l = STEP_WINDOWS;
    if n < 4 * l {
        return vec![];
    }
    let mut cum = vec![0.0; n + 1];
    for i in 0..n {
        cum[i + 1] = cum[i] + e[i];
    }
    let diff: Vec<f64> = (0..n)
        .map(|k| {
            if k < l || k + l > n {
                0.0
            } else {
                (cum[k + l] - cum[k]) / l as f64 - (cum[k] - cum[k - l]) / l as f64
            }
        })
        .collect();
    let mut inner: Vec<f64> = diff[l..n - l].iter().map(|v| v.abs()).collect();
    let scale = median(&mut inner) * 1.4826;
    let white = sigma * (2.0 / l as f64).sqrt();
    let floor = (sigmas * scale).max(6.0 * white);
    let mut cands: Vec<(usize, f64)> = (l..n - l)
        .filter(|&k| {
            let a = diff[k].abs();
            a > floor && (k.saturating_sub(l)..(k + l).min(n)).all(|j| diff[j].abs() <= a)
        })
        .map(|k| (k, diff[k].abs()))
        .collect();
    cands.sort_by(|a, b| b.1.total_cmp(&a.1));
    cands
        .iter()
        .take(most)
        .map(|&(k, _)| 0.5 * (win.t[k - 1] + win.t[k]))
        .collect()
}

/// The `most` most likely places of a single step in `e` were its noise
/// white (the largest |S_k - k S_n/n| / sqrt(k (n - k)/n), S the
/// cumulative sum), [`STEP_WINDOWS`] from the ends and from each other: a
/// step too small to stand out over a few windows still stands out over
/// the record.
pub fn cusum_peaks(win: &Windows, e: &[f64], most: usize) -> Vec<f64> {
    let n = e.len();
    let l = STEP_WINDOWS;
    if n < 4 * l {
        return vec![];
    }
    let total: f64 = e.iter().sum();
    let mut s = 0.0;
    let mut stat = vec![0.0; n];
    for k in 1..n {
        s += e[k - 1];
        let (kf, nf) = (k as f64, n as f64);
        stat[k] = (s - kf * total / nf).abs() / (kf * (nf - kf) / nf).sqrt();
    }
    let mut out: Vec<usize> = vec![];
    for _ in 0..most {
        let best = (l..n - l)
            .filter(|&k| out.iter().all(|&o| o.abs_diff(k) >= 2 * l))
            .max_by(|&a, &b| stat[a].total_cmp(&stat[b]));
        match best {
            Some(k) => out.push(k),
            None => break,
        }
    }
    out.iter()
        .map(|&k| 0.5 * (win.t[k - 1] + win.t[k]))
        .collect()
}

/// The transients of `e`, a residual's window means after a fit.
pub fn find(win: &Windows, e: &[f64]) -> Transients {
    let n = e.len();
    if n < 4 * STEP_WINDOWS {
        return Transients::default();
    }
    let sigma = white_sigma(e);
    if sigma.is_nan() || sigma <= 0.0 {
        return Transients::default();
    }
    // Spikes: far from the local median (15 windows either side).
    let h = 15;
    let local: Vec<f64> = (0..n)
        .map(|k| {
            let mut v: Vec<f64> = e[k.saturating_sub(h)..(k + h + 1).min(n)].to_vec();
            median(&mut v)
        })
        .collect();
    let out: Vec<bool> = (0..n)
        .map(|k| (e[k] - local[k]).abs() > SPIKE_SIGMAS * sigma)
        .collect();
    let mut spikes = vec![];
    let mut k = 0;
    while k < n {
        if out[k] {
            let a = k;
            while k < n && out[k] {
                k += 1;
            }
            if k - a <= MAX_SPIKE_WINDOWS {
                spikes.push((a, k - 1));
            }
        } else {
            k += 1;
        }
    }
    // Steps, on the residual with the spikes replaced by the local median.
    let mut c = e.to_vec();
    for &(a, b) in &spikes {
        for (i, v) in c.iter_mut().enumerate().take(b + 1).skip(a) {
            *v = local[i];
        }
    }
    let steps = step_peaks(win, &c, sigma, STEP_SIGMAS, MAX_STEPS);
    Transients { spikes, steps }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_spike_and_a_step_in_white_noise() {
        let n = 2000;
        let t: Vec<f64> = (0..n).map(|k| k as f64 + 0.5).collect();
        let win = Windows::new(&t, 1.0);
        // Deterministic "noise": a sum of incommensurate sines, sd ~ 1.
        let mut e: Vec<f64> = (0..n)
            .map(|k| {
                let x = k as f64;
                (x * 1.7).sin() + (x * 2.9 + 1.0).sin() * 0.8
            })
            .collect();
        e[500] += 40.0;
        for v in e.iter_mut().skip(1200) {
            *v += 3.0;
        }
        let tr = find(&win, &e);
        assert_eq!(tr.spikes, vec![(500, 500)]);
        assert_eq!(tr.steps.len(), 1);
        assert!((tr.steps[0] - 1200.0).abs() <= 2.0, "{:?}", tr.steps);
        // Nothing in the noise alone.
        let clean: Vec<f64> = (0..n).map(|k| ((k as f64) * 1.7).sin()).collect();
        let tr = find(&win, &clean);
        assert!(tr.spikes.is_empty() && tr.steps.is_empty(), "{tr:?}");
    }
}
