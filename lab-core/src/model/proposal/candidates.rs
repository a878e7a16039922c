//! The candidate space of a proposal: a grammar, not a list (issue 39).
//! A real gyro's missing effect is on nobody's list, but it is built from
//! the run's own inputs, so the space is made of them:
//!
//! - **primitives** ([`Prim`]): the rate and |rate| (where the table
//!   turns); each temperature less 20 degC, its filtered first and second
//!   derivatives, and the temperature through a first-order lag whose time
//!   constant is searched (the commonest missing effect of a measured gyro:
//!   its sensor is not where the physics is); the acceleration and its
//!   magnitude (where the run gives it); and time's shapes: hours since
//!   power-on, exp(-t/tau), a step at a time, a sinusoid at a period;
//! - **candidates** ([`Candidate`]): each input primitive, its square and
//!   cube, the product of two, and an input primitive times a shape of
//!   time; the time shapes alone; and the events searched in two
//!   parameters (a settling from a time, a jump that relaxes). No
//!   candidate searches more than two parameters.
//!
//! Each candidate is a formula of the model file's term language
//! (model/term/), so what is proposed is evaluated exactly as written, and
//! a recipe of its primitives, so the search can screen it on window
//! means (screen.rs) at the cost of the windows, not the rows. The space's
//! size sets the threshold a candidate's held-out gain must pass
//! (validation.rs's `threshold`): a larger space buys noise more chances.

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

/// What a primitive is, for its window-level value (screen.rs).
#[derive(Clone, Debug, PartialEq)]
pub enum PrimKind {
    /// A function of the run's columns, its window means taken from the
    /// rows (the lag's at each point of its grid).
    Input,
    /// Hours since power-on.
    Hours,
    /// exp(-t/tau).
    Decay,
    /// step(t - t0).
    Step,
    /// sin and cos at a period: two parts.
    Periodic,
}

/// A primitive: its label, formula (naming its searched parameter, if
/// any), and what it is.
#[derive(Clone, Debug, PartialEq)]
pub struct Prim {
    pub label: String,
    pub text: String,
    pub kind: PrimKind,
    pub searched: Option<Searched>,
    /// A candidate by itself only (in no product, no power): a variant of
    /// another primitive that the products already carry.
    pub alone: bool,
    /// The formula of the primitive that, beside this one with a
    /// coefficient of its own, leads it: its derivative (x + tau x' is x
    /// led by tau), or for a lag the input itself. A sensor that lags the
    /// physics by tau_s sees (1 + s tau_s) x of it, and a lag seen through
    /// it is (1 + s tau_s) / (1 + s tau) = tau_s / tau + (1 - tau_s / tau)
    /// / (1 + s tau): part direct, the rest lagged. Both are linear in
    /// their coefficients, so a lead costs a coefficient, not a search.
    pub lead: Option<String>,
}

impl Prim {
    fn input(label: String, text: String) -> Self {
        Self {
            label,
            text,
            kind: PrimKind::Input,
            searched: None,
            alone: false,
            lead: None,
        }
    }

    fn led_by(self, lead: String) -> Self {
        Self {
            lead: Some(lead),
            ..self
        }
    }

    pub fn is_input(&self) -> bool {
        self.kind == PrimKind::Input
    }
}

/// One factor of a recipe: a primitive to a power.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Factor {
    pub prim: usize,
    pub power: i32,
}

/// What a candidate's second part is to its first (candidates of two
/// recipes, [`paired`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Second {
    /// The first's derivative: k (x + tau x'), the physics ahead of the
    /// sensor by tau = k2 / k.
    Lead,
    /// A lag's input itself: k2 / (k + k2) of the effect direct, the rest
    /// through the lag (a lag tau seen through a sensor's own lag tau_s
    /// has tau_s / tau of it direct).
    Direct,
    /// The first's square: a quadratic.
    Square,
}

/// The longest lead of the physics over its sensor, s: a sensor on the
/// case or the mount, minutes from the element it stands for (a longer
/// one is a lag of the physics itself, which the lag primitive carries).
pub const MAX_LEAD_S: f64 = 900.0;

