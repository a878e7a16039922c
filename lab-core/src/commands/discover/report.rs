//! The discovery report (on the lab's one report writer, report/).

use crate::commands::adev_plot::adev_series;
use crate::model::discovery::estimates::Estimate;
use crate::model::discovery::noise_model::markov_avar;
use crate::model::discovery::{Discovery, Run, WINDOW_S};
use crate::model::effects::Effect;
use crate::noise::terms;
use crate::report::document::Report;
use crate::report::plot::{Axes, Series};
use crate::report::text::{num, sig, time_s};
use crate::report::verdict::Verdict;

const DPH: f64 = 3600.0;

/// At most this many points per time plot (window means thinned evenly).
const MAX_POINTS: usize = 2000;

fn scale(v: &[f64]) -> Vec<f64> {
    v.iter().map(|x| x * DPH).collect()
}

fn thin(t: &[f64], y: &[f64]) -> Vec<(f64, f64)> {
    let step = t.len().div_ceil(MAX_POINTS).max(1);
    t.iter()
        .zip(y)
        .step_by(step)
        .map(|(a, b)| (*a, *b))
        .collect()
}

/// The plots' time axis: the run's clock, or, where it reads a device's
/// clock far from zero (a record starting 2.6e8 s after its epoch), the
/// time since the record's first row, the clock's start said in the label.
fn time_axis(t: &[f64]) -> (Vec<f64>, String) {
    let (t0, t1) = (
        t.first().copied().unwrap_or(0.0),
        t.last().copied().unwrap_or(0.0),
    );
    if t0 > 10.0 * (t1 - t0).max(1.0) {
        (
            t.iter().map(|x| x - t0).collect(),
            format!(
                "time since the record's first window, s (at {} s on its clock)",
                time_s(t0)
            ),
        )
    } else {
        (t.to_vec(), "time since power-on, s".into())
    }
}

/// The residual over time before and after, and where it disagrees.
fn residual_section(r: &mut Report, d: &Discovery) {
    let win = &d.gap_windows;
    let before = win.mean(&d.residual_before);
    let after = win.mean(&d.residual_after);
    r.heading("Residual before and after");
    let (tx, x_label) = time_axis(&win.t);
    r.plot(
        &Axes {
            title: format!("measured - model, {}", gap_means_text(d)),
            x_label,
            y_label: "residual, deg/h".into(),
            log_x: false,
            log_y: false,
        },
        &[
            Series::line("before", thin(&tx, &scale(&before)), 0),
            Series::line("after", thin(&tx, &scale(&after)), 1),
        ],
        "The residual averaged over the gap's windows, before and after the found effects were added.",
    );
    if !d.disagreements.is_empty() {
        let rows: Vec<Vec<String>> = d
            .disagreements
            .iter()
            .map(|s| vec![time_s(s.from_s), time_s(s.to_s), num(s.peak_dph)])
            .collect();
        r.table(
            &["from, s", "to, s", "peak residual (60 s mean), deg/h"],
            &rows,
        );
    }
}

