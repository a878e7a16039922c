//! Records with gaps (frames lost on the way from the board, closures the
//! board missed).
//!
//! The Allan variance needs uniform samples. A row of a run file holds the
//! mean rate over the interval that ends at its time (`gyro-lab record`
//! takes the rate after a gap over the whole gap). Integrating the rows into
//! an angle and differencing that angle on a uniform grid keeps the angle
//! exactly, so every cluster average that spans a gap is right; only the
//! noise inside the gaps is lost, which lowers the deviation at averaging
//! times shorter than a gap by at most the filled share. A uniform record
//! passes unchanged; the filled share is reported so a user can judge it.

use super::analysis::{SamplingError, SAMPLING_TOLERANCE};
use std::borrow::Cow;

/// A uniform series made from one with gaps.
#[derive(Clone, Debug, PartialEq)]
pub struct Filled {
    /// The rate at every sample period, gaps filled.
    pub values: Vec<f64>,
    /// The sample period (s): the median interval.
    pub tau0: f64,
    /// Intervals where at least one sample is missing (half a period or
    /// more beyond the sample period): frames lost on the way.
    pub gaps: usize,
    /// Intervals longer than the sample period by less than half of one: a
    /// frame that spans closures the board missed (flagged in its frames),
    /// no sample lost.
    pub stretched: usize,
    /// Samples the uniform grid has beyond the record's rows.
    pub filled: usize,
}

impl Filled {
    /// The share of the series that was filled, not measured.
    pub fn filled_fraction(&self) -> f64 {
        self.filled as f64 / self.values.len().max(1) as f64
    }
}

/// The longest gap filled, in sample periods: a longer one is not a few
/// lost frames but a different record, and is refused.
pub const MAX_GAP_SAMPLES: f64 = 10_000.0;

/// Make `values` at times `t` uniform. Intervals within
/// [`SAMPLING_TOLERANCE`] of the median pass; a record of only those is
/// returned as it is. Longer intervals (up to [`MAX_GAP_SAMPLES`]) are gaps,
/// shorter ones rows taken early: either way the record is resampled
/// through its angle. A longer gap is an error at its row.
pub fn fill_gaps(t: &[f64], values: &[f64]) -> Result<Filled, SamplingError> {
    fill_gaps_cow(t, Cow::Borrowed(values), None)
}

/// [`fill_gaps`] of values the caller gives up (a uniform record keeps
/// them, no copy), `median` the median interval of `t` where the caller
/// has it.
pub fn fill_gaps_owned(
    t: &[f64],
    values: Vec<f64>,
    median: Option<f64>,
) -> Result<Filled, SamplingError> {
    fill_gaps_cow(t, Cow::Owned(values), median)
}

