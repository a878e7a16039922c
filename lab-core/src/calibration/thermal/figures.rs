//! The drift figures of a chamber run (docs/rlg.md): the scatter of 100 s
//! means, its standard error, and the run's own noise floor there.

/// Standard error of a standard deviation of `m` values (normal noise):
/// sd / sqrt(2 (m - 1)).
pub fn std_se(sd: f64, t: &[f64], window_s: f64) -> f64 {
    let m = window_means(t, &vec![0.0; t.len()], window_s).len() as f64;
    sd / (2.0 * (m - 1.0)).max(1.0).sqrt()
}

/// Standard deviation of consecutive `window_s` means (by time), deg/h.
pub fn std_of_means(t: &[f64], x: &[f64], window_s: f64) -> f64 {
    let means = window_means(t, x, window_s);
    let n = means.len() as f64;
    if means.len() < 2 {
        return f64::NAN;
    }
    let m = means.iter().sum::<f64>() / n;
    (means.iter().map(|v| (v - m).powi(2)).sum::<f64>() / (n - 1.0)).sqrt()
}

pub fn window_means(t: &[f64], x: &[f64], window_s: f64) -> Vec<f64> {
    let mut out = Vec::new();
    let (mut sum, mut cnt) = (0.0, 0usize);
    let mut end = t.first().copied().unwrap_or(0.0) + window_s;
    for (&tk, &xk) in t.iter().zip(x) {
        while tk >= end {
            if cnt > 0 {
                out.push(sum / cnt as f64);
            }
            sum = 0.0;
            cnt = 0;
            end += window_s;
        }
        sum += xk;
        cnt += 1;
    }
    out
}

/// Noise floor of a run at 100 s, deg/h: the Allan deviation at 10 s scaled
/// as white noise (tau^-1/2) to 100 s. At 10 s the thermal drift is far below
/// the noise, so this is the noise the run holds, estimated from the data.
pub fn noise_floor_100s(t: &[f64], x: &[f64]) -> f64 {
    let m = window_means(t, x, 10.0);
    if m.len() < 3 {
        return f64::NAN;
    }
    let avar =
        m.windows(2).map(|w| (w[1] - w[0]).powi(2)).sum::<f64>() / (2.0 * (m.len() - 1) as f64);
    avar.sqrt() * (10.0f64 / 100.0).sqrt()
}
