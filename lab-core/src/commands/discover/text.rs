//! The discovery in words: the text the command prints.

use super::report;
use crate::model::discovery::estimates::Estimate;
use crate::model::discovery::result::TermFound;
use crate::model::discovery::terms::Kind;
use crate::model::discovery::Discovery;
use crate::model::effects::Effect;
use crate::report::text::sig;

fn term_params_text(t: &TermFound) -> String {
    t.term
        .params
        .iter()
        .map(|(n, v)| match t.intervals.get(n) {
            Some((lo, hi)) => format!("{n} {} [{} .. {}]", sig(*v), sig(*lo), sig(*hi)),
            None => format!("{n} {}", sig(*v)),
        })
        .collect::<Vec<_>>()
        .join(", ")
}

fn params_text(e: &Estimate) -> String {
    e.params
        .iter()
        .map(|(n, v, lo, hi)| format!("{n} {} [{} .. {}]", sig(*v), sig(*lo), sig(*hi)))
        .collect::<Vec<_>>()
        .join(", ")
}

pub(super) fn lines(name: &str, d: &Discovery, written: Option<&str>) -> Vec<String> {
    let mut out = vec![];
    out.push(format!(
        "{}: gap (RMS of {} of measured - model) {:.4} deg/h; noise floor there {:.4} deg/h",
        name,
        report::gap_means_text(d),
        d.gap_before_dph,
        d.noise_floor_dph
    ));
    out.push(format!(
        "grade: {} ({})",
        d.grade.value,
        if d.grade.inferred {
            d.grade.reason.clone()
        } else {
            "given".into()
        }
    ));
    for s in &d.skipped {
        let names: Vec<&str> = s.missing.iter().map(|c| c.name()).collect();
        if names.is_empty() {
            out.push(format!("skipped {}: {}", s.effect.name(), s.reason));
        } else {
            out.push(format!(
                "skipped {}: the run has no {}",
                s.effect.name(),
                names.join(", ")
            ));
        }
    }
    if let Some(s) = &d.short {
        out.push(format!("short record: {s}"));
    }
    for e in &d.found {
        out.push(format!(
            "found {}: {} (delta BIC {:.1}, explains {:.1} % of the residual variance)",
            e.effect.name(),
            params_text(e),
            e.delta_bic,
            100.0 * e.explained_share
        ));
    }
    for t in &d.terms {
        let ps = term_params_text(t);
        match &t.carried {
            None => out.push(format!(
                "{} {} ({}): {ps}; it predicts blocks of the record it was not fitted on by {:.1} noise variances (threshold {:.1}, {} folds){}",
                if t.proposed { "found term, a proposal outside the physics library:" } else { "fitted term written in the model:" },
                t.term.formula,
                t.label,
                t.validation.held_out_gain,
                t.validation.threshold,
                t.validation.folds,
                t.disguise.as_ref().map_or(String::new(), |g| format!("; it is {g}"))
            )),
            Some(why) => out.push(format!("carried term {}: {ps} ({why})", t.term.formula)),
        }
        if let Some(r) = t.rival_text() {
            out.push(format!("  {r}"));
        }
    }
    if let Some(n) = &d.proposals.note {
        out.push(format!("proposal: {n}"));
    }
    for c in &d.carried {
        out.push(format!(
            "carried {}: {} ({})",
            c.estimate.effect.name(),
            params_text(&c.estimate),
            c.why
        ));
    }
    for g in &d.ambiguous {
        out.push(format!(
            "ambiguous: {} (correlation {:.3}), carried as {}: {}",
            Effect::names(&g.effects, " / "),
            g.correlation.get(1).copied().unwrap_or(1.0),
            g.carried_as.name(),
            g.suggestion
        ));
    }
    for (k, g) in &d.not_confirmed {
        let what = match k {
            Kind::Constant => "bias".to_owned(),
            k => k.describe(),
        };
        out.push(format!(
            "set aside {what}: it paid on the selection's noise, but once the noise (random walk, flicker, Markov) is re-fitted without it, it gains only {g:.1} (threshold {}): the noise imitates it",
            crate::model::discovery::select::THRESHOLD
        ));
    }
    for i in &d.implausible {
        let o: Vec<String> = i
            .outside
            .iter()
            .map(|(k, v, r)| format!("{k} {} outside {} .. {}", sig(*v), sig(r.0), sig(r.1)))
            .collect();
        out.push(format!(
            "implausible {}: {} (not named: no {} is that)",
            i.effect.name(),
            o.join(", "),
            i.effect.name()
        ));
    }
    match &d.unexplained {
        Some(u) => {
            out.push(format!(
                "no effect of the library explains this: {:.4} deg/h above the noise ({})",
                u.excess_dph,
                u.carried_text()
            ));
            for s in u.spans.iter().take(8) {
                out.push(format!(
                    "  {:.0} .. {:.0} s (peak {:+.4} deg/h)",
                    s.from_s, s.to_s, s.peak_dph
                ));
            }
            if u.spans.len() > 8 {
                out.push(format!(
                    "  ... {} more spans (in the JSON and the report)",
                    u.spans.len() - 8
                ));
            }
            let c: Vec<String> = u
                .correlates
                .iter()
                .take(4)
                .map(|c| format!("{} (r = {:+.2})", c.input, c.correlation))
                .collect();
            out.push(format!("  it follows most: {}", c.join(", ")));
        }
        None if d.found.is_empty() && d.ambiguous.is_empty() && d.terms.is_empty() => {
            out.push("nothing is missing: no effect of the library beats the noise, and nothing stands out of it".to_string());
        }
        None => {}
    }
    if let Some(f) = &d.fallback {
        out.push(format!("note: {f}"));
    }
    out.push(format!(
        "the residual after the model averages {:.4} deg/h over the record (95 % interval {:.4} .. {:.4}{})",
        d.residual_mean_dph,
        d.residual_mean_dph - 1.96 * d.residual_mean_sd_dph,
        d.residual_mean_dph + 1.96 * d.residual_mean_sd_dph,
        if d.centred_by_dph != 0.0 {
            format!("; the model's constant moved by {:.4} deg/h to the residual's mean", d.centred_by_dph)
        } else {
            String::new()
        }
    ));
    out.push(format!(
        "gap {:.4} -> {:.4} deg/h{}",
        d.gap_before_dph,
        d.gap_after_dph,
        written.map_or(String::new(), |w| format!("; written {w}"))
    ));
    out
}
