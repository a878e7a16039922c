//! `gyro-lab bench allan`: recovery of known noise terms from the project's
//! own generators (`gyro_sim::noise`, with the sinusoid and the Markov term
//! of sim/noise_run.rs) over seeds, each term alone and in combinations; `gyro-lab bench allan-speed`: the time for 10^7
//! samples against the O(N m) definition on 10^5 (the CSV read of the
//! record is the command's).

use crate::noise::adev;
use crate::noise::analysis::{analyse, Allan, AllanError, PER_DECADE};
use crate::noise::model::Interval;
use crate::noise::terms::{self, ALL, COUNT, MARKOV, SIN};
use crate::sim::noise_run::{record, record_with, Truth};

/// A record of known terms: the power laws (Q arcsec, N deg/sqrt(h), B
/// deg/h, K deg/h/sqrt(h), R deg/h^2; zero where absent), a sinusoid
/// (amplitude deg/h, Hz) and a Markov term (sigma deg/h, correlation time
/// s).
#[derive(Clone, Copy, Debug)]
pub struct Scenario {
    pub name: &'static str,
    pub truth: Truth,
}

/// 1 s samples, 2e5 of them (55 h): each term of a scenario dominates the
/// curve over at least a decade and a half of averaging time (a term seen
/// over less is honestly often reported absent).
pub const TAU0_S: f64 = 1.0;
pub const SAMPLES: usize = 200_000;

const fn laws(name: &'static str, laws: [f64; COUNT]) -> Scenario {
    Scenario {
        name,
        truth: Truth::laws(laws),
    }
}

pub const SCENARIOS: [Scenario; 13] = [
    laws("white", [0.0, 0.05, 0.0, 0.0, 0.0]),
    laws("flicker", [0.0, 0.0, 0.1, 0.0, 0.0]),
    laws("random walk", [0.0, 0.0, 0.0, 0.5, 0.0]),
    laws("quantization + white", [20.0, 0.1, 0.0, 0.0, 0.0]),
    laws("white + ramp", [0.0, 0.05, 0.0, 0.0, 0.5]),
    laws("white + flicker", [0.0, 0.02, 0.1, 0.0, 0.0]),
    laws("white + random walk", [0.0, 0.05, 0.0, 0.5, 0.0]),
    laws("white + flicker + random walk", [0.0, 0.006, 0.1, 0.2, 0.0]),
    laws("quantization + white + flicker", [20.0, 0.1, 0.5, 0.0, 0.0]),
    // A bump at 0.37/f = 37 s, 4.5 times the white noise there.
    Scenario {
        name: "white + sinusoid",
        truth: Truth {
            laws: [0.0, 0.05, 0.0, 0.0, 0.0],
            sinusoid: Some((3.0, 0.01)),
            markov: None,
        },
    },
    // The Markov term's hump near 1.9 T = 570 s, 6 times the white noise.
    Scenario {
        name: "white + Markov",
        truth: Truth {
            laws: [0.0, 0.02, 0.0, 0.0, 0.0],
            sinusoid: None,
            markov: Some((0.5, 300.0)),
        },
    },
    // An RLG's curve: a dither bump on quantization, then white noise.
    Scenario {
        name: "quantization + white + sinusoid",
        truth: Truth {
            laws: [20.0, 0.02, 0.0, 0.0, 0.0],
            sinusoid: Some((20.0, 0.1)),
            markov: None,
        },
    },
    // The hump near 38 s, its white tail to 2000 s, then the floor.
    Scenario {
        name: "white + Markov + flicker",
        truth: Truth {
            laws: [0.0, 0.01, 0.1, 0.0, 0.0],
            sinusoid: None,
            markov: Some((0.5, 20.0)),
        },
    },
];

/// Short names of the terms for the table's columns: the power laws, the
/// sinusoid, the Markov term.
pub const SHORT: [&str; ALL] = ["Q", "N", "B", "K", "R", "S", "M"];

/// Whether each term of `truth` is present (index as the shapes).
pub fn truth_present(t: &Truth) -> [bool; ALL] {
    let mut p = [false; ALL];
    for j in 0..COUNT {
        p[j] = t.laws[j] > 0.0;
    }
    p[SIN] = t.sinusoid.is_some();
    p[MARKOV] = t.markov.is_some();
    p
}

fn holds(i: &Interval, v: f64) -> bool {
    i.lo <= v && v <= i.hi
}

/// Per term of an analysis: reported, and (where the truth has it) every
/// interval of it holding the truth; the value compared (the power law,
/// the sinusoid's amplitude deg/h, the Markov sigma deg/h).
pub fn judge(an: &Allan, t: &Truth) -> [(bool, bool, f64); ALL] {
    let mut out = [(false, false, 0.0); ALL];
    let tf = &an.terms;
    for j in 0..COUNT {
        if tf.present[j] {
            let (v, lo, hi) = (
                terms::to_units(j, tf.c[j]),
                terms::to_units(j, tf.lo[j]),
                terms::to_units(j, tf.hi[j]),
            );
            out[j] = (true, lo <= t.laws[j] && t.laws[j] <= hi, v);
        }
    }
    if let Some(s) = &tf.sinusoid {
        let held = t
            .sinusoid
            .is_some_and(|(a, f)| holds(&s.amplitude_dps, a / 3600.0) && holds(&s.frequency_hz, f));
        out[SIN] = (true, held, s.amplitude_dps.value * 3600.0);
    }
    if let Some(m) = &tf.correlated {
        let held = t
            .markov
            .is_some_and(|(sg, tc)| holds(&m.sigma_dph, sg) && holds(&m.tau_s, tc));
        out[MARKOV] = (true, held, m.sigma_dph.value);
    }
    out
}

