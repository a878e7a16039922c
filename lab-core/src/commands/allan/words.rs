//! The Allan analysis in words: the headline figures, the verdict on the
//! fit, the readings off the curve, the terms' rows, the text the command
//! prints.

use crate::noise::analysis::Allan;
use crate::noise::gaps::Filled;
use crate::noise::terms::{self, COUNT, PLAIN, SLOPES, UNITS};
use crate::report::text::{num, sig};

const DPH: f64 = 3600.0;

/// What filling the record's gaps did, and what it costs.
pub fn gaps_text(f: &Filled) -> String {
    let mut parts = vec![];
    if f.gaps > 0 {
        parts.push(format!(
            "gaps: {} in the record (samples lost on the way), {} samples ({:.3} % of the series) filled \
             with the rate over each gap; the angle is kept, so averages spanning a gap are right, but the \
             noise inside the gaps is missing and deviations at averaging times shorter than a gap read low \
             by up to that share",
            f.gaps,
            f.filled,
            100.0 * f.filled_fraction()
        ));
    }
    if f.stretched > 0 {
        parts.push(format!(
            "{} interval(s) longer than the sample period by less than half of one (a frame spanning \
             closures the board missed; no sample lost): resampled through the angle",
            f.stretched
        ));
    }
    parts.join("; ")
}

/// The figures a user looks for first, in words: the angle random walk
/// and the bias instability (fitted, with their intervals, and as read off
/// the curve), and any slower term the curve shows.
pub fn headline(an: &Allan) -> String {
    let t = &an.terms;
    let term = |j: usize| -> String {
        if t.present[j] {
            format!(
                "{} {} [{} .. {}] {}{}",
                PLAIN[j],
                num(terms::to_units(j, t.c[j])),
                num(terms::to_units(j, t.lo[j])),
                num(terms::to_units(j, t.hi[j])),
                UNITS[j],
                if t.reliable[j] { "" } else { " (unreliable)" }
            )
        } else {
            format!("no {} (the curve shows no slope {})", PLAIN[j], SLOPES[j])
        }
    };
    let r = &an.readings;
    let n_read = r
        .arw_dpsh
        .map_or("no -1/2 region to read N from".into(), |n| {
            format!("N = {} deg/sqrt(h) read at 1 s", num(n))
        });
    let b_read = if r.resolved {
        format!(
            "B = {} deg/h read off the floor",
            num(r.bias_instability_dph)
        )
    } else {
        format!(
            "B <= {} deg/h (the floor is not resolved: an upper bound)",
            num(r.bias_instability_dph)
        )
    };
    let slow: Vec<String> = [0, 3, 4]
        .into_iter()
        .filter(|&j| t.present[j])
        .map(term)
        .collect();
    format!(
        "In short: {}; {}. Read off the curve: {n_read}; {b_read}.{}",
        term(1),
        term(2),
        if slow.is_empty() {
            " No quantization, rate random walk or rate ramp shows.".to_owned()
        } else {
            format!(" Also: {}.", slow.join("; "))
        }
    )
}

/// The verdict on the fit, one sentence.
pub fn verdict(an: &Allan) -> String {
    let g = &an.terms.goodness;
    let out: Vec<String> = g.outside.iter().map(|&i| sig(an.taus[i])).collect();
    if g.consistent && out.is_empty() {
        format!(
            "The model fits: it passes through every measured 95 % interval (chi-square per degree of freedom {:.2}, \
             at most {:.2} for a right model).",
            g.chi2_per_dof, g.limit_per_dof
        )
    } else if g.consistent {
        format!(
            "The model fits within the scatter the estimates' correlation allows (chi-square per degree of freedom \
             {:.2}, at most {:.2} for a right model); it leaves the measured 95 % interval at {} of {} averaging \
             times: {} s.",
            g.chi2_per_dof,
            g.limit_per_dof,
            out.len(),
            an.taus.len(),
            out.join(", ")
        )
    } else {
        format!(
            "THE MODEL DOES NOT FIT this curve: chi-square per degree of freedom {:.2} where a right model stays \
             below {:.2}; it leaves the measured 95 % interval at {} of {} averaging times: {} s. Something there \
             is none of the IEEE 952 terms (or not in the form fitted); the intervals below are widened by the \
             misfit and the terms carrying those averaging times are marked unreliable.",
            g.chi2_per_dof,
            g.limit_per_dof,
            out.len(),
            an.taus.len(),
            out.join(", ")
        )
    }
}

/// The readings, one sentence.
pub fn readings_text(an: &Allan) -> String {
    let r = &an.readings;
    let n = match (r.arw_dpsh, r.arw_region_s) {
        (Some(n), Some((a, b))) => format!(
            "N = {} deg/sqrt(h) on the -1/2 line through {} .. {} s read at 1 s",
            num(n),
            sig(a),
            sig(b)
        ),
        _ => "no -1/2 region, so no N reading".into(),
    };
    let b = if r.resolved {
        format!(
            "floor {} deg/h at {} s, B = floor/0.664 = {} deg/h (the curve turns up after it)",
            num(r.floor_dph),
            sig(r.floor_tau_s),
            num(r.bias_instability_dph)
        )
    } else {
        let after = match r.rise {
            Some((t, v)) => format!(
                "the curve rises after it (to {} deg/h at {} s) but within the 95 % intervals, not beyond the floor's",
                num(v),
                sig(t)
            ),
            None => "the curve does not rise after it".into(),
        };
        format!(
            "lowest point {} deg/h at {} s; {after}, so the floor is not resolved and B <= {} deg/h is only an \
             upper bound",
            num(r.floor_dph),
            sig(r.floor_tau_s),
            num(r.bias_instability_dph)
        )
    };
    format!("Readings off the curve: {n}; {b}.")
}

