//! Does the record hold still? A noise analysis assumes it does: a gyro
//! that warms up, or a chamber that drifts, puts a drift into the output
//! that the long averaging times read as a rate random walk or a ramp. Two
//! things are looked at: each temperature column (its span over the
//! record, and whether it settles: a warm-up), and the mean rate (its
//! first tenth against the rest, in units of what its white noise
//! allows).

use super::{mean_sd, white_sd, Warning};

/// A temperature that moves by more than this over the record, degC (of
/// its block means), is not a record at one temperature.
pub const TEMP_SPAN_C: f64 = 1.0;
/// The settled band about the final temperature: this share of the span,
/// at least [`SETTLED_MIN_C`] (a gyro's bias follows its temperature: a
/// twentieth of a warm-up left in is a twentieth of its drift).
pub const SETTLED_SHARE: f64 = 0.05;
pub const SETTLED_MIN_C: f64 = 0.2;
/// A mean rate whose first tenth differs from the rest by more than this
/// many standard errors of white noise drifts.
pub const RATE_SIGMAS: f64 = 8.0;
/// Blocks the record is judged in.
const BLOCKS: usize = 50;

/// What a temperature column did over the record.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct TempDrift {
    pub column: String,
    pub first_c: f64,
    pub last_c: f64,
    pub span_c: f64,
    /// From when on it stays within the settled band of its final value
    /// (None where it does not settle before the record's second half).
    pub settled_from_s: Option<f64>,
}

/// Block means of `x` over times `t`: (mid time, mean).
fn blocks(t: &[f64], x: &[f64], n: usize) -> Vec<(f64, f64)> {
    let size = x.len().div_ceil(n).max(1);
    t.chunks(size)
        .zip(x.chunks(size))
        .map(|(tc, xc)| {
            (
                0.5 * (tc[0] + tc[tc.len() - 1]),
                xc.iter().sum::<f64>() / xc.len() as f64,
            )
        })
        .collect()
}

/// How `temp` moved over the record, where it moved by more than
/// [`TEMP_SPAN_C`].
pub fn temperature(t: &[f64], name: &str, temp: &[f64]) -> Option<TempDrift> {
    if t.len() < 2 * BLOCKS {
        return None;
    }
    let b = blocks(t, temp, BLOCKS);
    let (lo, hi) = b.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |a, v| {
        (a.0.min(v.1), a.1.max(v.1))
    });
    let span = hi - lo;
    if span <= TEMP_SPAN_C {
        return None;
    }
    let last = b[b.len() - 1].1;
    let band = (SETTLED_SHARE * span).max(SETTLED_MIN_C);
    let out = b.iter().rposition(|v| (v.1 - last).abs() > band);
    let settled_from_s = out
        .map(|i| b.get(i + 1).map_or(f64::INFINITY, |v| v.0))
        .filter(|&s| s - t[0] < 0.5 * (t[t.len() - 1] - t[0]));
    Some(TempDrift {
        column: name.to_owned(),
        first_c: b[0].1,
        last_c: last,
        span_c: span,
        settled_from_s,
    })
}

/// When every drifting temperature has settled (a warm-up), None where
/// one does not settle in the record's first half.
pub fn settled_from(drifts: &[TempDrift]) -> Option<f64> {
    drifts
        .iter()
        .map(|d| d.settled_from_s)
        .try_fold(f64::NEG_INFINITY, |a, s| s.map(|s| a.max(s)))
        .filter(|s| s.is_finite())
}

/// One warning for the temperatures that move (None where none does).
pub fn warning(drifts: &[TempDrift]) -> Option<Warning> {
    if drifts.is_empty() {
        return None;
    }
    let moves: Vec<String> = drifts
        .iter()
        .map(|d| format!("`{}` {:.2} -> {:.2} degC", d.column, d.first_c, d.last_c))
        .collect();
    let how = match settled_from(drifts) {
        Some(s) => format!(
            "settling within {}% of the span ({SETTLED_MIN_C} degC at least) of the final values from {} s on: a warm-up",
            SETTLED_SHARE * 100.0,
            crate::report::text::sig(s)
        ),
        None => "not settling in the record's first half".into(),
    };
    Some(Warning::new(
        "non_stationary",
        format!(
            "the temperature moves over the record ({}), {how}; what it drives reads as noise at the long averaging times",
            moves.join(", ")
        ),
    ))
}

/// The mean rate's drift: its first tenth against the rest, where that
/// stands more than [`RATE_SIGMAS`] standard errors of the white noise
/// apart (deg/s in, the message in deg/h).
pub fn mean_rate(t: &[f64], x: &[f64]) -> Option<Warning> {
    mean_rate_with(t, x, None)
}

/// [`mean_rate`] with the white noise of `x` (`white_sd`, deg/s) where
/// the caller has it already.
pub fn mean_rate_with(t: &[f64], x: &[f64], white: Option<f64>) -> Option<Warning> {
    let n = x.len();
    if n < 200 {
        return None;
    }
    let k = n / 10;
    let (first, _) = mean_sd(&x[..k]);
    let (rest, _) = mean_sd(&x[k..]);
    let sd = white.unwrap_or_else(|| white_sd(x));
    let se = sd * (1.0 / k as f64 + 1.0 / (n - k) as f64).sqrt();
    let z = (first - rest).abs() / se.max(f64::MIN_POSITIVE);
    (z > RATE_SIGMAS).then(|| {
        Warning::new(
            "non_stationary",
            format!(
                "the mean rate over the first tenth of the record (to {} s) differs from the rest's by {} deg/h, {:.0} times the standard error its white noise allows: a warm-up, a thermal drift, or a slow random walk; the long averaging times read it as noise",
                crate::report::text::sig(t[k] - t[0]),
                crate::report::text::sig((first - rest) * 3600.0),
                z
            ),
        )
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_warm_up_settles_and_a_steady_record_says_nothing() {
        let t: Vec<f64> = (0..20_000).map(|k| k as f64).collect();
        let warm: Vec<f64> = t.iter().map(|s| 27.0 - 7.0 * (-s / 800.0).exp()).collect();
        let d = temperature(&t, "heat", &warm).unwrap();
        // The block means smooth the first, fastest part of the rise.
        assert!(d.span_c > 5.0 && d.span_c < 7.0, "{d:?}");
        let s = d.settled_from_s.unwrap();
        assert!((1200.0..3000.0).contains(&s), "settled from {s}");
        assert!(warning(std::slice::from_ref(&d))
            .unwrap()
            .message
            .contains("warm-up"));
        let steady: Vec<f64> = t.iter().map(|s| 20.0 + 0.2 * (s / 3000.0).sin()).collect();
        assert!(temperature(&t, "heat", &steady).is_none());
        let ramp: Vec<f64> = t.iter().map(|s| -40.0 + s / 200.0).collect();
        assert_eq!(temperature(&t, "heat", &ramp).unwrap().settled_from_s, None);
    }

    #[test]
    fn a_bias_settling_at_the_start_is_a_drift() {
        let t: Vec<f64> = (0..10_000).map(|k| k as f64).collect();
        let x: Vec<f64> = t
            .iter()
            .enumerate()
            .map(|(k, s)| {
                1e-5 * (-s / 300.0).exp() + 1e-6 * ((k * 7919 % 1000) as f64 / 500.0 - 1.0)
            })
            .collect();
        assert!(mean_rate(&t, &x).is_some());
        let flat: Vec<f64> = x
            .iter()
            .zip(&t)
            .map(|(v, s)| v - 1e-5 * (-s / 300.0).exp())
            .collect();
        assert!(mean_rate(&t, &flat).is_none());
    }
}