impl Second {
    /// Whether the two coefficients (the first part's `k_dph`, the
    /// second's `k2_dph`) describe what the pairing stands for: a sensor
    /// behind the physics, not ahead of it (a lead of zero to
    /// [`MAX_LEAD_S`]), or a share of the effect direct between none and
    /// all whose sensor lag (tau times the share) is no longer than a lead.
    /// Outside that the pair is two shapes fitted against each other (a
    /// difference of sensors standing in for another), not a lead.
    pub fn plausible(self, params: &std::collections::BTreeMap<String, f64>) -> bool {
        let (Some(&k), Some(&k2)) = (params.get("k_dph"), params.get("k2_dph")) else {
            return false;
        };
        match self {
            Second::Lead => k != 0.0 && (0.0..=MAX_LEAD_S).contains(&(k2 / k)),
            // The share direct is tau_s / tau: the sensor's own lag
            // tau_s = tau k2 / (k + k2), no longer than a lead.
            Second::Direct => {
                let tau = params.get("tau_s").copied().unwrap_or(f64::NAN);
                k * k2 >= 0.0 && k + k2 != 0.0 && tau * k2 / (k + k2) <= MAX_LEAD_S
            }
            Second::Square => true,
        }
    }
}

/// A candidate term: its parts (summed), the parameters searched (none,
/// one, or two, searched on every pair of their grids), and, for the
/// screening, the primitives it is the product of (empty for the events
/// searched in two parameters, which are screened from their formula).
#[derive(Clone, Debug, PartialEq)]
pub struct Candidate {
    /// What a gyro engineer would call it.
    pub label: String,
    pub parts: Vec<Part>,
    pub searched: Vec<Searched>,
    pub recipe: Vec<Factor>,
    /// The recipes of further linear parts, screened as the first is (a
    /// primitive's lead or square beside it), and what the second is.
    pub also: Vec<Vec<Factor>>,
    pub second: Option<Second>,
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

    /// The searched parameters by name at a point of the search (a value
    /// per searched parameter, in their order).
    pub fn params_at(&self, point: &[f64]) -> std::collections::BTreeMap<String, f64> {
        self.searched
            .iter()
            .zip(point)
            .map(|(s, &v)| (s.name.to_string(), v))
            .collect()
    }

    /// Linear coefficients plus the searched parameters: what the term can
    /// bend (the simplest explanation has the fewest).
    pub fn freedom(&self) -> usize {
        self.parts.len() + self.searched.len()
    }

