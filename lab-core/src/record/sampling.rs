//! How a record was sampled, and one policy for every command.
//!
//! A board samples on its crystal; a PC that stamps each row on arrival
//! scatters the stamps about that grid by its scheduling (+-10 ms on a
//! 1 s log is common). The rows are then uniform and their stamps are
//! not: differencing them would turn the stamping noise into rate noise,
//! and 1 s windows would catch two rows or none. So the times are judged:
//!
//! - **uniform**: every interval within 1e-4 of the median: kept;
//! - **jittered**: each stamp within a quarter period of a grid whose
//!   offset may wander slowly (the PC's clock against the board's): the
//!   rows are put on that grid (their slot counted from the intervals, so
//!   a lost row stays a gap), and the stamps' scatter is reported;
//! - **irregular**: anything else (rows really taken at uneven times): the
//!   true times are kept, and what needs uniform rows resamples through
//!   the angle (noise/gaps.rs).

use super::Warning;
use crate::numerics::stats::{median, median_mut};

/// The relative spread of intervals below which a record is uniform.
pub const UNIFORM_TOLERANCE: f64 = 1e-4;
/// Stamps further than this share of a period from their slot are not
/// jitter.
pub const MAX_JITTER: f64 = 0.25;
/// Rows per block of the wandering offset's estimate.
const BLOCK: usize = 256;

/// What was found, for the JSON (`sampling`) and the reports.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Sampling {
    /// `uniform`, `jittered` or `irregular`.
    pub kind: &'static str,
    /// The median interval, s.
    pub period_s: f64,
    /// The stamps' scatter about their slots (RMS and largest), s.
    pub jitter_rms_s: f64,
    pub jitter_max_s: f64,
    /// Intervals of more than one period (rows lost).
    pub gaps: usize,
    /// Whether the times analysed are the grid's, not the stamps.
    pub regularised: bool,
}

impl Sampling {
    /// The warning a user reads, where there is one.
    pub fn warning(&self) -> Option<Warning> {
        match self.kind {
            "jittered" => Some(Warning::new(
                "jitter",
                format!(
                    "the time stamps scatter about a regular {} s grid by {} s RMS ({} s at most): stamping jitter, not the sampling; the rows are analysed on the grid",
                    crate::report::text::sig(self.period_s),
                    crate::report::text::sig(self.jitter_rms_s),
                    crate::report::text::sig(self.jitter_max_s)
                ),
            )),
            "irregular" => Some(Warning::new(
                "irregular",
                format!(
                    "the rows are not evenly spaced (median interval {} s, stamps up to {} s off any regular grid): analysed on their own times, resampled through the angle where a method needs even rows",
                    crate::report::text::sig(self.period_s),
                    crate::report::text::sig(self.jitter_max_s)
                ),
            )),
            _ => None,
        }
    }
}