/// The residual's Allan deviation before and after, against the floor.
fn allan_section(r: &mut Report, d: &Discovery) {
    if let (Some(a), Some(b)) = (&d.allan_before, &d.allan_after) {
        r.heading("Allan deviation before and after, against the noise floor");
        let mut s = adev_series(a, "before", 0, false);
        s.extend(adev_series(b, "after", 1, false));
        // The noise model the discovery judged against (its slow levels
        // at most the grade's), as an Allan deviation: white N^2/tau with
        // N^2 the variance of a 1 s mean, flicker's floor, the Markov
        // term, the random walk's K^2 tau/3. (The Allan terms of the
        // residual before the model read a missing effect as noise.)
        let m = d.noise.capped(d.grade.value.noise_caps());
        // A window's white variance is that of one sample where the record
        // is sparser than the windows (a row every 15 s): white N^2/tau
        // from the windows' own spacing.
        let mut gaps: Vec<f64> = d.windows.t.windows(2).map(|p| p[1] - p[0]).collect();
        gaps.sort_by(f64::total_cmp);
        let dt = gaps
            .get(gaps.len() / 2)
            .copied()
            .unwrap_or(WINDOW_S)
            .max(WINDOW_S);
        let model: Vec<(f64, f64)> = a
            .taus
            .iter()
            .filter(|&&t| t >= dt)
            .map(|&t| {
                let v = m.white * dt / t
                    + m.flicker * terms::basis(2, t)
                    + m.markov * markov_avar(t, m.markov_s.max(1e-9))
                    + m.random_walk * t / 3.0;
                (t, v.sqrt() * DPH)
            })
            .collect();
        s.push(Series::dashed("noise model (the floor's)", model, 7));
        r.plot(
            &Axes {
                title: "Allan deviation of the residual".into(),
                x_label: "averaging time tau, s".into(),
                y_label: "Allan deviation, deg/h".into(),
                log_x: true,
                log_y: true,
            },
            &s,
            "A missing effect lifts the residual's Allan deviation above the noise model at long averaging; once \
             it is in the model the \"after\" curve lies on the noise model's (dashed: the residual's white, \
             flicker, Markov and random-walk levels as fitted, each at most the grade's; at 1 s it is the floor).",
        );
    }
}

fn params_cell(e: &Estimate) -> String {
    e.params
        .iter()
        .map(|(n, v, lo, hi)| format!("{n} = {} [{} .. {}]", sig(*v), sig(*lo), sig(*hi)))
        .collect::<Vec<_>>()
        .join("; ")
}

/// The table of the effects found and carried.
fn found_section(r: &mut Report, d: &Discovery) {
    r.heading("Effects found");
    if d.found.is_empty() {
        let terms = d.terms.iter().any(|t| t.proposed && t.carried.is_none());
        r.paragraph(if d.unexplained.is_some() {
            "No effect of the library is named (what the residual holds is below, under \"Unexplained\")."
        } else if terms {
            "No effect of the library is named: a term outside the library explains what the residual held \
             (below, under \"Terms outside the physics library\")."
        } else if d.ambiguous.is_empty() {
            "Nothing is missing: no effect of the library beats the noise, and nothing stands out of it."
        } else {
            "No effect is named: the run cannot tell apart the effects below."
        });
    } else {
        let rows: Vec<Vec<String>> = d
            .found
            .iter()
            .map(|e| {
                vec![
                    e.effect.name().into(),
                    params_cell(e),
                    format!("{:.1}", e.delta_bic),
                    format!("{:.1} %", 100.0 * e.explained_share),
                ]
            })
            .collect();
        r.table(
            &[
                "effect",
                "parameters (95 % interval, the residual's coloured noise included)",
                "BIC change without it",
                "share of residual variance",
            ],
            &rows,
        );
    }
    if !d.dropped.is_empty() {
        // A name that came in and went: beside a term that carries it, or
        // by the selection's backward steps.
        r.paragraph(&format!("Named, then dropped: {}.", d.dropped.join("; ")));
    }
    if !d.carried.is_empty() {
        r.paragraph("Carried in the model written, not named:");
        let rows: Vec<Vec<String>> = d
            .carried
            .iter()
            .map(|c| {
                vec![
                    c.estimate.effect.name().into(),
                    params_cell(&c.estimate),
                    c.why.clone(),
                ]
            })
            .collect();
        r.table(&["effect", "parameters (95 % interval)", "why"], &rows);
    }
    if let Some(f) = &d.fallback {
        r.note(f);
    }
}

