//! The candidate space of a proposal: terms built from the run's own
//! inputs, each written in the model file's term language (model/term/) so
//! the term proposed is evaluated exactly as it was validated.
//!
//! Small on purpose. Every candidate has one or two linear coefficients
//! and at most one searched shape parameter, but one: the settling from a
//! time searches its onset and its time constant, on coarse grids (the
//! onsets the step and the ramp share, ten time constants), and counts as
//! more complex than any one-parameter shape, so it is proposed only
//! where it predicts clearly better. A term cannot fit noise by being
//! flexible, and the validation's threshold (validation.rs) pays for the
//! whole space at once. Physical terms come first (products and powers of
//! the rate, |rate|, the temperatures, their filtered derivatives, the
//! acceleration), then the one-off shapes (a step at a time, a sinusoid at
//! a period, an exponential with a time constant, a ramp, a settling from
//! a time).

use crate::data::run_file::Column;
use crate::model::inputs::Inputs;

/// One linear part of a candidate: its coefficient's name and the formula
/// it multiplies (deg/h per unit of the coefficient).
#[derive(Clone, Debug, PartialEq)]
pub struct Part {
    pub coef: &'static str,
    pub shape: String,
}

/// A shape parameter searched on a grid (its name in the formula).
#[derive(Clone, Debug, PartialEq)]
pub struct Searched {
    pub name: &'static str,
    pub grid: Vec<f64>,
}

/// A candidate term: its parts (summed) and the parameters searched (none,
/// one, or the settling's two, searched on every pair of their grids).
#[derive(Clone, Debug, PartialEq)]
pub struct Candidate {
    /// What a gyro engineer would call it.
    pub label: &'static str,
    pub parts: Vec<Part>,
    pub searched: Vec<Searched>,
}

impl Candidate {
    /// The formula with its coefficients as names.
    pub fn formula(&self) -> String {
        let p: Vec<String> = self
            .parts
            .iter()
            .map(|p| format!("{} * {}", p.coef, p.shape))
            .collect();
        p.join(" + ")
    }

    /// Linear coefficients plus the searched parameters: what the term can
    /// bend (the simplest explanation has the fewest).
    pub fn freedom(&self) -> usize {
        self.parts.len() + self.searched.len()
    }

    /// Every point of the search: one value per searched parameter, in
    /// their order (one empty point when nothing is searched).
    pub fn points(&self) -> Vec<Vec<f64>> {
        self.searched.iter().fold(vec![vec![]], |pts, s| {
            pts.iter()
                .flat_map(|p| {
                    s.grid.iter().map(move |&v| {
                        let mut q = p.clone();
                        q.push(v);
                        q
                    })
                })
                .collect()
        })
    }
}

fn one(label: &'static str, shape: String) -> Candidate {
    Candidate {
        label,
        parts: vec![Part {
            coef: "k_dph",
            shape,
        }],
        searched: vec![],
    }
}

/// Whether a column moves enough to carry a term (not a constant, nor a
/// sensor that only toggles its last digit).
fn moves(x: &[f64]) -> bool {
    let (lo, hi) = x.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |a, &v| {
        (a.0.min(v), a.1.max(v))
    });
    hi - lo > 1e-9 * hi.abs().max(lo.abs()).max(1.0) && x.len() > 2
}

/// Time constants the settling from a time is searched over, from
/// [`SETTLING_TAU_MIN_S`] to a third of the record.
pub const SETTLING_TAUS: usize = 10;

/// The settling's shortest time constant searched, s (a faster settling
/// is a step at the 1 s means' resolution, and the refinement may still
/// shorten it).
pub const SETTLING_TAU_MIN_S: f64 = 120.0;

/// `n` values from `a` to `b`, evenly spaced in log.
fn log_grid(a: f64, b: f64, n: usize) -> Vec<f64> {
    (0..n)
        .map(|k| a * (b / a).powf(k as f64 / (n - 1).max(1) as f64))
        .collect()
}

