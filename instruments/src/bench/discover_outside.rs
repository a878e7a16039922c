//! Scoring discovery on the outside generator's cases (sim/outside_run/,
//! `simulate outside`), from the truth it states, the hidden term per row
//! it wrote, and what discovery added to the model: never from a formula's
//! text.
//!
//! - Physical terms and events: explained when what the model added (its
//!   output less the given model's, deg/h, 1 s means) correlates at least
//!   0.95 with the hidden term's 1 s means, the gap after is at most 1.25
//!   times the realised noise of run A (the truth's `noise_1s_dph`: RMS of
//!   the 1 s means of measured minus true output, about their mean), and
//!   no library effect is named beyond those the truth allows (a bias, and
//!   library effects that are an exact part of the term's expansion);
//!   predicts B when the model found on A leaves on run B a residual whose
//!   1 s means, less their mean (a bias may change from run to run), have
//!   an RMS at most 1.5 times B's realised noise.
//! - Nulls: nothing named, no term.
//! - Library runs: the library's names, nothing else but a bias, no term.

use std::collections::BTreeMap;

/// Correlation the model's addition must reach with the hidden term.
pub const MIN_CORRELATION: f64 = 0.95;
/// Below this RMS (deg/h, a millionth of any gyro's floor) a series is
/// taken as constant: the model's addition (y_after - y_given) carries
/// the rounding of the reference rate (1e-10 deg/h), not a shape.
pub const NEGLIGIBLE_DPH: f64 = 1e-6;
/// Gap after on A, and residual on B, as multiples of the realised noise.
pub const GAP_FACTOR: f64 = 1.25;
pub const PREDICT_FACTOR: f64 = 1.5;

/// A run's truth, as `simulate outside` writes it.
#[derive(Clone, Debug, serde::Deserialize)]
pub struct RunTruth {
    pub file: String,
    pub hidden: String,
    pub floor_dph: f64,
    pub noise_1s_dph: f64,
    #[serde(default)]
    pub white_1s_dph: f64,
}

/// A case's truth.
#[derive(Clone, Debug, serde::Deserialize)]
pub struct CaseTruth {
    pub name: String,
    pub kind: String,
    pub category: String,
    pub gyro: String,
    pub expect: Vec<String>,
    #[serde(default)]
    pub allow: Vec<String>,
    /// The hidden term's coefficient and shape parameters (read only by
    /// the bench's `--oracle` reference, never by the scoring).
    #[serde(default)]
    pub parameters: BTreeMap<String, f64>,
    pub a: RunTruth,
    pub b: RunTruth,
}

/// What the bench gathered on a case.
#[derive(Clone, Debug, Default)]
pub struct Evidence {
    /// `found[].effect` in order ("term" for a term outside the library).
    pub named: Vec<String>,
    /// 1 s means on run A of what the model added and of the hidden term, deg/h.
    pub added_1s: Vec<f64>,
    pub hidden_1s: Vec<f64>,
    pub gap_after_dph: f64,
    /// The tool's own noise floor (reported beside the truth's).
    pub tool_floor_dph: f64,
    /// 1 s means on run B of measured less the model found on A, deg/h.
    pub residual_b_1s: Vec<f64>,
}

/// A case's score.
#[derive(Clone, Debug, serde::Serialize)]
pub struct Scored {
    pub name: String,
    pub kind: String,
    pub category: String,
    pub named: Vec<String>,
    pub terms: usize,
    pub false_names: Vec<String>,
    pub correlation: f64,
    pub gap_after_dph: f64,
    pub floor_a_dph: f64,
    pub tool_floor_dph: f64,
    pub explained: bool,
    pub b_rms_dph: f64,
    pub floor_b_dph: f64,
    pub predicts_b: bool,
    /// The category's own rule (explained and predicts B; nothing named;
    /// the library's names).
    pub right: bool,
}

/// 1 s window means of `x` over rows `t` (windows [k, k+1) s).
pub fn means_1s(t: &[f64], x: &[f64]) -> Vec<f64> {
    let mut out: Vec<f64> = vec![];
    let mut cur: Option<(i64, f64, usize)> = None;
    for (ti, xi) in t.iter().zip(x) {
        let k = ti.floor() as i64;
        match &mut cur {
            Some((key, s, c)) if *key == k => {
                *s += xi;
                *c += 1;
            }
            _ => {
                if let Some((_, s, c)) = cur {
                    out.push(s / c as f64);
                }
                cur = Some((k, *xi, 1));
            }
        }
    }
    if let Some((_, s, c)) = cur {
        out.push(s / c as f64);
    }
    out
}