/// The terms outside the library: each against the residual it explains,
/// said plainly to be a proposal, with its evidence.
fn terms_section(r: &mut Report, d: &Discovery, run: &Run) {
    if d.terms.is_empty() && d.proposals.tried.is_empty() {
        return;
    }
    r.heading("Terms outside the physics library");
    if d.proposals.space > 0 {
        r.paragraph(&format!(
            "The candidates are composed from the run's own inputs (docs/discovery.md): the rate and |rate|, each \
             temperature, its rates of change, its lag and the differences between sensors, the acceleration, and \
             shapes of time; their squares and cubes, products of two, an input times a shape of time, and events \
             searched in two parameters. {} candidate columns (every point of every search) were screened; a \
             candidate must predict blocks of the record it was not fitted on by {} noise variances, a threshold \
             that grows with the space (4 ln of its size), so that noise buys no term.",
            d.proposals.space,
            num(d.proposals.threshold)
        ));
    }
    let win = &d.windows;
    let after = win.mean(&d.residual_after);
    // The time axis every term is plotted against.
    let (tx, x_label) = time_axis(&win.t);
    for t in &d.terms {
        let what = if t.proposed {
            format!(
                "A proposal outside the physics library: {} ({}), built from the run's own inputs because no \
                 library effect explained what the residual held. It is not a named physical effect: it is the \
                 simplest candidate that predicts data it was not fitted on.",
                t.term.formula, t.label
            )
        } else {
            format!(
                "Written in the model given: {} (its parameters fitted here).",
                t.term.formula
            )
        };
        r.paragraph(&what);
        let params: Vec<String> = t
            .term
            .params
            .iter()
            .map(|(k, v)| match t.intervals.get(k) {
                Some((lo, hi)) => format!("{k} = {} [{} .. {}]", sig(*v), sig(*lo), sig(*hi)),
                None => format!("{k} = {}", sig(*v)),
            })
            .collect();
        let v = &t.validation;
        let worst = v.fold_gains.iter().copied().fold(f64::INFINITY, f64::min);
        r.table(
            &["parameters (95 % interval)", "validation", "status"],
            &[vec![
                params.join("; "),
                format!(
                    "blocked cross-validation, {} folds: fitted on the others, each fold predicted; held-out gain {} \
                     noise variances (threshold {}; worst fold {}), {} % of the whitened residual",
                    v.folds,
                    sig(v.held_out_gain),
                    sig(v.threshold),
                    sig(worst),
                    sig(100.0 * v.held_out_share)
                ),
                t.carried.clone().unwrap_or_else(|| {
                    if t.proposed {
                        "in the model written, as a proposal (not a library effect)".into()
                    } else {
                        "in the model written, fitted".into()
                    }
                }),
            ]],
        );
        if let Some(g) = &t.disguise {
            r.note(&format!("A known shape in disguise: this term is {g}."));
        }
        if let Some(x) = t.rival_text() {
            r.note(&format!("{x}."));
        }
        let Ok(c) = t.term.evaluate(&run.inputs) else {
            continue;
        };
        let cw: Vec<f64> = win.mean(&c);
        // The residual the term explains: after the model, the term put back.
        let partial: Vec<f64> = after.iter().zip(&cw).map(|(a, b)| a * DPH + b).collect();
        r.plot(
            &Axes {
                title: format!("{}: the term against the residual it explains", t.term.formula),
                x_label: x_label.clone(),
                y_label: "deg/h".into(),
                log_x: false,
                log_y: false,
            },
            &[
                Series::points("residual with the term put back, 1 s means", thin(&tx, &partial), None, 0),
                Series::line("the term", thin(&tx, &cw), 1),
            ],
            "The residual after the model with this term's contribution added back (points), and the term (line): \
             where the term is what was missing the points scatter about the line by the noise alone.",
        );
    }
    if !d.proposals.tried.is_empty() {
        let rows: Vec<Vec<String>> = d
            .proposals
            .tried
            .iter()
            .take(8)
            .map(|c| vec![c.label.to_string(), c.formula.clone(), sig(c.held_out_gain)])
            .collect();
        r.paragraph("The candidates tried last, best first (held-out gain in noise variances of the whitened residual):");
        r.table(&["candidate", "formula", "held-out gain"], &rows);
    }
    if let Some(n) = &d.proposals.note {
        r.note(n);
    }
}

