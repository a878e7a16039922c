//! What no effect of the library explains, said plainly: the part of the
//! residual that the shapes, steps and implausible fits carry, the spikes,
//! and the stretches where the whitened residual of the final fit still
//! stands out of its noise (blocks of [`BLOCK_WINDOWS`] whose sum of
//! standardised innovations is beyond [`BLOCK_SIGMAS`] sigmas, or whose sum
//! of squares is beyond chi-square's quantile at the same tail: a burst
//! that swings both ways, a vehicle rocking, sums to nothing but not its
//! squares); with its size, where it sits, and the inputs it follows most.

use super::design::Design;
use super::noise_model::NoiseModel;
use super::select::corr;
use crate::data::run_file::Column;
use crate::model::inputs::{centered_slope, Inputs, RATE_HALF_WIDTH_S};

/// Block of the residual test and of the spans' smoothing, windows.
pub const BLOCK_WINDOWS: usize = 60;
/// A block stands out beyond this many sigmas (one in 3.5 million for
/// white innovations: no false alarm over the longest records).
pub const BLOCK_SIGMAS: f64 = 5.0;

/// A stretch where the residual holds what the library does not explain.
#[derive(Clone, Debug, serde::Serialize)]
pub struct Span {
    pub from_s: f64,
    pub to_s: f64,
    /// Largest residual after the model there (60 s means; a spike's own
    /// window), deg/h.
    pub peak_dph: f64,
}

/// An input and its correlation with what is unexplained.
#[derive(Clone, Debug, serde::Serialize)]
pub struct Correlate {
    pub input: String,
    pub correlation: f64,
}

#[derive(Clone, Debug, serde::Serialize)]
pub struct Unexplained {
    /// RMS of the unexplained part over the record (1 s means), deg/h.
    pub excess_dph: f64,
    pub spans: Vec<Span>,
    pub correlates: Vec<Correlate>,
    /// What carries it in the fit (shapes, steps, implausible fits), and
    /// spikes left out of the fit.
    pub carried_by: Vec<String>,
    pub spikes: usize,
    /// Set where a function of the inputs predicts it (trend.rs): the
    /// function, in the term language.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub input_function: Option<String>,
}

impl Unexplained {
    /// What carries it, said: the shapes and spikes, or, where none is
    /// named (the excess stands in its spans alone), that.
    pub fn carried_text(&self) -> String {
        if self.carried_by.is_empty() {
            "no shape the fit names (see its spans)".into()
        } else {
            self.carried_by.join("; ")
        }
    }
}

/// The unexplained part, one value per window, from its sources.
pub struct Sources<'a> {
    /// The nuisance terms' parts (window means, deg/s) and their names.
    pub parts: Vec<(&'a [f64], String)>,
    /// Spike windows (inclusive ranges).
    pub spikes: &'a [(usize, usize)],
    /// The whitened residual of the final fit and its variance scale.
    pub whitened: &'a [f64],
    pub scale: f64,
    /// The residual after the model written (window means, deg/s).
    pub after: &'a [f64],
}

/// The inputs a residual may follow, by name, as window means.
fn inputs(d: &Design) -> Vec<(String, Vec<f64>)> {
    let inp: &Inputs = d.inp;
    let w = Column::RefRate.name();
    let mut v = vec![
        (Column::Time.name().to_owned(), d.win.t.clone()),
        (w.to_owned(), d.win.mean(&inp.w)),
        (
            format!("{w}^2"),
            d.win.mean(&inp.w.iter().map(|x| x * x).collect::<Vec<_>>()),
        ),
        (
            format!("|{w}|"),
            d.win
                .mean(&inp.w.iter().map(|x| x.abs()).collect::<Vec<_>>()),
        ),
        (
            format!("{}^2", Column::RefAcc.name()),
            d.win
                .mean(&inp.acc.iter().map(|x| x * x).collect::<Vec<_>>()),
        ),
    ];
    if let (Some(temp), Some(rate)) = (&inp.temp, &inp.temp_rate) {
        let c = Column::Temp.name();
        v.push((c.to_owned(), d.win.mean(temp)));
        v.push((format!("d({c})/dt"), d.win.mean(rate)));
    }
    if let Some(case) = &inp.case {
        let c = Column::Case.name();
        v.push((c.to_owned(), d.win.mean(case)));
        let r = centered_slope(&inp.t, case, RATE_HALF_WIDTH_S);
        v.push((format!("d({c})/dt"), d.win.mean(&r)));
    }
    if let Some(dt) = &inp.dt {
        v.push((
            format!("{} - {}", Column::MonoA.name(), Column::MonoB.name()),
            d.win.mean(dt),
        ));
    }
    v
}

