//! The discovery's JSON (docs/interfaces.md keys and more).

use super::report;
use crate::model::discovery::estimates::Estimate;
use crate::model::discovery::result::TermFound;
use crate::model::discovery::terms::Kind;
use crate::model::discovery::Discovery;
use crate::model::effects::Effect;
use std::collections::BTreeMap;

/// An estimate's JSON: parameters and their 95 % intervals.
pub(super) fn estimate_json(e: &Estimate) -> serde_json::Value {
    let parameters: BTreeMap<&str, f64> = e.params.iter().map(|p| (p.0, p.1)).collect();
    let intervals: BTreeMap<&str, [f64; 2]> = e.params.iter().map(|p| (p.0, [p.2, p.3])).collect();
    serde_json::json!({
        "effect": e.effect,
        "parameters": parameters,
        "parameter_intervals": intervals,
        "delta_bic": e.delta_bic,
        "explained_share": e.explained_share,
    })
}

/// A term outside the library's JSON (docs/interfaces.md): its formula,
/// parameters with intervals, and how it was validated.
fn term_json(t: &TermFound) -> serde_json::Value {
    let intervals: BTreeMap<&str, [f64; 2]> = t
        .intervals
        .iter()
        .map(|(k, v)| (k.as_str(), [v.0, v.1]))
        .collect();
    let v = &t.validation;
    serde_json::json!({
        "effect": "term",
        "library": false,
        "label": t.label,
        "proposed": t.proposed,
        "formula": t.term.formula,
        "parameters": t.term.params,
        "parameter_intervals": intervals,
        "validation": {
            "method": "blocked cross-validation on the whitened 1 s means: the coefficients fitted on all folds but one, the held-out fold predicted, in turn",
            "folds": v.folds,
            "held_out_gain": v.held_out_gain,
            "fold_gains": v.fold_gains,
            "threshold": v.threshold,
            "held_out_share": v.held_out_share,
            "passed": v.held_out_gain >= v.threshold,
            "units": "noise variances of the whitened residual",
        },
        "disguise": t.disguise,
        "rival": t.rival.as_ref().map(|r| serde_json::json!({
            "label": r.label, "formula": r.formula, "held_out_gain": r.held_out_gain,
        })),
        "gap_closed": t.closure.map(|c| serde_json::json!({
            "gap_without_dph": c.0, "gap_with_dph": c.1, "excess_closed_share": c.2,
        })),
    })
}

/// The JSON of a discovery (docs/interfaces.md keys and more).
pub fn json(d: &Discovery) -> serde_json::Value {
    let mut found: Vec<serde_json::Value> = d.found.iter().map(estimate_json).collect();
    // Added: the terms proposed and named. A user's terms were not added
    // (they were in the model given): they are under `model_terms`, with
    // their parameters as fitted here.
    found.extend(
        d.terms
            .iter()
            .filter(|t| t.proposed && t.carried.is_none())
            .map(term_json),
    );
    let model_terms: Vec<serde_json::Value> = d
        .terms
        .iter()
        .filter(|t| !t.proposed)
        .map(|t| {
            let mut j = term_json(t);
            j["named"] = t.carried.is_none().into();
            j["why"] = t.carried.clone().into();
            j
        })
        .collect();
    let mut carried: Vec<serde_json::Value> = d
        .carried
        .iter()
        .map(|c| {
            let mut j = estimate_json(&c.estimate);
            j["why"] = c.why.clone().into();
            j
        })
        .collect();
    carried.extend(d.terms.iter().filter(|t| t.proposed).filter_map(|t| {
        t.carried.as_ref().map(|why| {
            let mut j = term_json(t);
            j["why"] = why.clone().into();
            j
        })
    }));
    let skipped: Vec<serde_json::Value> = d
        .skipped
        .iter()
        .map(|s| {
            let names: Vec<&str> = s.missing.iter().map(|c| c.name()).collect();
            serde_json::json!({"effect": s.effect.name(), "missing": names, "reason": s.reason})
        })
        .collect();
    let implausible: Vec<serde_json::Value> = d
        .implausible
        .iter()
        .map(|i| {
            let p: BTreeMap<&str, f64> = i.parameters.iter().map(|(k, v)| (k.as_str(), *v)).collect();
            let out: Vec<serde_json::Value> = i
                .outside
                .iter()
                .map(|(k, v, r)| serde_json::json!({"parameter": k, "value": v, "range": [r.0, r.1]}))
                .collect();
            serde_json::json!({"effect": i.effect, "parameters": p, "outside": out})
        })
        .collect();
    let n = &d.noise;
    serde_json::json!({
        "found": found,
        "gap_before_dph": d.gap_before_dph,
        "gap_after_dph": d.gap_after_dph,
        "gap_window_s": report::gap_window_s(d),
        "residual_mean": {
            "value_dph": d.residual_mean_dph,
            "sd_dph": d.residual_mean_sd_dph,
            "lo_dph": d.residual_mean_dph - 1.96 * d.residual_mean_sd_dph,
            "hi_dph": d.residual_mean_dph + 1.96 * d.residual_mean_sd_dph,
            "centred_by_dph": d.centred_by_dph,
        },
        "noise_floor_dph": d.noise_floor_dph,
        "noise_floor_hi_dph": d.noise_floor_hi_dph,
        "noise_floor_white_dph": d.noise_floor_white_dph,
        "ambiguous": d.ambiguous,
        "unexplained": d.unexplained,
        "carried": carried,
        "model_terms": model_terms,
        "implausible": implausible,
        "dropped": d.dropped,
        "not_confirmed": d
            .not_confirmed
            .iter()
            .map(|(k, g)| {
                let e = match k {
                    Kind::Constant => Some(Effect::Bias),
                    k => k.effect(),
                };
                serde_json::json!({"effect": e, "term": k.describe(), "gain": g})
            })
            .collect::<Vec<_>>(),
        "skipped": skipped,
        "proposal": {
            "tried": d.proposals.tried.iter().take(12).map(|t| serde_json::json!({
                "label": t.label, "formula": t.formula, "held_out_gain": t.held_out_gain,
            })).collect::<Vec<_>>(),
            "note": d.proposals.note,
            "space_size": d.proposals.space,
            "threshold": d.proposals.threshold,
        },
        "disagreements": d.disagreements,
        "noise": {
            "white_1s_dph": n.white.sqrt() * 3600.0,
            "bias_instability_dph": n.flicker.sqrt() * 3600.0,
            "rate_random_walk_dph_per_sqrt_h": n.random_walk.sqrt() * 3600.0 * 60.0,
            "passes": d.passes,
        },
        "fallback": d.fallback,
        "intervals_reliable": d.short.is_none(),
        "intervals_note": d.short,
        "windows": d.windows.len(),
        "fit_window_s": crate::model::discovery::fit_window_s(
            d.windows.t.last().copied().unwrap_or(0.0) - d.windows.t.first().copied().unwrap_or(0.0)
        ),
        "gyro": d.gyro.name(),
        "grade": d.grade,
    })
}