    /// How composed it is: its factors' powers summed (a primitive 1, a
    /// square or a product 2; of a pair, its more composed part's), the
    /// simpler preferred among equals.
    pub fn order(&self) -> i32 {
        std::iter::once(&self.recipe)
            .chain(&self.also)
            .map(|r| r.iter().map(|f| f.power).sum::<i32>())
            .max()
            .unwrap_or(0)
            .max(1)
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

/// Time constants a temperature's lag is searched over: from two minutes
/// to a quarter of the record, in this many steps.
pub const LAG_TAUS: usize = 8;
pub const LAG_TAU_MIN_S: f64 = 120.0;

/// Onsets of a step or an event: anywhere but the record's first and last
/// 5 % (there a step is a bias or nothing).
const ONSETS: usize = 96;
/// The coarser grids of a shape of time inside a product (the product's
/// search costs the grid's points).
const PRODUCT_ONSETS: usize = 48;
const PRODUCT_PERIODS: usize = 40;
const PRODUCT_DECAYS: usize = 20;

/// Half widths, s, of a temperature's curvature besides the default
/// (`d2dt2(x)`, eval.rs's 120 s), each a candidate by itself. Where the
/// temperature turns fast (a chamber's corner through a coil's lag of a
/// few minutes) the default smooths the curvature the term follows; where
/// a quantised sensor creeps, a narrow one is all noise. The best width
/// is the data's (instruments/d2t_bound: within a few percent of what any
/// linear filter can do). Widths under three rows are left out.
pub const CURVATURE_HALF_WIDTHS_S: [f64; 4] = [15.0, 30.0, 60.0, 240.0];

/// A pulse's width, its second searched parameter (the refinement moves
/// its onset with the end held).
pub const PULSE_WIDTH: &str = "w_s";

/// Widths a pulse is searched over.
const PULSE_WIDTHS: usize = 10;

/// `n` values from `a` to `b`, evenly spaced in log.
fn log_grid(a: f64, b: f64, n: usize) -> Vec<f64> {
    (0..n)
        .map(|k| a * (b / a).powf(k as f64 / (n - 1).max(1) as f64))
        .collect()
}

/// `n` onsets over the record from `t0` over `span`.
fn onsets(t0: f64, span: f64, n: usize) -> Vec<f64> {
    (0..n)
        .map(|k| t0 + span * (0.05 + 0.9 * k as f64 / (n - 1) as f64))
        .collect()
}

/// The primitives of a run's inputs: the input primitives first, then
/// time's shapes (at their grids inside products).
pub fn primitives(inp: &Inputs) -> Vec<Prim> {
    let w = Column::RefRate.name();
    let t = Column::Time.name();
    let mut p = vec![];
    if moves(&inp.w) {
        p.push(Prim::input("rate".into(), w.to_owned()));
        p.push(Prim::input("|rate|".into(), format!("abs({w})")));
    }
    let span = inp.t.last().copied().unwrap_or(0.0) - inp.t.first().copied().unwrap_or(0.0);
    let row_s = crate::numerics::stats::median_interval(&inp.t);
    let mut temps: Vec<(&str, &str, &[f64])> = vec![];
    if let Some(x) = &inp.temp {
        temps.push((Column::Temp.name(), "temperature", x));
    }
    if let Some((a, b)) = &inp.mono {
        temps.push((Column::MonoA.name(), "monoblock A", a));
        temps.push((Column::MonoB.name(), "monoblock B", b));
    }
    if let Some(c) = &inp.case {
        temps.push((Column::Case.name(), "case temperature", c));
    }
    let moving: Vec<(&str, &str)> = temps
        .iter()
        .filter(|(_, _, x)| moves(x))
        .map(|(c, n, _)| (*c, *n))
        .collect();
    // The gradients between sensors: where the heat flows, a gyro's bias
    // follows (the case less the monoblocks' mean, one sensor less
    // another).
    for (k, &(a, na)) in moving.iter().enumerate() {
        for &(b, nb) in &moving[k + 1..] {
            p.push(Prim::input(
                format!("{na} less {nb}"),
                format!("({a} - {b})"),
            ));
            if span / 4.0 > 2.0 * LAG_TAU_MIN_S {
                p.push(Prim {
                    searched: Some(Searched {
                        name: "tau_s",
                        grid: log_grid(LAG_TAU_MIN_S, span / 4.0, LAG_TAUS),
                    }),
                    ..Prim::input(
                        format!("{na} less {nb} through a lag"),
                        format!("lag({a} - {b}, tau_s)"),
                    )
                    .led_by(format!("({a} - {b})"))
                });
            }
        }
    }
    if let (Some(_), Some(_)) = (&inp.mono, &inp.case) {
        let (a, b, c) = (
            Column::MonoA.name(),
            Column::MonoB.name(),
            Column::Case.name(),
        );
        if moving.len() >= 3 {
            p.push(Prim::input(
                "case less the monoblocks' mean".into(),
                format!("({c} - ({a} + {b}) / 2)"),
            ));
        }
    }
    for (col, name, _) in temps.into_iter().filter(|(_, _, x)| moves(x)) {
        p.push(
            Prim::input(format!("{name} less 20 degC"), format!("({col} - 20)"))
                .led_by(format!("ddt({col})")),
        );
        p.push(
            Prim::input(format!("{name}'s rate"), format!("ddt({col})"))
                .led_by(format!("d2dt2({col})")),
        );
        p.push(Prim::input(
            format!("{name}'s curvature"),
            format!("d2dt2({col})"),
        ));
        for h in CURVATURE_HALF_WIDTHS_S
            .into_iter()
            .filter(|&h| h >= 3.0 * row_s)
        {
            p.push(Prim {
                alone: true,
                ..Prim::input(
                    format!("{name}'s curvature over {h:.0} s"),
                    format!("d2dt2({col}, {h:.0})"),
                )
            });
        }
        if span / 4.0 > 2.0 * LAG_TAU_MIN_S {
            p.push(Prim {
                searched: Some(Searched {
                    name: "tau_s",
                    grid: log_grid(LAG_TAU_MIN_S, span / 4.0, LAG_TAUS),
                }),
                ..Prim::input(
                    format!("{name} through a lag"),
                    format!("(lag({col}, tau_s) - 20)"),
                )
                .led_by(format!("({col} - 20)"))
            });
        }
    }
    if !inp.acc_derived && moves(&inp.acc) {
        let a = Column::RefAcc.name();
        p.push(Prim::input("acceleration".into(), a.to_owned()));
        p.push(Prim::input("|acceleration|".into(), format!("abs({a})")));
    }
    if span > 0.0 {
        let t0 = inp.t.first().copied().unwrap_or(0.0);
        p.push(Prim {
            label: "hours since power-on".into(),
            text: format!("{t} / 3600"),
            kind: PrimKind::Hours,
            searched: None,
            alone: false,
            lead: None,
        });
        p.push(Prim {
            label: "a decay".into(),
            text: format!("exp(-{t} / tau_s)"),
            kind: PrimKind::Decay,
            searched: Some(Searched {
                name: "tau_s",
                grid: log_grid(60.0, span, PRODUCT_DECAYS),
            }),
            alone: false,
            lead: None,
        });
        p.push(Prim {
            label: "a step".into(),
            text: format!("step({t} - t0_s)"),
            kind: PrimKind::Step,
            searched: Some(Searched {
                name: "t0_s",
                grid: onsets(t0, span, PRODUCT_ONSETS),
            }),
            alone: false,
            lead: None,
        });
        if span >= 600.0 {
            p.push(Prim {
                label: "a period".into(),
                text: format!("2 * pi * {t} / p_s"),
                kind: PrimKind::Periodic,
                searched: Some(Searched {
                    name: "p_s",
                    grid: log_grid(300.0, span / 2.0, PRODUCT_PERIODS),
                }),
                alone: false,
                lead: None,
            });
        }
    }
    p
}

/// A candidate of one part from a recipe.
fn product(prims: &[Prim], recipe: Vec<Factor>) -> Candidate {
    let mut searched: Vec<Searched> = recipe
        .iter()
        .filter_map(|f| prims[f.prim].searched.clone())
        .collect();
    let periodic = recipe
        .iter()
        .find(|f| prims[f.prim].kind == PrimKind::Periodic)
        .copied();
    let others: Vec<String> = recipe
        .iter()
        .filter(|f| prims[f.prim].kind != PrimKind::Periodic)
        .map(|f| match f.power {
            1 => prims[f.prim].text.clone(),
            k => format!("{}^{k}", prims[f.prim].text),
        })
        .collect();
    let label = recipe
        .iter()
        .map(|f| match f.power {
            1 => prims[f.prim].label.clone(),
            2 => format!("{} squared", prims[f.prim].label),
            _ => format!("{} cubed", prims[f.prim].label),
        })
        .collect::<Vec<_>>()
        .join(" times ");
    let parts = match periodic {
        Some(f) => {
            let arg = &prims[f.prim].text;
            let with = |s: String| {
                if others.is_empty() {
                    s
                } else {
                    format!("{} * {s}", others.join(" * "))
                }
            };
            vec![
                Part {
                    coef: "a_dph",
                    shape: with(format!("sin({arg})")),
                },
                Part {
                    coef: "b_dph",
                    shape: with(format!("cos({arg})")),
                },
            ]
        }
        None => vec![Part {
            coef: "k_dph",
            shape: others.join(" * "),
        }],
    };
    searched.dedup_by(|a, b| a.name == b.name);
    Candidate {
        label,
        parts,
        searched,
        recipe,
        also: vec![],
        second: None,
    }
}

/// `recipe`'s product beside the same product with its last factor
/// replaced by `other`, each with its coefficient: the factor led (its
/// lead primitive) or made a quadratic (its square). Any searched
/// parameter is the two parts' one.
fn paired(prims: &[Prim], recipe: &[Factor], other: Factor, what: Second) -> Candidate {
    let mut first = product(prims, recipe.to_vec());
    let mut second_recipe = recipe.to_vec();
    *second_recipe.last_mut().expect("a factor") = other;
    let second = product(prims, second_recipe);
    let how = match what {
        Second::Lead => "with a lead",
        Second::Direct => "part of it direct",
        Second::Square => "and its square",
    };
    first.label = format!("{}, {how}", first.label);
    first.second = Some(what);
    first.parts.push(Part {
        coef: "k2_dph",
        shape: second.parts[0].shape.clone(),
    });
    for s in second.searched {
        if !first.searched.iter().any(|f| f.name == s.name) {
            first.searched.push(s);
        }
    }
    first.also.push(second.recipe);
    first
}

/// The candidates a run's inputs can carry, with the primitives their
/// recipes name.
pub fn candidates(inp: &Inputs) -> (Vec<Prim>, Vec<Candidate>) {
    let mut prims = primitives(inp);
    let inputs: Vec<usize> = (0..prims.len()).filter(|&i| prims[i].is_input()).collect();
    let shapes: Vec<usize> = (0..prims.len()).filter(|&i| !prims[i].is_input()).collect();
    let f = |prim: usize, power: i32| Factor { prim, power };
    let mut c = vec![];
    for &i in &inputs {
        c.push(product(&prims, vec![f(i, 1)]));
        // |rate|^2 is rate^2.
        if !prims[i].alone && prims[i].label != "|rate|" && prims[i].label != "|acceleration|" {
            c.push(product(&prims, vec![f(i, 2)]));
            c.push(product(&prims, vec![f(i, 3)]));
        }
    }
    let composable: Vec<usize> = inputs
        .iter()
        .copied()
        .filter(|&i| !prims[i].alone)
        .collect();
    for (a, &i) in composable.iter().enumerate() {
        for &j in &composable[a + 1..] {
            // One lag per candidate (its time constant is one parameter).
            if prims[i].searched.is_some() && prims[j].searched.is_some() {
                continue;
            }
            // Products of two of the primitives and their powers, to a
            // degree of three: x y, x^2 y, x y^2.
            for (pi, pj) in [(1, 1), (2, 1), (1, 2)] {
                // |x|^2 is x^2: left to x's own products.
                let even_abs = |k: usize, p: i32| p == 2 && prims[k].text.starts_with("abs(");
                if !even_abs(i, pi) && !even_abs(j, pj) {
                    c.push(product(&prims, vec![f(i, pi), f(j, pj)]));
                }
            }
        }
    }
    // A temperature's primitive beside its lead, or beside its own square,
    // by itself and times the rate (a bias, a scale factor): two
    // coefficients on one primitive, so a lagged temperature's quadratic
    // or a sensor that lags the physics is one candidate, not a term with
    // a library name standing in for its other half.
    let rate = inputs.iter().copied().find(|&i| prims[i].label == "rate");
    for &i in &composable {
        let Some(lead) = prims[i]
            .lead
            .as_ref()
            .and_then(|l| prims.iter().position(|p| p.text == *l))
        else {
            continue;
        };
        let level = !prims[i].text.starts_with("ddt(");
        for by in std::iter::once(None).chain(rate.map(Some)) {
            let base: Vec<Factor> = by.map(|r| f(r, 1)).into_iter().chain([f(i, 1)]).collect();
            let how = if prims[i].searched.is_some() {
                Second::Direct
            } else {
                Second::Lead
            };
            c.push(paired(&prims, &base, f(lead, 1), how));
            if level {
                c.push(paired(&prims, &base, f(i, 2), Second::Square));
            }
        }
    }
    // An input times a shape of time (a lag's and a shape's grids
    // together would be hundreds of points: left out). A coefficient
    // that ages or settles (hours, a decay) may be any input's; one that
    // steps or oscillates, the rate's and the acceleration's (a scale
    // factor that jumps at a mode hop, a table's periodic error): a
    // temperature is itself slow in time, and its product with a step
    // imitates the events of time alone.
    for &i in composable.iter().filter(|&&i| prims[i].searched.is_none()) {
        let fast = prims[i].text.contains(Column::RefRate.name())
            || prims[i].text.contains(Column::RefAcc.name());
        for &s in &shapes {
            let slow_shape = matches!(prims[s].kind, PrimKind::Hours | PrimKind::Decay);
            if slow_shape || fast {
                c.push(product(&prims, vec![f(i, 1), f(s, 1)]));
            }
        }
    }
    // The shapes of time alone, on their full grids.
    let t = Column::Time.name();
    let span = inp.t.last().copied().unwrap_or(0.0) - inp.t.first().copied().unwrap_or(0.0);
    let t0 = inp.t.first().copied().unwrap_or(0.0);
    for &s in &shapes {
        let mut p = prims[s].clone();
        if let Some(g) = p.searched.as_mut() {
            g.grid = match p.kind {
                PrimKind::Decay => log_grid(60.0, span, 40),
                PrimKind::Step => onsets(t0, span, ONSETS),
                PrimKind::Periodic => log_grid(300.0, span / 2.0, 80),
                _ => g.grid.clone(),
            };
        }
        prims.push(p);
        let k = prims.len() - 1;
        let mut cand = product(&prims, vec![f(k, 1)]);
        cand.label = match prims[k].kind {
            PrimKind::Hours => "ageing ramp".into(),
            PrimKind::Decay => "exponential settling".into(),
            PrimKind::Step => "step".into(),
            _ => "periodic disturbance".into(),
        };
        c.push(cand);
    }
    if span > 0.0 {
        let on = onsets(t0, span, ONSETS);
        c.push(Candidate {
            label: "ramp from a time".into(),
            parts: vec![Part {
                coef: "k_dph",
                shape: format!("({t} - t0_s) / 3600 * step({t} - t0_s)"),
            }],
            searched: vec![Searched {
                name: "t0_s",
                grid: on.clone(),
            }],
            recipe: vec![],
            also: vec![],
            second: None,
        });
        // Events searched in two parameters: a bias that settles after an
        // event (a mode hop, a relock, a heater switched: 0 before t1, k (1
        // - exp(-(t - t1)/tau)) after), and a jump that relaxes (k from t0,
        // decaying with tau). The step inside the exponential keeps its
        // argument at or below zero (no overflow before the onset).
        // A pulse: on at t0 for a width (a heater switched on and off, a
        // vehicle's engine run), widths from a minute to half the record.
        c.push(Candidate {
            label: "a pulse".into(),
            parts: vec![Part {
                coef: "k_dph",
                shape: format!("(step({t} - t0_s) - step({t} - t0_s - w_s))"),
            }],
            searched: vec![
                Searched {
                    name: "t0_s",
                    grid: on.clone(),
                },
                Searched {
                    name: PULSE_WIDTH,
                    grid: log_grid(60.0, span / 2.0, PULSE_WIDTHS),
                },
            ],
            recipe: vec![],
            also: vec![],
            second: None,
        });
        if span / 3.0 > 2.0 * SETTLING_TAU_MIN_S {
            let taus = log_grid(SETTLING_TAU_MIN_S, span / 3.0, SETTLING_TAUS);
            for (label, shape, onset) in [
                (
                    "settling from a time",
                    format!("(1 - exp(-({t} - t1_s) * step({t} - t1_s) / tau_s))"),
                    "t1_s",
                ),
                (
                    "a jump that relaxes",
                    format!("step({t} - t0_s) * exp(-({t} - t0_s) * step({t} - t0_s) / tau_s)"),
                    "t0_s",
                ),
            ] {
                c.push(Candidate {
                    label: label.into(),
                    parts: vec![Part {
                        coef: "k_dph",
                        shape,
                    }],
                    searched: vec![
                        Searched {
                            name: onset,
                            grid: on.clone(),
                        },
                        Searched {
                            name: "tau_s",
                            grid: taus.clone(),
                        },
                    ],
                    recipe: vec![],
                    also: vec![],
                    second: None,
                });
            }
        }
    }
    (prims, c)
}

/// The number of candidate columns a run's space holds: every point of
/// every candidate's grid (what the threshold pays for).
pub fn space_size(c: &[Candidate]) -> usize {
    c.iter()
        .map(|c| c.searched.iter().map(|s| s.grid.len()).product::<usize>())
        .sum()
}