/// The candidates a run's inputs can carry.
pub fn candidates(inp: &Inputs) -> Vec<Candidate> {
    let w = Column::RefRate.name();
    let t = Column::Time.name();
    let mut c = vec![];
    let turns = moves(&inp.w);
    if turns {
        c.push(one("rate squared", format!("{w}^2")));
        c.push(one("rate cubed", format!("{w}^3")));
        c.push(one("rate times |rate|", format!("{w} * abs({w})")));
        c.push(one("|rate|", format!("abs({w})")));
    }
    if let Some(temp) = &inp.temp {
        if moves(temp) {
            let tc = Column::Temp.name();
            c.push(one(
                "bias quadratic in temperature",
                format!("({tc} - 20)^2"),
            ));
            c.push(one("coil temperature's curvature", format!("d2dt2({tc})")));
            if turns {
                c.push(one(
                    "scale factor quadratic in temperature",
                    format!("{w} * ({tc} - 20)^2"),
                ));
                c.push(one(
                    "scale factor following the temperature's rate",
                    format!("{w} * ddt({tc})"),
                ));
            }
        }
    }
    if let (Some((a, b)), Some(case)) = (&inp.mono, &inp.case) {
        if moves(a) && moves(b) && moves(case) {
            let (ma, mb, cc) = (
                Column::MonoA.name(),
                Column::MonoB.name(),
                Column::Case.name(),
            );
            c.push(one(
                "case less the monoblocks' mean",
                format!("({cc} - ({ma} + {mb}) / 2)"),
            ));
            c.push(one("case temperature's rate", format!("ddt({cc})")));
        }
    }
    if !inp.acc_derived && moves(&inp.acc) {
        c.push(one(
            "|angular acceleration|",
            format!("abs({})", Column::RefAcc.name()),
        ));
    }
    let t0 = inp.t.first().copied().unwrap_or(0.0);
    let t1 = inp.t.last().copied().unwrap_or(0.0);
    let span = t1 - t0;
    if span > 0.0 {
        // Time is since power-on, so a ramp or a settling written on one
        // run reads the same on the next.
        c.push(one("ageing ramp", format!("{t} / 3600")));
        // Steps, and ramps that start at a time (an ageing that sets in, a
        // drift after an event): anywhere but the record's first and last
        // 5 % (there a step is a bias or nothing), on one grid of onsets.
        let n = 96;
        let onsets: Vec<f64> = (0..n)
            .map(|k| t0 + span * (0.05 + 0.9 * k as f64 / (n - 1) as f64))
            .collect();
        for (label, shape) in [
            ("step", format!("step({t} - t0_s)")),
            (
                "ramp from a time",
                format!("({t} - t0_s) / 3600 * step({t} - t0_s)"),
            ),
        ] {
            c.push(Candidate {
                label,
                parts: vec![Part {
                    coef: "k_dph",
                    shape,
                }],
                searched: vec![Searched {
                    name: "t0_s",
                    grid: onsets.clone(),
                }],
            });
        }
        // Sinusoids: two or more periods in the record, down to 5 min.
        if span >= 600.0 {
            c.push(Candidate {
                label: "periodic disturbance",
                parts: vec![
                    Part {
                        coef: "a_dph",
                        shape: format!("sin(2 * pi * {t} / p_s)"),
                    },
                    Part {
                        coef: "b_dph",
                        shape: format!("cos(2 * pi * {t} / p_s)"),
                    },
                ],
                searched: vec![Searched {
                    name: "p_s",
                    grid: log_grid(300.0, span / 2.0, 80),
                }],
            });
        }
        c.push(Candidate {
            label: "exponential settling",
            parts: vec![Part {
                coef: "k_dph",
                shape: format!("exp(-{t} / tau_s)"),
            }],
            searched: vec![Searched {
                name: "tau_s",
                grid: log_grid(60.0, span, 40),
            }],
        });
        // A settling from a time (a bias that settles after an event: a
        // mode hop, a relock, a heater switched), first order: 0 before
        // t1, k (1 - exp(-(t - t1) / tau)) after. The step and the ramp
        // from a time are its limits (tau -> 0, tau -> infinity). The
        // step inside the exponential keeps its argument at or below zero
        // (no overflow before t1). Onsets on the steps' grid, time
        // constants from 2 min to a third of the record: 96 x 10 points,
        // each judged as every candidate is (refined afterwards, both
        // parameters jointly, by refit.rs).
        if span / 3.0 > 2.0 * SETTLING_TAU_MIN_S {
            c.push(Candidate {
                label: "settling from a time",
                parts: vec![Part {
                    coef: "k_dph",
                    shape: format!("(1 - exp(-({t} - t1_s) * step({t} - t1_s) / tau_s))"),
                }],
                searched: vec![
                    Searched {
                        name: "t1_s",
                        grid: onsets.clone(),
                    },
                    Searched {
                        name: "tau_s",
                        grid: log_grid(SETTLING_TAU_MIN_S, span / 3.0, SETTLING_TAUS),
                    },
                ],
            });
        }
    }
    c
}
