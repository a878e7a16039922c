//! The scale-factor figure of a run: the RMS of the scale-factor error over
//! whole windows at one rate (the fits' residual, the compensation's result
//! and the bench's validation all use it), and the floor the run's white
//! rate noise sets under it.

use super::input::MIN_RATE_DPS;
use super::result::Est;

/// Window of the scale-factor residual figure, s.
pub const RESIDUAL_WINDOW_S: f64 = 60.0;
/// Window of the noise floor's short means, s.
pub const FLOOR_WINDOW_S: f64 = 10.0;

/// One whole window of consecutive rows at one rate.
#[derive(Clone, Copy, Debug)]
pub struct WindowMean {
    /// Middle of the window, s.
    pub t_s: f64,
    /// Mean scale-factor error over the window, ppm (err over the rate).
    pub ppm: f64,
    /// Mean of the extra column given (e.g. the coil temperature).
    pub extra: f64,
    /// Index of the window's first row, and its row count.
    pub first: usize,
    pub rows: usize,
}

/// Means of `err` (deg/s) over whole `window_s` windows of consecutive
/// rows at one nonzero rate, over the rate, ppm; with the mean of `extra`
/// over each.
pub fn window_means(
    t: &[f64],
    w: &[f64],
    err: &[f64],
    extra: &[f64],
    window_s: f64,
) -> Vec<WindowMean> {
    let mut means = Vec::new();
    let mut k = 0;
    while k < t.len() {
        if w[k].abs() < MIN_RATE_DPS {
            k += 1;
            continue;
        }
        let start = k;
        let t0 = if k > 0 {
            t[k - 1]
        } else {
            t[k] - (t.get(1).unwrap_or(&1.0) - t[0])
        };
        let (mut sum, mut ex) = (0.0, 0.0);
        while k < t.len() && w[k] == w[start] && t[k] - t0 <= window_s + 1e-9 {
            sum += err[k];
            ex += extra.get(k).copied().unwrap_or(f64::NAN);
            k += 1;
        }
        // Whole windows only (a rate change cuts the window short).
        if t[k - 1] - t0 >= window_s - 1e-9 {
            let n = (k - start) as f64;
            means.push(WindowMean {
                t_s: 0.5 * (t0 + t[k - 1]),
                ppm: sum / n / w[start] * 1e6,
                extra: ex / n,
                first: start,
                rows: k - start,
            });
        }
    }
    means
}

/// RMS of the scale-factor error over `window_s` means of consecutive
/// rows at one rate: err (deg/s) over the rate, ppm. Returns the RMS, its
/// standard error (sqrt(1/(2m)) relative, m windows) and m.
pub fn window_rms_ppm(t: &[f64], w: &[f64], err: &[f64], window_s: f64) -> (f64, f64, usize) {
    let means = window_means(t, w, err, &[], window_s);
    let m = means.len();
    if m == 0 {
        return (f64::NAN, f64::NAN, 0);
    }
    let rms = (means.iter().map(|x| x.ppm * x.ppm).sum::<f64>() / m as f64).sqrt();
    (rms, rms / (2.0 * m as f64).sqrt(), m)
}

/// The noise floor of the 60 s figure, ppm: what white rate noise alone
/// leaves in an RMS of 60 s means. From the Allan variance of consecutive
/// 10 s means within one rate stretch (drifts slower than that cancel in
/// the differences), scaled as white noise (tau^-1/2) to 60 s; with its
/// standard error (sqrt(1/(2m)) relative, m differences).
pub fn noise_floor_ppm(t: &[f64], w: &[f64], err: &[f64]) -> Est {
    let m = window_means(t, w, err, &[], FLOOR_WINDOW_S);
    let (mut sum, mut count) = (0.0, 0usize);
    for p in m.windows(2) {
        let adjacent = p[1].first == p[0].first + p[0].rows && w[p[1].first] == w[p[0].first];
        if adjacent {
            sum += (p[1].ppm - p[0].ppm).powi(2);
            count += 1;
        }
    }
    if count == 0 {
        return Est {
            value: f64::NAN,
            se: f64::NAN,
        };
    }
    let sd10 = (sum / (2.0 * count as f64)).sqrt();
    let v = sd10 * (FLOOR_WINDOW_S / RESIDUAL_WINDOW_S).sqrt();
    Est {
        value: v,
        se: v / (2.0 * count as f64).sqrt(),
    }
}
