//! `gyro-lab bench allan`: recovery of known noise terms from the project's
//! own generators (`gyro_sim::noise`) over seeds, each term alone and
//! in combinations; `gyro-lab bench allan-speed`: the time for 10^7
//! samples against the O(N m) definition on 10^5 (the CSV read of the
//! record is the command's).

use crate::noise::adev;
use crate::noise::analysis::{analyse, AllanError, PER_DECADE};
use crate::noise::terms::{self, COUNT};
use crate::sim::noise_run::record;

/// A record of known terms: (Q arcsec, N deg/sqrt(h), B deg/h, K
/// deg/h/sqrt(h), R deg/h^2), zero where absent.
#[derive(Clone, Copy, Debug)]
pub struct Scenario {
    pub name: &'static str,
    pub truth: [f64; COUNT],
}

/// 1 s samples, 2e5 of them (55 h): each term of a scenario dominates the
/// curve over at least a decade and a half of averaging time (a term seen
/// over less is honestly often reported absent).
pub const TAU0_S: f64 = 1.0;
pub const SAMPLES: usize = 200_000;

pub const SCENARIOS: [Scenario; 9] = [
    Scenario {
        name: "white",
        truth: [0.0, 0.05, 0.0, 0.0, 0.0],
    },
    Scenario {
        name: "flicker",
        truth: [0.0, 0.0, 0.1, 0.0, 0.0],
    },
    Scenario {
        name: "random walk",
        truth: [0.0, 0.0, 0.0, 0.5, 0.0],
    },
    Scenario {
        name: "quantization + white",
        truth: [20.0, 0.1, 0.0, 0.0, 0.0],
    },
    Scenario {
        name: "white + ramp",
        truth: [0.0, 0.05, 0.0, 0.0, 0.5],
    },
    Scenario {
        name: "white + flicker",
        truth: [0.0, 0.02, 0.1, 0.0, 0.0],
    },
    Scenario {
        name: "white + random walk",
        truth: [0.0, 0.05, 0.0, 0.5, 0.0],
    },
    Scenario {
        name: "white + flicker + random walk",
        truth: [0.0, 0.006, 0.1, 0.2, 0.0],
    },
    Scenario {
        name: "quantization + white + flicker",
        truth: [20.0, 0.1, 0.5, 0.0, 0.0],
    },
];

#[derive(serde::Serialize, Default, Clone)]
pub struct Row {
    pub scenario: &'static str,
    /// Per term: seeds where it was reported and its interval held the
    /// truth (present terms), or where it was reported (absent terms).
    pub recovered: [Option<u64>; COUNT],
    pub false_reports: [Option<u64>; COUNT],
    /// Mean of the reported value over the seeds that reported it.
    pub mean_value: [Option<f64>; COUNT],
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

/// Every scenario over seeds 1..=`seeds`; `progress` after each record.
pub fn recovery(seeds: u64, mut progress: impl FnMut()) -> Result<Recovery, AllanError> {
    let mut rows = vec![];
    for sc in SCENARIOS {
        let mut row = Row {
            scenario: sc.name,
            ..Row::default()
        };
        let mut sums = [0.0; COUNT];
        for j in 0..COUNT {
            if sc.truth[j] > 0.0 {
                row.recovered[j] = Some(0);
            } else {
                row.false_reports[j] = Some(0);
            }
        }
        for seed in 1..=seeds {
            let y = record(&sc.truth, SAMPLES, TAU0_S, seed);
            let an = analyse(&y, TAU0_S)?;
            for j in 0..COUNT {
                let t = &an.terms;
                if !t.present[j] {
                    continue;
                }
                let (v, lo, hi) = (
                    terms::to_units(j, t.c[j]),
                    terms::to_units(j, t.lo[j]),
                    terms::to_units(j, t.hi[j]),
                );
                if sc.truth[j] > 0.0 {
                    sums[j] += v;
                    if lo <= sc.truth[j] && sc.truth[j] <= hi {
                        row.recovered[j] = row.recovered[j].map(|c| c + 1);
                    }
                } else {
                    row.false_reports[j] = row.false_reports[j].map(|c| c + 1);
                }
            }
            progress();
        }
        for j in 0..COUNT {
            if sc.truth[j] > 0.0 {
                row.mean_value[j] = Some(sums[j] / seeds as f64);
            }
        }
        rows.push(row);
    }
    let n = seeds;
    let (mut rec, mut rec_n, mut fp, mut fp_n) = (0, 0, 0, 0);
    for r in &rows {
        for j in 0..COUNT {
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

/// The long record of the speed bench: white, flicker and random walk at
/// 100 Hz.
pub const SPEED_TAU0_S: f64 = 0.01;

pub fn speed_record(n: usize) -> Vec<f64> {
    let truth = [0.0, 0.1, 0.05, 0.02, 0.0];
    record(&truth, n, SPEED_TAU0_S, 1)
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