/// Judges the times `t` (increasing) and, for a jittered record, puts
/// them on their grid in place.
pub fn regularise(t: &mut [f64]) -> Sampling {
    let n = t.len();
    let mut d: Vec<f64> = t.windows(2).map(|w| w[1] - w[0]).collect();
    let uniform = |period_s| Sampling {
        kind: "uniform",
        period_s,
        jitter_rms_s: 0.0,
        jitter_max_s: 0.0,
        gaps: 0,
        regularised: false,
    };
    if n < 3 {
        return uniform(d.first().copied().unwrap_or(1.0));
    }
    let med = median_mut(&mut d);
    if t.windows(2)
        .all(|w| (w[1] - w[0] - med).abs() <= UNIFORM_TOLERANCE * med)
    {
        return uniform(med);
    }
    // Each row's slot on the grid, counted from the intervals.
    let mut slot = vec![0i64; n];
    for k in 1..n {
        slot[k] = slot[k - 1] + (((t[k] - t[k - 1]) / med).round() as i64).max(1);
    }
    let gaps = (1..n).filter(|&k| slot[k] - slot[k - 1] > 1).count();
    // The period by least squares of the stamps on their slots (the
    // median interval is off by its own scatter, which the slots
    // multiply).
    let (ms, mt) = (
        slot.iter().sum::<i64>() as f64 / n as f64,
        t.iter().sum::<f64>() / n as f64,
    );
    let (mut sxy, mut sxx) = (0.0, 0.0);
    for k in 0..n {
        let x = slot[k] as f64 - ms;
        sxy += x * (t[k] - mt);
        sxx += x * x;
    }
    let period = if sxx > 0.0 { sxy / sxx } else { med };
    // The offset of each stamp from its slot, and its slow wander: the
    // median of each block, linear between the blocks' middles (and
    // beyond the first and last, along the nearest two).
    let off: Vec<f64> = (0..n).map(|k| t[k] - period * slot[k] as f64).collect();
    let centres: Vec<(f64, f64)> = off
        .chunks(BLOCK)
        .enumerate()
        .map(|(b, c)| {
            let mid = (b * BLOCK) as f64 + 0.5 * (c.len() - 1) as f64;
            (mid, median(c))
        })
        .collect();
    let smooth = |k: usize| -> f64 {
        let x = k as f64;
        let j = centres.partition_point(|c| c.0 <= x);
        let line = |a: &(f64, f64), b: &(f64, f64)| a.1 + (b.1 - a.1) * (x - a.0) / (b.0 - a.0);
        match centres.len() {
            0 => 0.0,
            1 => centres[0].1,
            m => {
                let i = j.clamp(1, m - 1);
                line(&centres[i - 1], &centres[i])
            }
        }
    };
    let grid: Vec<f64> = (0..n)
        .map(|k| period * slot[k] as f64 + smooth(k))
        .collect();
    d = (0..n).map(|k| t[k] - grid[k]).collect();
    let rms = (d.iter().map(|e| e * e).sum::<f64>() / n as f64).sqrt();
    let max = d.iter().fold(0.0f64, |a, e| a.max(e.abs()));
    let increasing = grid.windows(2).all(|w| w[1] > w[0]);
    if max > MAX_JITTER * med || !increasing {
        return Sampling {
            kind: "irregular",
            period_s: med,
            jitter_rms_s: rms,
            jitter_max_s: max,
            gaps,
            regularised: false,
        };
    }
    t.copy_from_slice(&grid);
    Sampling {
        kind: "jittered",
        period_s: period,
        jitter_rms_s: rms,
        jitter_max_s: max,
        gaps,
        regularised: true,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn jittered_stamps_go_back_on_their_grid_and_a_lost_row_stays_lost() {
        let n = 5000;
        let mut s = 7u64;
        let mut u = || {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (s >> 11) as f64 / (1u64 << 53) as f64 - 0.5
        };
        // 1 s rows, +-10 ms of stamping jitter, a clock 50 ppm fast, and
        // row 2500 lost.
        let truth: Vec<f64> = (0..n)
            .filter(|&k| k != 2500)
            .map(|k| 100.0 + k as f64 * 1.00005)
            .collect();
        let mut t: Vec<f64> = truth.iter().map(|x| x + 0.02 * u()).collect();
        let s = regularise(&mut t);
        assert_eq!((s.kind, s.gaps, s.regularised), ("jittered", 1, true));
        let worst = t
            .iter()
            .zip(&truth)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        // Within 0.3 % of the period of the truth (the block medians'
        // own scatter), where the stamps were 1 % off.
        assert!(worst < 3e-3, "back on the grid to {worst} s");
        assert!(s.jitter_max_s < 0.013 && s.jitter_rms_s > 0.004, "{s:?}");
        assert!((s.period_s - 1.00005).abs() < 1e-6, "{s:?}");
    }

    #[test]
    fn uniform_and_irregular_times_are_kept() {
        let mut t: Vec<f64> = (0..100).map(|k| k as f64 * 0.1).collect();
        let before = t.clone();
        assert_eq!(regularise(&mut t).kind, "uniform");
        assert_eq!(t, before);
        let mut t: Vec<f64> = (0..100).map(|k| (k * k) as f64 * 0.01 + k as f64).collect();
        let before = t.clone();
        assert_eq!(regularise(&mut t).kind, "irregular");
        assert_eq!(t, before);
    }
}