/// What no effect of the library explains.
fn unexplained_section(r: &mut Report, d: &Discovery) {
    r.heading("Unexplained");
    let Some(u) = &d.unexplained else {
        r.paragraph(&format!(
            "The model explains the data to its noise: nothing stands out of the residual's noise \
             (white {} deg/h in 1 s, bias instability {} deg/h, rate random walk {} deg/h/sqrt(h), from the Allan \
             analysis of the residual).",
            num(d.noise.white.sqrt() * DPH),
            num(d.noise.flicker.sqrt() * DPH),
            num(d.noise.random_walk.sqrt() * DPH * 60.0)
        ));
        return;
    };
    r.paragraph(&format!(
        "No effect of the library explains this: {} deg/h (RMS of {}) stays above the noise after the model, \
         carried by {}.",
        num(u.excess_dph),
        gap_means_text(d),
        u.carried_text()
    ));
    if !u.spans.is_empty() {
        let rows: Vec<Vec<String>> = u
            .spans
            .iter()
            .map(|s| vec![time_s(s.from_s), time_s(s.to_s), num(s.peak_dph)])
            .collect();
        r.table(
            &[
                "from, s",
                "to, s",
                "peak residual after the model (60 s mean), deg/h",
            ],
            &rows,
        );
    }
    let rows: Vec<Vec<String>> = u
        .correlates
        .iter()
        .map(|c| vec![c.input.clone(), format!("{:+.3}", c.correlation)])
        .collect();
    r.table(&["input", "correlation with the unexplained part"], &rows);
    if !d.implausible.is_empty() {
        let rows: Vec<Vec<String>> = d
            .implausible
            .iter()
            .map(|i| {
                let o: Vec<String> = i
                    .outside
                    .iter()
                    .map(|(k, v, rg)| {
                        format!("{k} = {} (range {} .. {})", sig(*v), sig(rg.0), sig(rg.1))
                    })
                    .collect();
                vec![i.effect.name().into(), o.join("; ")]
            })
            .collect();
        r.paragraph("Fits outside their physical range, not named:");
        r.table(&["effect", "parameters outside their range"], &rows);
    }
}

/// Each effect found against the residual it explains.
fn effect_plots(r: &mut Report, d: &Discovery, run: &Run) {
    let win = &d.windows;
    let after = win.mean(&d.residual_after);
    for e in &d.found {
        // The effect's contribution against the residual it explains (the
        // residual after, plus the effect back).
        let params = e.params.iter().map(|p| (p.0.to_owned(), p.1)).collect();
        let c = e.effect.contribution(&run.inputs, &params);
        let cw = win.mean(&c);
        let partial: Vec<f64> = after.iter().zip(&cw).map(|(a, b)| a + b).collect();
        let pts = thin(&scale(&cw), &scale(&partial));
        let (lo, hi) = cw
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| {
                (a.min(*x), b.max(*x))
            });
        // A constant (the bias) has no shape to plot against the residual:
        // its points would stand in one column.
        if hi - lo <= 1e-9 * lo.abs().max(hi.abs()) {
            continue;
        }
        r.plot(
            &Axes {
                title: format!("{}: regressor against residual", e.effect.name()),
                x_label: format!("{} contribution, deg/h", e.effect.name()),
                y_label: "residual with it, deg/h".into(),
                log_x: false,
                log_y: false,
            },
            &[
                Series::points(&gap_means_text(d), pts, None, 0),
                Series::line("fitted", vec![(lo * DPH, lo * DPH), (hi * DPH, hi * DPH)], 1),
            ],
            &format!(
                "The residual the {} explains (after the model, with this effect put back) against the effect's \
                 fitted contribution: the points lie along the line when the effect is what was missing.",
                e.effect.name()
            ),
        );
    }
}