/// Centred correlation.
fn pearson(a: &[f64], b: &[f64]) -> f64 {
    let n = a.len().min(b.len()) as f64;
    if n < 3.0 {
        return 0.0;
    }
    let ma = a.iter().sum::<f64>() / n;
    let mb = b.iter().sum::<f64>() / n;
    let ca: Vec<f64> = a.iter().map(|x| x - ma).collect();
    let cb: Vec<f64> = b.iter().map(|x| x - mb).collect();
    corr(&ca, &cb)
}

/// Block means of `x` over [`BLOCK_WINDOWS`] windows: (first, last window,
/// mean).
fn blocks(x: &[f64]) -> Vec<(usize, usize, f64)> {
    let l = BLOCK_WINDOWS;
    (0..x.len().div_ceil(l))
        .map(|b| {
            let (a, e) = (b * l, ((b + 1) * l).min(x.len()));
            (a, e - 1, x[a..e].iter().sum::<f64>() / (e - a) as f64)
        })
        .collect()
}

/// What is unexplained in the final fit, or None when the library explains
/// the data to its noise.
pub fn assess(d: &Design, noise: &NoiseModel, src: &Sources) -> Option<Unexplained> {
    let n = d.win.len();
    let mut u = vec![0.0; n];
    for (p, _) in &src.parts {
        for (a, b) in u.iter_mut().zip(p.iter()) {
            *a += b;
        }
    }
    for &(a, b) in src.spikes {
        u[a..=b].copy_from_slice(&src.after[a..=b]);
    }
    // Blocks where the whitened residual still stands out.
    let sd = (BLOCK_WINDOWS as f64 * src.scale.max(1e-300)).sqrt();
    let flagged: Vec<(usize, usize)> = src
        .whitened
        .chunks(BLOCK_WINDOWS)
        .enumerate()
        .filter(|(_, c)| (c.iter().sum::<f64>() / sd).abs() > BLOCK_SIGMAS)
        .map(|(b, c)| (b * BLOCK_WINDOWS, b * BLOCK_WINDOWS + c.len() - 1))
        .collect();
    // Blocks whose innovations' energy stands out: a burst that swings
    // both ways. The residual itself is what is unexplained there.
    // The two-sided tail of the sum's test: P(|Z| > BLOCK_SIGMAS).
    let tail = statrs::function::erf::erfc(BLOCK_SIGMAS / std::f64::consts::SQRT_2);
    let loud: Vec<(usize, usize)> = src
        .whitened
        .chunks(BLOCK_WINDOWS)
        .enumerate()
        .filter(|(b, c)| {
            let k = c.len() as f64;
            let used = d.wh.keep[b * BLOCK_WINDOWS..b * BLOCK_WINDOWS + c.len()]
                .iter()
                .filter(|x| **x)
                .count() as f64;
            let ss = c.iter().map(|v| v * v).sum::<f64>() / src.scale.max(1e-300);
            used >= 0.5 * k && ss > crate::numerics::stats::chi2_quantile(1.0 - tail, used)
        })
        .map(|(b, c)| (b * BLOCK_WINDOWS, b * BLOCK_WINDOWS + c.len() - 1))
        .filter(|x| !flagged.contains(x))
        .collect();
    for &(a, b) in &loud {
        for k in a..=b {
            if u[k] == 0.0 {
                u[k] = src.after[k];
            }
        }
    }
    let after_blocks = blocks(src.after);
    for &(a, b) in &flagged {
        let m = after_blocks[a / BLOCK_WINDOWS].2;
        for v in u.iter_mut().take(b + 1).skip(a) {
            if *v == 0.0 {
                *v = m;
            }
        }
    }
    if src.parts.is_empty() && src.spikes.is_empty() && flagged.is_empty() && loud.is_empty() {
        return None;
    }
    let excess = (u.iter().map(|v| v * v).sum::<f64>() / n.max(1) as f64).sqrt() * 3600.0;
    // Spans: the spikes, and the blocks where the smoothed unexplained part
    // stands above the noise of a block mean (or half its own largest).
    let ub = blocks(&u);
    let top = ub.iter().fold(0.0f64, |a, b| a.max(b.2.abs()));
    let sd60 = noise.sd_of_mean(BLOCK_WINDOWS as f64, 1.0);
    let th = (3.0 * sd60).min(0.5 * top);
    let mut spans: Vec<Span> = vec![];
    let t = &d.win.t;
    let half = 0.5 * (t.get(1).copied().unwrap_or(1.0) - t[0]).max(0.0);
    for &(a, b, m) in &ub {
        if m.abs() <= th || top == 0.0 {
            continue;
        }
        let peak = after_blocks[a / BLOCK_WINDOWS].2 * 3600.0;
        match spans.last_mut() {
            Some(s) if t[a] - half <= s.to_s + 2.0 * BLOCK_WINDOWS as f64 => {
                s.to_s = t[b] + half;
                if peak.abs() > s.peak_dph.abs() {
                    s.peak_dph = peak;
                }
            }
            _ => spans.push(Span {
                from_s: t[a] - half,
                to_s: t[b] + half,
                peak_dph: peak,
            }),
        }
    }
    for &(a, b) in src.spikes.iter().chain(&loud) {
        let peak =
            (a..=b)
                .map(|k| src.after[k])
                .fold(0.0f64, |m, v| if v.abs() > m.abs() { v } else { m });
        spans.push(Span {
            from_s: t[a] - half,
            to_s: t[b] + half,
            peak_dph: peak * 3600.0,
        });
    }
    spans.sort_by(|a, b| a.from_s.total_cmp(&b.from_s));
    // Neighbouring or overlapping spans as one.
    let mut merged: Vec<Span> = vec![];
    for sp in spans {
        match merged.last_mut() {
            Some(m) if sp.from_s <= m.to_s + 2.0 * half => {
                m.to_s = m.to_s.max(sp.to_s);
                if sp.peak_dph.abs() > m.peak_dph.abs() {
                    m.peak_dph = sp.peak_dph;
                }
            }
            _ => merged.push(sp),
        }
    }
    let spans = merged;
    let mut correlates: Vec<Correlate> = inputs(d)
        .into_iter()
        .map(|(name, x)| Correlate {
            correlation: pearson(&u, &x),
            input: name,
        })
        .filter(|c| c.correlation.is_finite())
        .collect();
    correlates.sort_by(|a, b| b.correlation.abs().total_cmp(&a.correlation.abs()));
    let mut carried_by: Vec<String> = src.parts.iter().map(|p| p.1.clone()).collect();
    if !loud.is_empty() {
        carried_by.push(format!(
            "{} stretch(es) of {BLOCK_WINDOWS} s where the residual swings beyond its noise",
            loud.len()
        ));
    }
    if !flagged.is_empty() {
        carried_by.push(format!(
            "{} stretch(es) of {BLOCK_WINDOWS} s where the residual stands out of its noise",
            flagged.len()
        ));
    }
    Some(Unexplained {
        excess_dph: excess,
        spans,
        correlates,
        carried_by,
        spikes: src.spikes.len(),
        input_function: None,
    })
}

