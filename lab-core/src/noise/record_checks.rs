//! What a record must be for its Allan analysis to mean what it says: a
//! noise record (the gyro at rest, or at a constant reference rate), and
//! long enough to show the terms the fit reports. Each check gives a
//! warning with a code the JSON and the report carry.

use super::analysis::Allan;
use super::terms::{shape_name, COUNT, MARKOV, SIN};

/// A reference that moves by more than this, deg/s, turns: the record is a
/// rate-table run, not a noise record (0.01 deg/s is 36 deg/h, far above
/// any table's jitter at rest and below any rate a table is set to).
pub const STATIC_TOLERANCE_DPS: f64 = 0.01;

/// Fewest degrees of freedom at the averaging times a term must dominate
/// somewhere for the record to show it: below that the term rests on a
/// handful of the record's longest averages.
pub const MIN_EDF: f64 = 4.0;

pub use crate::record::Warning as RecordWarning;

/// `not_static` when the reference rate varies over the record.
pub fn not_static(reference_dps: &[f64]) -> Option<RecordWarning> {
    let (lo, hi) = reference_dps
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), &x| {
            (a.min(x), b.max(x))
        });
    (hi - lo > STATIC_TOLERANCE_DPS).then(|| RecordWarning {
        code: "not_static",
        message: format!(
            "the reference rate varies from {lo:.4} to {hi:.4} deg/s: this is a rate-table run, \
             not a noise record. The output less the reference is analysed, but what the table's \
             motion leaves in it (scale-factor error, dynamics) reads as noise; record the gyro \
             at rest for its noise terms"
        ),
    })
}

/// `too_short` when a term the fit reports dominates only averaging times
/// with fewer than [`MIN_EDF`] degrees of freedom (the record's last few
/// averages).
pub fn too_short(an: &Allan) -> Option<RecordWarning> {
    let t = &an.terms;
    let reported: Vec<usize> = (0..COUNT)
        .filter(|&j| t.present[j])
        .chain(t.sinusoid.as_ref().map(|_| SIN))
        .chain(t.correlated.as_ref().map(|_| MARKOV))
        .collect();
    let unsupported = unsupported_terms(&reported, &t.dominant, &t.edf);
    if unsupported.is_empty() {
        return None;
    }
    let duration = an.n as f64 * an.tau0;
    let (them, mean) = if unsupported.len() == 1 {
        ("it", "its value and interval mean")
    } else {
        ("them", "their values and intervals mean")
    };
    let names: Vec<&str> = unsupported.iter().map(|&s| shape_name(s)).collect();
    Some(RecordWarning {
        code: "too_short",
        message: format!(
            "the record ({} s, {} samples) is too short to show {}: the fit reads {them} only at \
             its longest averaging times, from fewer than {MIN_EDF:.0} degrees of freedom, and {mean} \
             little. A record ten times longer would show {them}",
            crate::report::text::sig(duration),
            an.n,
            names.join(", ")
        ),
    })
}

/// Of the `reported` shapes, those that dominate some averaging time but
/// only ones with fewer than [`MIN_EDF`] degrees of freedom (`dominant`
/// and `edf` per averaging time).
pub fn unsupported_terms(reported: &[usize], dominant: &[usize], edf: &[f64]) -> Vec<usize> {
    reported
        .iter()
        .copied()
        .filter(|&s| {
            let mut dominated = dominant.iter().zip(edf).filter(|(&d, _)| d == s).peekable();
            dominated.peek().is_some() && dominated.all(|(_, &e)| e < MIN_EDF)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A ramp (shape 4) that carries only the last three averages (EDF 3.8,
    /// 2.5, 1.6) is unsupported; one that carries averages with 9.5 and 6.7
    /// degrees of freedom as well is shown; white noise (1) over the rest is.
    #[test]
    fn a_term_read_only_at_the_last_averages_is_unsupported() {
        let edf = [200.0, 80.0, 30.0, 9.5, 6.7, 3.8, 2.5, 1.6];
        let tail = [1, 1, 1, 1, 1, 4, 4, 4];
        assert_eq!(unsupported_terms(&[1, 4], &tail, &edf), vec![4]);
        let wide = [1, 1, 1, 4, 4, 4, 4, 4];
        assert!(unsupported_terms(&[1, 4], &wide, &edf).is_empty());
        // A reported term that dominates nowhere is not judged here.
        assert!(unsupported_terms(&[1, 3], &tail, &edf).is_empty());
    }

    #[test]
    fn a_turning_reference_is_not_static() {
        assert!(not_static(&[0.004178; 100]).is_none());
        let table: Vec<f64> = (0..100).map(|k| if k < 50 { 0.0 } else { 10.0 }).collect();
        assert_eq!(not_static(&table).unwrap().code, "not_static");
    }
}