/// Groups of effects the run cannot tell apart, and the effects skipped.
fn ambiguous_and_skipped(r: &mut Report, d: &Discovery) {
    if !d.ambiguous.is_empty() {
        r.heading("Effects this run cannot tell apart");
        let rows: Vec<Vec<String>> = d
            .ambiguous
            .iter()
            .map(|g| {
                vec![
                    Effect::names(&g.effects, " / "),
                    format!("{:.3}", g.correlation.get(1).copied().unwrap_or(1.0)),
                    g.carried_as.name().into(),
                    g.suggestion.clone(),
                ]
            })
            .collect();
        r.table(
            &[
                "effects",
                "correlation",
                "carried as",
                "a test profile that separates them",
            ],
            &rows,
        );
    }
    if !d.skipped.is_empty() {
        r.note(&format!(
            "Skipped: {}.",
            d.skipped
                .iter()
                .map(|s| {
                    let names: Vec<&str> = s.missing.iter().map(|c| c.name()).collect();
                    if names.is_empty() {
                        format!("{} ({})", s.effect.name(), s.reason)
                    } else {
                        format!("{} (the run lacks {})", s.effect.name(), names.join(", "))
                    }
                })
                .collect::<Vec<_>>()
                .join("; ")
        ));
    }
}

/// The verdict: what was found, how much of the gap it closed, what is
/// left and where, each number tagged with its JSON key.
fn verdict(d: &Discovery) -> Verdict {
    let mut v = Verdict::new();
    if d.found.is_empty() {
        v.text(if d.terms.iter().any(|t| t.carried.is_none()) {
            "No effect of the library is named. "
        } else {
            "Nothing is named. "
        });
    } else {
        v.text("Found ");
        for (i, e) in d.found.iter().enumerate() {
            if i > 0 {
                v.text(if i + 1 == d.found.len() {
                    " and "
                } else {
                    ", "
                });
            }
            v.word(&format!("found.{i}.effect"), e.effect.name());
            let lin = e.effect.linear_params();
            if let Some(p) = e
                .params
                .iter()
                .find(|p| lin.contains(&p.0))
                .or(e.params.first())
            {
                v.text(" (").text(p.0).text(" ").text(&sig(p.1)).text(")");
            }
        }
        v.text(". ");
    }
    let named_terms: Vec<&str> = d
        .terms
        .iter()
        .filter(|t| t.carried.is_none())
        .map(|t| t.term.formula.as_str())
        .collect();
    if !named_terms.is_empty() {
        v.text(&format!(
            "Added outside the physics library (a proposal, validated on blocks of the record it was not fitted on): {}. ",
            named_terms.join("; ")
        ));
        v.warning(
            "proposal",
            "a term outside the physics library is in the model written: it predicts the data, but it is not a named physical effect",
        );
    }
    v.text(&format!(
        " The gap (RMS of {} of measured - model) went from ",
        gap_means_text(d)
    ))
    .num("gap_before_dph", d.gap_before_dph, 4)
    .text(" to ")
    .num("gap_after_dph", d.gap_after_dph, 4)
    .text(" deg/h against a noise floor of ")
    .num("noise_floor_dph", d.noise_floor_dph, 4)
    .text(" deg/h");
    let excess = |g: f64| (g * g - d.noise_floor_dph.powi(2)).max(0.0);
    if excess(d.gap_before_dph) > 0.0 {
        let closed = 100.0 * (1.0 - excess(d.gap_after_dph) / excess(d.gap_before_dph));
        v.text(&format!(
            " ({closed:.0} % of what stood above the floor closed)"
        ));
    }
    v.text("; ")
        .word("grade.value", d.grade.value.name())
        .text(if d.grade.inferred {
            " grade, judged from the run's white noise. "
        } else {
            " grade, given. "
        });
    match &d.unexplained {
        Some(u) => {
            v.text("Left unexplained: ")
                .num("unexplained.excess_dph", u.excess_dph, 4)
                .text(" deg/h above the noise, carried by ")
                .text(&u.carried_text());
            if let (Some(a), Some(b)) = (u.spans.first(), u.spans.last()) {
                v.text(&format!(
                    ", in {} span(s) from {} s to {} s",
                    u.spans.len(),
                    time_s(a.from_s),
                    time_s(b.to_s)
                ));
            }
            if let Some(c) = u.correlates.first() {
                v.text(&format!(
                    ", following {} most (r = {:+.2})",
                    c.input, c.correlation
                ));
            }
            v.warning(
                "unexplained",
                "no effect of the library explains what is left; it is not in the model written",
            );
        }
        None => {
            v.text("Nothing is left above the noise.");
        }
    }
    if !d.ambiguous.is_empty() {
        v.warning(
            "ambiguous",
            &format!(
                "this run cannot tell apart {}",
                d.ambiguous
                    .iter()
                    .map(|g| Effect::names(&g.effects, " / "))
                    .collect::<Vec<_>>()
                    .join("; ")
            ),
        );
    }
    if let Some(s) = &d.short {
        v.warning("short_record", s);
    }
    v
}