/// What is unexplained when the gap after the model stands above what
/// the noise can leave (noise_floor.rs's `expected_gap`, with the slow
/// levels at most a gyro of its grade has) by more than that level's own
/// uncertainty, though no term of the fit carries it: the residual after
/// the model (`after`, window means, deg/s) is the unexplained part, the
/// spans are the minutes whose means stand three of `noise`'s sigmas out,
/// and `why` says what gave it away.
pub fn beyond_floor(
    d: &Design,
    noise: &NoiseModel,
    after: &[f64],
    excess_dph: f64,
    why: String,
) -> Unexplained {
    let t = &d.win.t;
    let half =
        0.5 * (t.get(1).copied().unwrap_or(1.0) - t.first().copied().unwrap_or(0.0)).max(0.0);
    let sd60 = noise.sd_of_mean(BLOCK_WINDOWS as f64, 1.0);
    let mut spans: Vec<Span> = vec![];
    for (a, b, m) in blocks(after) {
        if m.abs() <= 3.0 * sd60 {
            continue;
        }
        match spans.last_mut() {
            Some(s) if t[a] - half <= s.to_s + 2.0 * BLOCK_WINDOWS as f64 => {
                s.to_s = t[b] + half;
                if m.abs() * 3600.0 > s.peak_dph.abs() {
                    s.peak_dph = m * 3600.0;
                }
            }
            _ => spans.push(Span {
                from_s: t[a] - half,
                to_s: t[b] + half,
                peak_dph: m * 3600.0,
            }),
        }
    }
    let mut correlates: Vec<Correlate> = inputs(d)
        .into_iter()
        .map(|(name, x)| Correlate {
            correlation: pearson(after, &x),
            input: name,
        })
        .filter(|c| c.correlation.is_finite())
        .collect();
    correlates.sort_by(|a, b| b.correlation.abs().total_cmp(&a.correlation.abs()));
    Unexplained {
        excess_dph,
        spans,
        correlates,
        carried_by: vec![why],
        spikes: 0,
        input_function: None,
    }
}
