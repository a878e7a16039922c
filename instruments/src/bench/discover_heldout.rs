//! Scoring discovery on the held-out set of the second generator
//! (sim/heldout_run.rs), from the truth it states and the JSON `discover`
//! printed for each run (any version of the tool: only the keys of
//! docs/interfaces.md and the parameter intervals are read). The rules are
//! the bench's (discover_trials.rs): right when exactly the expected names
//! are found (nothing on a null; nothing, and `unexplained` said, outside
//! the library); false names; the gap growing; and the interval coverage of
//! the named expected effects' parameters.

use std::collections::BTreeMap;

/// One run's truth, as `simulate heldout` writes it.
#[derive(Clone, Debug, serde::Deserialize)]
pub struct Truth {
    pub file: String,
    pub name: String,
    pub category: String,
    pub gyro: String,
    pub expect: Vec<String>,
    pub truth: BTreeMap<String, BTreeMap<String, f64>>,
    /// A second day of the same gyro (the third generator's MEMS runs).
    #[serde(default)]
    pub validate: Option<String>,
}

/// A run's score.
#[derive(Clone, Debug, serde::Serialize)]
pub struct Scored {
    pub name: String,
    pub category: String,
    pub expect: Vec<String>,
    pub named: Vec<String>,
    pub ambiguous: Vec<Vec<String>>,
    pub unexplained: bool,
    pub right: bool,
    pub false_names: usize,
    pub covered: usize,
    pub intervals: usize,
    /// Parameters outside their interval: (effect, parameter, truth, lo, hi).
    pub missed: Vec<(String, String, f64, f64, f64)>,
    pub gap_before_dph: f64,
    pub gap_after_dph: f64,
    pub gap_grew: bool,
}

fn names(v: &serde_json::Value) -> Vec<String> {
    v.as_array()
        .map(|a| {
            a.iter()
                .filter_map(|x| x.as_str().map(str::to_owned))
                .collect()
        })
        .unwrap_or_default()
}

/// Scores `r`, the JSON of `discover` on the run of `t`.
pub fn score(t: &Truth, r: &serde_json::Value) -> Scored {
    let found = r["found"].as_array().cloned().unwrap_or_default();
    // The library's names; a term outside it (issue 32) apart.
    let named: Vec<String> = found
        .iter()
        .filter_map(|f| f["effect"].as_str().map(str::to_owned))
        .filter(|e| e != "term")
        .collect();
    let terms = found.iter().filter(|f| f["effect"] == "term").count();
    let outside = t.category == "outside the library";
    let ambiguous: Vec<Vec<String>> = r["ambiguous"]
        .as_array()
        .map(|a| a.iter().map(|g| names(&g["effects"])).collect())
        .unwrap_or_default();
    let unexplained = !r["unexplained"].is_null();
    let (mut covered, mut intervals, mut missed) = (0, 0, vec![]);
    for f in &found {
        let Some(e) = f["effect"].as_str() else {
            continue;
        };
        let (Some(truth), true) = (t.truth.get(e), t.expect.iter().any(|x| x == e)) else {
            continue;
        };
        for (p, v) in truth {
            let iv = &f["parameter_intervals"][p.as_str()];
            let (Some(lo), Some(hi)) = (iv[0].as_f64(), iv[1].as_f64()) else {
                continue;
            };
            intervals += 1;
            if lo <= *v && *v <= hi {
                covered += 1;
            } else {
                missed.push((e.to_owned(), p.clone(), *v, lo, hi));
            }
        }
    }
    let mut ns = named.clone();
    ns.sort();
    let mut es = t.expect.clone();
    es.sort();
    let right = match t.category.as_str() {
        "null, coloured noise" => named.is_empty() && terms == 0,
        // Said unexplained, or a term proposed for it.
        "outside the library" => named.is_empty() && (unexplained || terms > 0),
        _ => ns == es && terms == 0,
    };
    let gb = r["gap_before_dph"].as_f64().unwrap_or(f64::NAN);
    let ga = r["gap_after_dph"].as_f64().unwrap_or(f64::NAN);
    Scored {
        name: t.name.clone(),
        category: t.category.clone(),
        expect: t.expect.clone(),
        // A term proposed where the truth holds none is a false name.
        false_names: named.iter().filter(|n| !t.expect.contains(n)).count()
            + if outside { 0 } else { terms },
        named,
        ambiguous,
        unexplained,
        right,
        covered,
        intervals,
        missed,
        gap_before_dph: gb,
        gap_after_dph: ga,
        gap_grew: ga > gb,
    }
}

/// Per category and over all: runs, right, false names, the gap growing,
/// unexplained said, intervals covering / all.
#[derive(Clone, Debug, Default, serde::Serialize)]
pub struct Totals {
    pub runs: usize,
    pub right: usize,
    pub false_names: usize,
    pub gap_grew: usize,
    pub unexplained: usize,
    pub covered: usize,
    pub intervals: usize,
}

/// The totals per category, and over all (key "all").
pub fn totals(s: &[Scored]) -> BTreeMap<String, Totals> {
    let mut m: BTreeMap<String, Totals> = BTreeMap::new();
    for x in s {
        for key in [x.category.clone(), "all".to_owned()] {
            let t = m.entry(key).or_default();
            t.runs += 1;
            t.right += usize::from(x.right);
            t.false_names += x.false_names;
            t.gap_grew += usize::from(x.gap_grew);
            t.unexplained += usize::from(x.unexplained);
            t.covered += x.covered;
            t.intervals += x.intervals;
        }
    }
    m
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scores_names_coverage_and_the_gap() {
        let t = Truth {
            file: "x.csv".into(),
            name: "bias+case".into(),
            category: "bias + thermal term (RLG chamber)".into(),
            gyro: "rlg".into(),
            expect: vec!["bias".into(), "case_temperature".into()],
            validate: None,
            truth: [
                ("bias".to_owned(), [("bias_dph".to_owned(), 0.5)].into()),
                (
                    "case_temperature".to_owned(),
                    [("dph_per_c".to_owned(), 0.01)].into(),
                ),
            ]
            .into(),
        };
        let r = serde_json::json!({
            "found": [
                {"effect": "bias", "parameters": {"bias_dph": 0.49},
                 "parameter_intervals": {"bias_dph": [0.48, 0.52]}},
                {"effect": "case_temperature", "parameters": {"dph_per_c": 0.0101},
                 "parameter_intervals": {"dph_per_c": [0.01005, 0.0102]}},
                {"effect": "warm_up", "parameters": {}}
            ],
            "ambiguous": [], "unexplained": null,
            "gap_before_dph": 1.0, "gap_after_dph": 1.1
        });
        let s = score(&t, &r);
        assert!(!s.right && s.false_names == 1 && s.gap_grew);
        assert_eq!((s.covered, s.intervals), (1, 2));
        assert_eq!(s.missed[0].1, "dph_per_c");
    }
}