fn fill_gaps_cow(
    t: &[f64],
    values: Cow<[f64]>,
    median: Option<f64>,
) -> Result<Filled, SamplingError> {
    let n = t.len().min(values.len());
    let uniform = |tau0, values: Cow<[f64]>| {
        let mut values = values.into_owned();
        values.truncate(n);
        Filled {
            values,
            tau0,
            gaps: 0,
            stretched: 0,
            filled: 0,
        }
    };
    if n < 2 {
        return Ok(uniform(1.0, values));
    }
    let interval = |k: usize| t[k + 1] - t[k];
    let med = median.unwrap_or_else(|| {
        crate::numerics::stats::median_mut(&mut (0..n - 1).map(interval).collect::<Vec<f64>>())
    });
    if med.is_nan() || med <= 0.0 {
        return Err(SamplingError::NotIncreasing);
    }
    let tol = SAMPLING_TOLERANCE * med;
    let (mut gaps, mut stretched) = (0, 0);
    for (k, h) in (0..n - 1).map(interval).enumerate() {
        if (h - med).abs() <= tol {
            continue;
        }
        if h > MAX_GAP_SAMPLES * med {
            return Err(SamplingError::Uneven {
                row: k + 1,
                interval: h,
                median: med,
            });
        }
        if h < med {
            // A row taken early (irregular sampling, record/sampling.rs
            // keeps such times): resampled through the angle like the rest.
            stretched += 1;
        } else if h >= 1.5 * med {
            gaps += 1;
        } else {
            stretched += 1;
        }
    }
    if gaps + stretched == 0 {
        return Ok(uniform(med, values));
    }
    // The angle at each row's time (rate held over the interval before it),
    // read on the grid t0 + k med by linear interpolation.
    let mut angle = Vec::with_capacity(n);
    angle.push(0.0);
    for k in 1..n {
        angle.push(angle[k - 1] + values[k] * interval(k - 1));
    }
    let span = t[n - 1] - t[0];
    let m = ((span + tol) / med).floor() as usize;
    let mut out = Vec::with_capacity(m + 1);
    out.push(values[0]);
    let (mut row, mut prev) = (1, 0.0);
    for k in 1..=m {
        let tk = (t[0] + k as f64 * med).min(t[n - 1]);
        while row < n - 1 && t[row] < tk {
            row += 1;
        }
        let a = angle[row] - values[row] * (t[row] - tk);
        out.push((a - prev) / med);
        prev = a;
    }
    let filled = out.len().saturating_sub(n);
    Ok(Filled {
        values: out,
        tau0: med,
        gaps,
        stretched,
        filled,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn uniform_series_pass_unchanged() {
        let t: Vec<f64> = (0..100).map(|i| i as f64 * 0.002).collect();
        let y: Vec<f64> = (0..100).map(|i| (i as f64).sin()).collect();
        let f = fill_gaps(&t, &y).unwrap();
        assert_eq!(f.values, y);
        assert_eq!((f.gaps, f.filled), (0, 0));
        assert!((f.tau0 - 0.002).abs() < 1e-15);
    }

    #[test]
    fn a_gap_keeps_the_angle() {
        // Rates at 1 s; samples 10..12 lost, the row at 13 holds their mean.
        let rate: Vec<f64> = (0..30).map(|i| 0.1 * i as f64).collect();
        let mut t = vec![];
        let mut y = vec![];
        for i in 0..30 {
            if (10..13).contains(&i) {
                continue;
            }
            t.push(i as f64);
            y.push(if i == 13 {
                rate[10..14].iter().sum::<f64>() / 4.0
            } else {
                rate[i]
            });
        }
        let f = fill_gaps(&t, &y).unwrap();
        assert_eq!(f.values.len(), 30);
        assert_eq!((f.gaps, f.stretched, f.filled), (1, 0, 3));
        let angle: f64 = f.values.iter().sum();
        let truth: f64 = rate.iter().sum();
        assert!((angle - truth).abs() < 1e-12, "{angle} vs {truth}");
    }

    #[test]
    fn irregular_rows_keep_the_angle_and_a_day_long_gap_is_an_error() {
        // Rows at uneven times, each the mean rate since the row before.
        let t = [0.0, 1.0, 2.0, 2.5, 3.5, 4.5, 6.0];
        let y = [0.0, 1.0, 2.0, 3.0, 4.0, 5.0, 6.0];
        let f = fill_gaps(&t, &y).unwrap();
        let angle: f64 = f.values[1..].iter().sum::<f64>() * f.tau0;
        let truth: f64 = (1..7).map(|i| y[i] * (t[i] - t[i - 1])).sum();
        assert!((angle - truth).abs() < 1e-12, "{angle} vs {truth}");
        let t = [0.0, 1.0, 2.0, 20_000.0];
        assert_eq!(fill_gaps(&t, &[0.0; 4]).unwrap_err().row(), 3);
    }

    #[test]
    fn a_long_sample_keeps_the_angle_on_the_grid() {
        // One interval of 1.08 periods (two closures missed in a frame of
        // 25): the grid from then on is 0.08 period early; the angle at
        // every grid time is the record's, linearly within an interval.
        let t: Vec<f64> = (0..20)
            .map(|i| i as f64 + if i >= 7 { 0.08 } else { 0.0 })
            .collect();
        let y: Vec<f64> = (0..20).map(|i| 1.0 + 0.5 * (i % 3) as f64).collect();
        let f = fill_gaps(&t, &y).unwrap();
        assert_eq!((f.gaps, f.stretched, f.filled), (0, 1, 0));
        assert_eq!(f.values.len(), 20);
        let angle: f64 = f.values[1..].iter().sum();
        let truth: f64 = (1..20).map(|i| y[i] * (t[i] - t[i - 1])).sum::<f64>() - y[19] * 0.08;
        assert!((angle - truth).abs() < 1e-12, "{angle} vs {truth}");
    }
}