pub use gyro_lab_core::numerics::stats::pearson as correlation;

/// RMS about the mean (NaN stays NaN: a model that cannot be evaluated
/// predicts nothing).
pub fn rms_about_mean(v: &[f64]) -> f64 {
    let n = v.len().max(1) as f64;
    let m = v.iter().sum::<f64>() / n;
    (v.iter().map(|x| (x - m).powi(2)).sum::<f64>() / n).sqrt()
}

/// Scores what the bench gathered on a case against its truth.
pub fn score(t: &CaseTruth, e: &Evidence) -> Scored {
    let terms = e.named.iter().filter(|n| *n == "term").count();
    let false_names: Vec<String> = e
        .named
        .iter()
        .filter(|n| *n != "term" && !t.expect.contains(n) && !t.allow.contains(n))
        .cloned()
        .collect();
    let correlation = if rms_about_mean(&e.added_1s) < NEGLIGIBLE_DPH {
        0.0
    } else {
        correlation(&e.added_1s, &e.hidden_1s)
    };
    let floor_a = t.a.noise_1s_dph;
    let floor_b = t.b.noise_1s_dph;
    let b_rms = rms_about_mean(&e.residual_b_1s);
    let explained = correlation >= MIN_CORRELATION
        && e.gap_after_dph <= GAP_FACTOR * floor_a
        && false_names.is_empty();
    let predicts_b = b_rms <= PREDICT_FACTOR * floor_b;
    let right = match t.category.as_str() {
        // A null's truth may hold a bias (a gyro has one): naming it is no
        // false name; anything else is.
        "null" => e.named.iter().all(|n| t.allow.contains(n)),
        "library" => {
            t.expect.iter().all(|x| e.named.contains(x)) && terms == 0 && false_names.is_empty()
        }
        _ => explained && predicts_b,
    };
    Scored {
        name: t.name.clone(),
        kind: t.kind.clone(),
        category: t.category.clone(),
        named: e.named.clone(),
        terms,
        false_names,
        correlation,
        gap_after_dph: e.gap_after_dph,
        floor_a_dph: floor_a,
        tool_floor_dph: e.tool_floor_dph,
        explained,
        b_rms_dph: b_rms,
        floor_b_dph: floor_b,
        predicts_b,
        right,
    }
}

/// Per category: cases, explained, predicts B, both, cases with a term
/// where none belongs (nulls, library runs) or with any term at all, cases
/// with a false library name, cases with anything named, right.
#[derive(Clone, Debug, Default, serde::Serialize)]
pub struct Totals {
    pub n: usize,
    pub explained: usize,
    pub predicts_b: usize,
    pub explained_and_predicts_b: usize,
    pub with_term: usize,
    pub false_terms: usize,
    pub false_names: usize,
    pub anything_named: usize,
    pub right: usize,
}

/// The totals per category, and over all (key "all").
pub fn totals(s: &[Scored]) -> BTreeMap<String, Totals> {
    let mut m: BTreeMap<String, Totals> = BTreeMap::new();
    for x in s {
        let term_expected = x.category == "physical" || x.category == "event";
        for key in [x.category.clone(), "all".to_owned()] {
            let t = m.entry(key).or_default();
            t.n += 1;
            t.explained += usize::from(x.explained);
            t.predicts_b += usize::from(x.predicts_b);
            t.explained_and_predicts_b += usize::from(x.explained && x.predicts_b);
            t.with_term += usize::from(x.terms > 0);
            t.false_terms += usize::from(x.terms > 0 && !term_expected);
            t.false_names += usize::from(!x.false_names.is_empty());
            t.anything_named += usize::from(!x.named.is_empty());
            t.right += usize::from(x.right);
        }
    }
    m
}

#[cfg(test)]
mod tests {
    use super::*;

    fn truth(category: &str) -> CaseTruth {
        let run = RunTruth {
            file: "x.csv".into(),
            hidden: "x.hidden.csv".into(),
            floor_dph: 0.2,
            noise_1s_dph: 0.2,
            white_1s_dph: 0.2,
        };
        CaseTruth {
            name: "w2-1".into(),
            kind: "w2".into(),
            category: category.into(),
            gyro: "fog".into(),
            expect: if category == "library" {
                vec!["scale_factor_error".into()]
            } else if category == "null" {
                vec![]
            } else {
                vec!["term".into()]
            },
            allow: vec!["bias".into()],
            parameters: BTreeMap::new(),
            a: run.clone(),
            b: run,
        }
    }

