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

/// A warning on the record: `code` for scripts, `message` for people.
#[derive(Clone, Debug, serde::Serialize)]
pub struct RecordWarning {
    pub code: &'static str,
    pub message: String,
}

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
/// averages), or when no averaging time has that many.
pub fn too_short(an: &Allan) -> Option<RecordWarning> {
    let t = &an.terms;
    let reported = |s: usize| match s {
        SIN => t.sinusoid.is_some(),
        MARKOV => t.correlated.is_some(),
        j if j < COUNT => t.present[j],
        _ => false,
    };
    let shapes: Vec<usize> = (0..COUNT)
        .chain([SIN, MARKOV])
        .filter(|&s| reported(s))
        .collect();
    let unsupported: Vec<&str> = shapes
        .iter()
        .filter(|&&s| {
            let dominated: Vec<f64> = t
                .dominant
                .iter()
                .zip(&t.edf)
                .filter(|(&d, _)| d == s)
                .map(|(_, &e)| e)
                .collect();
            !dominated.is_empty() && dominated.iter().all(|&e| e < MIN_EDF)
        })
        .map(|&s| shape_name(s))
        .collect();
    if unsupported.is_empty() {
        return None;
    }
    let duration = an.n as f64 * an.tau0;
    Some(RecordWarning {
        code: "too_short",
        message: format!(
            "the record ({duration:.4} s, {} samples) is too short to show {}: the fit reads \
             them only at its longest averaging times, from fewer than {MIN_EDF:.0} degrees of \
             freedom; their values and intervals mean little. A record ten times longer would show them",
            an.n,
            unsupported.join(", ")
        ),
    })
}