/// The rows of the terms table (and of the terminal's list).
pub fn term_rows(an: &Allan) -> Vec<Vec<String>> {
    let t = &an.terms;
    let row = |name: &str, slope: &str, v: f64, lo: f64, hi: f64, unit: &str, rel: bool| {
        vec![
            name.to_owned(),
            slope.to_owned(),
            num(v),
            num(lo),
            num(hi),
            unit.to_owned(),
            if rel { "yes".into() } else { "no".into() },
        ]
    };
    let mut rows: Vec<Vec<String>> = (0..COUNT)
        .map(|j| {
            if t.present[j] {
                let bounded = j == 2 && t.bias_upper_bound;
                row(
                    if bounded {
                        "bias instability (upper bound: floor not resolved)"
                    } else {
                        PLAIN[j]
                    },
                    SLOPES[j],
                    terms::to_units(j, t.c[j]),
                    terms::to_units(j, t.lo[j]),
                    terms::to_units(j, t.hi[j]),
                    UNITS[j],
                    t.reliable[j],
                )
            } else {
                vec![
                    PLAIN[j].into(),
                    SLOPES[j].into(),
                    "absent".into(),
                    "-".into(),
                    "-".into(),
                    UNITS[j].into(),
                    "-".into(),
                ]
            }
        })
        .collect();
    if let Some(f) = &t.arw_filter_s {
        rows.push(row(
            "  white noise filter time constant",
            "bends -1/2 at short tau",
            f.value,
            f.lo,
            f.hi,
            "s",
            true,
        ));
    }
    match &t.sinusoid {
        Some(s) => {
            let a = &s.amplitude_dps;
            rows.push(row(
                "sinusoid amplitude",
                "bump, then -1",
                a.value * DPH,
                a.lo * DPH,
                a.hi * DPH,
                "deg/h",
                s.reliable,
            ));
            let f = &s.frequency_hz;
            rows.push(row(
                "sinusoid frequency",
                "bump at 0.37/f",
                f.value,
                f.lo,
                f.hi,
                "Hz",
                s.reliable,
            ));
        }
        None => rows.push(vec![
            "sinusoid".into(),
            "bump".into(),
            "absent".into(),
            "-".into(),
            "-".into(),
            "-".into(),
            "-".into(),
        ]),
    }
    match &t.correlated {
        Some(c) => {
            let s = &c.sigma_dph;
            rows.push(row(
                "correlated (Markov) sigma",
                "+1/2 .. -1/2",
                s.value,
                s.lo,
                s.hi,
                "deg/h",
                c.reliable,
            ));
            let tc = &c.tau_s;
            rows.push(row(
                "correlated (Markov) time",
                "hump at 1.89 T",
                tc.value,
                tc.lo,
                tc.hi,
                "s",
                c.reliable,
            ));
            let w = &c.white_limit_dpsh;
            rows.push(row(
                "  its white limit N = q T",
                "-1/2 at tau >> T",
                w.value,
                w.lo,
                w.hi,
                "deg/sqrt(h)",
                c.reliable,
            ));
        }
        None => rows.push(vec![
            "correlated (Markov)".into(),
            "hump".into(),
            "absent".into(),
            "-".into(),
            "-".into(),
            "-".into(),
            "-".into(),
        ]),
    }
    rows
}

/// The first line of the text: what was analysed, over which averaging
/// times.
pub fn first_line(an: &Allan, name: &str, analysed: &str) -> String {
    format!(
        "{}: `{}`, {} samples at {} s ({:.4} h); {} averaging times {} .. {} s",
        name,
        analysed,
        an.n,
        sig(an.tau0),
        an.n as f64 * an.tau0 / 3600.0,
        an.taus.len(),
        sig(an.taus[0]),
        sig(an.taus[an.taus.len() - 1])
    )
}

/// The text of the analysis, line by line.
pub fn text(
    an: &Allan,
    name: &str,
    analysed: &str,
    (read_s, compute_s): (f64, f64),
) -> Vec<String> {
    let mut out = vec![first_line(an, name, analysed)];
    out.push(format!(
        "mean rate {:.6e} +- {:.2e} deg/s (standard error from the noise model at the record length)",
        an.mean_dps, an.mean_se_dps
    ));
    out.push(headline(an));
    out.push(verdict(an));
    out.push("IEEE 952 terms (95 % intervals; fitted to the whole curve; absent: the curve does not show it):".into());
    for r in term_rows(an) {
        if r[2] == "absent" {
            out.push(format!(
                "  {:<34} absent (the curve does not show slope {})",
                r[0], r[1]
            ));
        } else {
            out.push(format!(
                "  {:<34} {:>12} [{} .. {}] {}{}",
                r[0],
                r[2],
                r[3],
                r[4],
                r[5],
                if r[6] == "no" { "  (unreliable)" } else { "" }
            ));
        }
    }
    out.push(readings_text(an));
    out.push(format!("read {read_s:.2} s, computed {compute_s:.2} s"));
    out
}