    /// A hidden term, white noise of 0.2 deg/h on its 1 s means, and
    /// what a model adding `added` leaves.
    fn evidence(scale_added: f64, named: &[&str]) -> Evidence {
        let n = 3000;
        let t: Vec<f64> = (0..2 * n).map(|k| k as f64 * 0.5).collect();
        let hidden: Vec<f64> = t.iter().map(|s| 1.2 * (s / 400.0).sin() + 0.3).collect();
        // Deterministic "noise" with RMS 0.2 on 1 s means: a fast sequence.
        let noise_1s: Vec<f64> = (0..n)
            .map(|k| 0.2 * 2f64.sqrt() * ((k as f64) * 2.399_963).sin())
            .collect();
        let h1 = means_1s(&t, &hidden);
        let added: Vec<f64> = hidden.iter().map(|h| scale_added * h).collect();
        let a1 = means_1s(&t, &added);
        // Residual = hidden + noise - added (1 s means).
        let res: Vec<f64> = (0..n).map(|k| h1[k] + noise_1s[k] - a1[k]).collect();
        let gap = (res.iter().map(|x| x * x).sum::<f64>() / n as f64).sqrt();
        Evidence {
            named: named.iter().map(|s| s.to_string()).collect(),
            added_1s: a1,
            hidden_1s: h1,
            gap_after_dph: gap,
            tool_floor_dph: 0.2,
            residual_b_1s: res,
        }
    }

    #[test]
    fn the_exact_term_is_explained_and_nothing_is_not() {
        let t = truth("physical");
        let s = score(&t, &evidence(1.0, &["bias", "term"]));
        assert!(s.explained && s.predicts_b && s.right, "{s:?}");
        assert!((s.correlation - 1.0).abs() < 1e-12);
        // Adding nothing (a bias only): no correlation, the term left in the gap.
        let s = score(&t, &evidence(0.0, &["bias"]));
        assert!(!s.explained && !s.predicts_b && !s.right, "{s:?}");
        assert_eq!(s.correlation, 0.0);
        // Half the term: correlated, but the gap and B stay above the bars.
        let s = score(&t, &evidence(0.5, &["term"]));
        assert!(
            s.correlation > 0.99 && !s.explained && !s.predicts_b,
            "{s:?}"
        );
        // The exact term with a library effect the truth does not allow.
        let s = score(&t, &evidence(1.0, &["term", "scale_factor_asymmetry"]));
        assert!(!s.explained && s.false_names == vec!["scale_factor_asymmetry"]);
    }

    #[test]
    fn nulls_and_library_runs_follow_their_rules() {
        let mut n = truth("null");
        n.allow.clear();
        assert!(score(&n, &evidence(0.0, &[])).right);
        assert!(!score(&n, &evidence(0.0, &["bias"])).right);
        assert!(!score(&n, &evidence(0.0, &["term"])).right);
        // A null whose gyro has a bias: naming it is right.
        let mut nb = truth("null");
        nb.allow = vec!["bias".into()];
        assert!(score(&nb, &evidence(0.0, &["bias"])).right);
        assert!(!score(&nb, &evidence(0.0, &["bias", "shupe"])).right);
        let l = truth("library");
        assert!(score(&l, &evidence(1.0, &["bias", "scale_factor_error"])).right);
        assert!(!score(&l, &evidence(1.0, &["scale_factor_error", "term"])).right);
        assert!(!score(&l, &evidence(1.0, &["bias"])).right);
        let tot = totals(&[
            score(&n, &evidence(0.0, &["term"])),
            score(&l, &evidence(1.0, &["scale_factor_error"])),
        ]);
        assert_eq!(tot["null"].false_terms, 1);
        assert_eq!(tot["library"].right, 1);
        assert_eq!(tot["all"].n, 2);
    }

    #[test]
    fn one_second_means_follow_the_windows() {
        let t = [0.0, 0.5, 1.0, 1.5, 2.2];
        let x = [1.0, 3.0, 5.0, 7.0, 9.0];
        assert_eq!(means_1s(&t, &x), vec![2.0, 6.0, 9.0]);
    }
}
