//! The scale-factor figure of a run: the RMS of the scale-factor error over
//! whole windows at one rate (the fits' residual, the compensation's result
//! and the bench's validation all use it).

use super::input::MIN_RATE_DPS;

/// Window of the scale-factor residual figure, s.
pub const RESIDUAL_WINDOW_S: f64 = 60.0;

/// RMS of the scale-factor error over `window_s` means of consecutive
/// rows at one rate: err (deg/s) over the rate, ppm. Returns the RMS, its
/// standard error (sqrt(1/(2m)) relative, m windows) and m.
pub fn window_rms_ppm(t: &[f64], w: &[f64], err: &[f64], window_s: f64) -> (f64, f64, usize) {
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
        let mut sum = 0.0;
        while k < t.len() && w[k] == w[start] && t[k] - t0 <= window_s + 1e-9 {
            sum += err[k];
            k += 1;
        }
        // Whole windows only (a rate change cuts the window short).
        if t[k - 1] - t0 >= window_s - 1e-9 {
            means.push(sum / (k - start) as f64 / w[start] * 1e6);
        }
    }
    let m = means.len();
    if m == 0 {
        return (f64::NAN, f64::NAN, 0);
    }
    let rms = (means.iter().map(|x| x * x).sum::<f64>() / m as f64).sqrt();
    (rms, rms / (2.0 * m as f64).sqrt(), m)
}