#[derive(serde::Serialize, Default, Clone)]
pub struct Row {
    pub scenario: &'static str,
    /// Per term (Q, N, B, K, R, sinusoid, Markov): seeds where it was
    /// reported and every interval of it held the truth (present terms),
    /// or where it was reported (absent terms).
    pub recovered: [Option<u64>; ALL],
    pub false_reports: [Option<u64>; ALL],
    /// Mean of the reported value over the seeds that reported it.
    pub mean_value: [Option<f64>; ALL],
    /// Seeds whose fit was consistent with the curve.
    pub consistent: u64,
    /// Seeds where the white noise was reported filtered (the generators'
    /// is not).
    pub filter_reports: u64,
}

/// The recovery table and its totals: present terms held by their
/// interval, absent terms reported.
pub struct Recovery {
    pub rows: Vec<Row>,
    pub recovered: u64,
    pub recovered_of: u64,
    pub false_reports: u64,
    pub false_reports_of: u64,
}

/// Which records the bench runs: seeds `first_seed..first_seed + seeds`
/// of the scenarios whose name contains `only` (all when empty).
#[derive(Clone, Debug)]
pub struct Selection {
    pub first_seed: u64,
    pub seeds: u64,
    pub only: String,
}

/// Every selected scenario over the selected seeds; `each` after each
/// record, with its scenario, seed and analysis.
pub fn recovery(
    sel: &Selection,
    mut each: impl FnMut(&Scenario, u64, &Allan),
) -> Result<Recovery, AllanError> {
    let mut rows = vec![];
    let seeds = sel.seeds;
    for sc in SCENARIOS
        .iter()
        .filter(|s| s.name.contains(sel.only.as_str()))
    {
        let mut row = Row {
            scenario: sc.name,
            ..Row::default()
        };
        let present = truth_present(&sc.truth);
        let mut sums = [0.0; ALL];
        let mut counts = [0u64; ALL];
        for j in 0..ALL {
            if present[j] {
                row.recovered[j] = Some(0);
            } else {
                row.false_reports[j] = Some(0);
            }
        }
        for seed in sel.first_seed..sel.first_seed + seeds {
            let y = if sc.truth.sinusoid.is_none() && sc.truth.markov.is_none() {
                record(&sc.truth.laws, SAMPLES, TAU0_S, seed)
            } else {
                record_with(&sc.truth, SAMPLES, TAU0_S, seed)
            };
            let an = analyse(&y, TAU0_S)?;
            row.consistent += u64::from(an.terms.goodness.consistent);
            row.filter_reports += u64::from(an.terms.arw_filter_s.is_some());
            for (j, &(reported, held, v)) in judge(&an, &sc.truth).iter().enumerate() {
                if !reported {
                    continue;
                }
                if present[j] {
                    sums[j] += v;
                    counts[j] += 1;
                    if held {
                        row.recovered[j] = row.recovered[j].map(|c| c + 1);
                    }
                } else {
                    row.false_reports[j] = row.false_reports[j].map(|c| c + 1);
                }
            }
            each(sc, seed, &an);
        }
        for j in 0..ALL {
            if present[j] && counts[j] > 0 {
                row.mean_value[j] = Some(sums[j] / counts[j] as f64);
            }
        }
        rows.push(row);
    }
    let n = seeds;
    let (mut rec, mut rec_n, mut fp, mut fp_n) = (0, 0, 0, 0);
    for r in &rows {
        for j in 0..ALL {
            if let Some(c) = r.recovered[j] {
                rec += c;
                rec_n += n;
            }
            if let Some(c) = r.false_reports[j] {
                fp += c;
                fp_n += n;
            }
        }
    }
    Ok(Recovery {
        rows,
        recovered: rec,
        recovered_of: rec_n,
        false_reports: fp,
        false_reports_of: fp_n,
    })
}

/// The long record of the speed bench: white, flicker, random walk, a
/// sinusoid and a Markov term at 100 Hz.
pub const SPEED_TAU0_S: f64 = 0.01;

pub fn speed_record(n: usize) -> Vec<f64> {
    let truth = Truth {
        laws: [0.0, 0.1, 0.05, 0.02, 0.0],
        sinusoid: Some((2.0, 0.5)),
        markov: Some((0.3, 20.0)),
    };
    record_with(&truth, n, SPEED_TAU0_S, 1)
}

/// The O(N m) definition against the fast estimator on the first 10^5
/// samples, at the averaging factors the fast one uses there.
pub struct AgainstDefinition {
    pub reference_s: f64,
    pub fast_s: f64,
    /// Largest relative difference of the two.
    pub max_rel_diff: f64,
}

pub fn against_definition(y: &[f64]) -> AgainstDefinition {
    let small = &y[..100_000.min(y.len())];
    let ms = adev::averaging_factors(small.len(), PER_DECADE);
    let t2 = std::time::Instant::now();
    let reference = adev::oavar_reference(small, &ms);
    let reference_s = t2.elapsed().as_secs_f64();
    let t3 = std::time::Instant::now();
    let fast = adev::oavar(small, &ms);
    let fast_s = t3.elapsed().as_secs_f64();
    let max_rel_diff = reference
        .iter()
        .zip(&fast)
        .map(|(r, f)| (r - f).abs() / r)
        .fold(0.0, f64::max);
    AgainstDefinition {
        reference_s,
        fast_s,
        max_rel_diff,
    }
}