pub fn report(d: &Discovery, run: &Run, data: &str, warnings: &[crate::record::Warning]) -> Report {
    let mut r = Report::new(&format!("What the model misses: {data}"));
    let mut v = verdict(d);
    v.text(" The residual after the model averages ")
        .num("residual_mean.value_dph", d.residual_mean_dph, 4)
        .text(" deg/h over the record (standard deviation ")
        .num("residual_mean.sd_dph", d.residual_mean_sd_dph, 4)
        .text(" deg/h).");
    for w in warnings {
        v.warning(w.code, &w.message);
    }
    r.verdict(&v);
    r.paragraph(&format!(
        "{} gyro, {} rows (the fit's windows of {} s: {}). Gap (RMS of {} of measured - model): {} deg/h \
         before, {} deg/h after; noise floor there {} deg/h (what the residual's noise, its slow levels at \
         most the grade's, leaves in the gap).",
        d.gyro.name(),
        run.inputs.len(),
        crate::report::text::sig(crate::model::discovery::fit_window_s(
            run.inputs.t.last().copied().unwrap_or(0.0) - run.inputs.t.first().copied().unwrap_or(0.0)
        )),
        d.windows.len(),
        gap_means_text(d),
        num(d.gap_before_dph),
        num(d.gap_after_dph),
        num(d.noise_floor_dph)
    ));
    residual_section(&mut r, d);
    allan_section(&mut r, d);
    found_section(&mut r, d);
    terms_section(&mut r, d, run);
    unexplained_section(&mut r, d);
    effect_plots(&mut r, d, run);
    ambiguous_and_skipped(&mut r, d);
    r
}

/// What the gap's means are over: 1 s windows, or the rows themselves
/// where they are further apart.
pub fn gap_window_s(d: &Discovery) -> f64 {
    let t = &d.gap_windows.t;
    let mut g: Vec<f64> = t.windows(2).map(|w| w[1] - w[0]).collect();
    if g.is_empty() {
        return WINDOW_S;
    }
    let k = g.len() / 2;
    let med = *g.select_nth_unstable_by(k, f64::total_cmp).1;
    med.max(WINDOW_S)
}

/// "1 s means", or "the rows (15 s each)" where the rows are longer.
pub fn gap_means_text(d: &Discovery) -> String {
    let w = gap_window_s(d);
    if w > 1.5 * WINDOW_S {
        format!("its rows ({} s each)", sig(w))
    } else {
        format!("{WINDOW_S} s means")
    }
}

#[cfg(test)]
mod tests {
    use super::time_axis;

    #[test]
    fn a_device_clock_is_plotted_from_the_records_start() {
        // A record of 70 min stamped on a clock 2.6e8 s from its epoch.
        let t: Vec<f64> = (0..4200).map(|k| 2.565e8 + k as f64).collect();
        let (x, label) = time_axis(&t);
        assert_eq!((x[0], x[4199]), (0.0, 4199.0));
        assert!(label.contains("256500000.0 s on its clock"), "{label}");
        // A clock from power-on is the axis as it stands.
        let t: Vec<f64> = (0..100).map(|k| 5.0 + k as f64).collect();
        let (x, label) = time_axis(&t);
        assert_eq!(x, t);
        assert_eq!(label, "time since power-on, s");
    }
}
