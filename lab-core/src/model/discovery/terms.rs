//! What a discovery fit is made of: the constant every fit carries, the
//! library's effects (effects.rs), and shapes the library has no name
//! for. A shape is a rival, never a name: when the residual is better
//! explained by the rate squared, the rate cubed, w|w|, a scale factor
//! following the temperature's square or its rate, a ramp in time, the
//! temperature squared, a temperature's curvature, the case less the
//! monoblocks, |acceleration|, a step or a periodic disturbance than by
//! any effect, it is taken as what no effect of the library explains, so
//! that no effect is bent to imitate it (docs/discovery.md). The shapes
//! are the physical forms issue 32 names outside the library.

use crate::data::run_file::Column;
use crate::model::effects::Effect;
use crate::model::inputs::{centered_slope, Inputs, RATE_HALF_WIDTH_S};

/// A rate the run must reach to show a rate-dependent term, deg/s (the
/// Earth rate is 0.004 deg/s).
pub const ROTATING_DPS: f64 = 0.5;
/// Half width of the slopes that make a temperature's curvature, s: a
/// second difference of a sensor read in hundredths of a degree is noise
/// over the temperature's own slope's 30 s; a thermal lag's curvature
/// lives over minutes.
pub const CURVATURE_HALF_WIDTH_S: f64 = 120.0;

/// A shape of the inputs no effect of the library has.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Shape {
    RateSquared,
    RateCubed,
    RateAbsRate,
    RateTempSquared,
    RateTempRate,
    Ramp,
    TimeSquared,
    TempSquared,
    TempCurvature,
    CaseSquared,
    CaseRate,
    CaseCurvature,
    CaseMinusMono,
    AbsAcc,
}

impl Shape {
    pub const ALL: [Shape; 14] = [
        Shape::RateSquared,
        Shape::RateCubed,
        Shape::RateAbsRate,
        Shape::RateTempSquared,
        Shape::RateTempRate,
        Shape::Ramp,
        Shape::TimeSquared,
        Shape::TempSquared,
        Shape::TempCurvature,
        Shape::CaseSquared,
        Shape::CaseRate,
        Shape::CaseCurvature,
        Shape::CaseMinusMono,
        Shape::AbsAcc,
    ];

    /// What the shape follows, in the run's terms.
    pub fn describe(self) -> String {
        let t = Column::Temp.name();
        let c = Column::Case.name();
        let w = Column::RefRate.name();
        match self {
            Shape::RateSquared => format!("{w}^2 (a rate-squared term)"),
            Shape::RateCubed => format!("{w}^3 (a rate-cubed term)"),
            Shape::RateAbsRate => format!("{w} |{w}| (a rate-squared term odd in the rate)"),
            Shape::RateTempSquared => {
                format!("{w} ({t} - 20)^2 (a scale factor quadratic in temperature)")
            }
            Shape::RateTempRate => {
                format!("{w} d({t})/dt (a scale factor following the temperature's rate)")
            }
            Shape::Ramp => format!("{} (a drift linear in time)", Column::Time.name()),
            Shape::TimeSquared => format!("{}^2 (a drift curving in time)", Column::Time.name()),
            Shape::TempSquared => format!("({t} - 20)^2"),
            Shape::TempCurvature => format!("d2({t})/dt2"),
            Shape::CaseSquared => format!("({c} - 20)^2"),
            Shape::CaseRate => format!("d({c})/dt"),
            Shape::CaseCurvature => format!("d2({c})/dt2"),
            Shape::CaseMinusMono => format!(
                "{c} - ({} + {})/2 (the case less the monoblocks)",
                Column::MonoA.name(),
                Column::MonoB.name()
            ),
            Shape::AbsAcc => format!("|{}|", Column::RefAcc.name()),
        }
    }

    /// Whether the run can show it.
    pub fn available(self, inp: &Inputs) -> bool {
        match self {
            Shape::RateSquared | Shape::RateCubed | Shape::RateAbsRate => rotating(inp),
            Shape::RateTempSquared | Shape::RateTempRate => rotating(inp) && inp.temp.is_some(),
            Shape::Ramp | Shape::TimeSquared => true,
            Shape::TempSquared | Shape::TempCurvature => inp.temp.is_some(),
            Shape::CaseSquared | Shape::CaseRate | Shape::CaseCurvature => inp.case.is_some(),
            Shape::CaseMinusMono => inp.case.is_some() && inp.mono_mean.is_some(),
            // A measured acceleration only: one derived from a rate
            // table's steps is spikes at its transitions.
            Shape::AbsAcc => !inp.acc_derived,
        }
    }

    /// The shape's column, one value per row (its scale is arbitrary: it is
    /// never reported as a parameter), zero where the input is at its
    /// reference (the record's start, no rate, 20 degC, no change): the
    /// constant is the bias there.
    pub fn column(self, inp: &Inputs) -> Vec<f64> {
        let n = inp.len();
        let t0 = inp.t.first().copied().unwrap_or(0.0);
        let span = (inp.t.last().copied().unwrap_or(1.0) - t0).max(1.0);
        let zeros = vec![0.0; n];
        let temp = inp.temp.as_ref().unwrap_or(&zeros);
        let case = inp.case.as_ref().unwrap_or(&zeros);
        let w = &inp.w;
        match self {
            Shape::RateSquared => w.iter().map(|x| x * x).collect(),
            Shape::RateCubed => w.iter().map(|x| x * x * x).collect(),
            Shape::RateAbsRate => w.iter().map(|x| x * x.abs()).collect(),
            Shape::RateTempSquared => w
                .iter()
                .zip(temp)
                .map(|(x, c)| x * (c - 20.0).powi(2))
                .collect(),
            Shape::RateTempRate => {
                let r = inp.temp_rate.as_ref().unwrap_or(&zeros);
                w.iter().zip(r).map(|(x, d)| x * d).collect()
            }
            Shape::CaseMinusMono => {
                let m = inp.mono_mean.as_ref().unwrap_or(&zeros);
                case.iter().zip(m).map(|(c, m)| c - m).collect()
            }
            Shape::AbsAcc => inp.acc.iter().map(|a| a.abs()).collect(),
            // From the record's start: the constant is then the bias there.
            Shape::Ramp => inp.t.iter().map(|t| (t - t0) / span).collect(),
            Shape::TimeSquared => inp.t.iter().map(|t| ((t - t0) / span).powi(2)).collect(),
            Shape::TempSquared => temp.iter().map(|x| (x - 20.0).powi(2)).collect(),
            Shape::CaseSquared => case.iter().map(|x| (x - 20.0).powi(2)).collect(),
            Shape::TempCurvature => curvature(&inp.t, temp, CURVATURE_HALF_WIDTH_S),
            Shape::CaseRate => centered_slope(&inp.t, case, RATE_HALF_WIDTH_S),
            Shape::CaseCurvature => curvature(&inp.t, case, CURVATURE_HALF_WIDTH_S),
        }
    }
}

/// The second derivative of `x` over `t`, per s^2: the slope of its slope,
/// each over `half` s either side, inside the record; within `2 half` of
/// either end, where those slopes would be one-sided (a one-sided slope of
/// a curving series is the slope at its window's centre, not at the row:
/// the nested slopes halve a lag's start-up curvature at the record's
/// first minutes, and that error reads as a step or a warm-up), the
/// curvature of a local cubic over the rows within `2 half` (exact for a
/// cubic, as the nested slopes are inside).
pub fn curvature(t: &[f64], x: &[f64], half: f64) -> Vec<f64> {
    let r = centered_slope(t, x, half);
    let mut c = centered_slope(t, &r, half);
    let n = t.len();
    if n == 0 {
        return c;
    }
    let reach = 2.0 * half;
    let (t0, t1) = (t[0], t[n - 1]);
    let edge = |k: usize| t[k] - t0 < reach || t1 - t[k] < reach;
    // The local cubic at edge rows at least a second apart (and the last
    // of each edge), linear between: a curvature over minutes is smooth on
    // a second, and a 10 Hz record's edges cost what a 1 Hz one's do.
    let mut at: Vec<usize> = vec![];
    for k in (0..n).filter(|&k| edge(k)) {
        let last_of_edge = k + 1 == n || !edge(k + 1);
        let first_of_edge = k == 0 || !edge(k - 1);
        if first_of_edge || last_of_edge || at.last().is_none_or(|&a| t[k] - t[a] >= 1.0) {
            at.push(k);
        }
    }
    let value = |k: usize| {
        let lo = t.partition_point(|&v| v < t[k] - reach);
        let hi = t.partition_point(|&v| v <= t[k] + reach);
        local_cubic_curvature(&t[lo..hi], &x[lo..hi], t[k], reach)
    };
    let vals: Vec<Option<f64>> = at.iter().map(|&k| value(k)).collect();
    for (j, &k) in at.iter().enumerate() {
        if let Some(v) = vals[j] {
            c[k] = v;
        }
        // The rows up to the next computed one on the same edge.
        if let (Some(&k2), Some(Some(v1)), Some(Some(v2))) =
            (at.get(j + 1), vals.get(j), vals.get(j + 1))
        {
            if (k + 1..k2).all(edge) {
                for m in k + 1..k2 {
                    let f = (t[m] - t[k]) / (t[k2] - t[k]);
                    c[m] = v1 + (v2 - v1) * f;
                }
            }
        }
    }
    c
}

/// The second derivative at `at` of the least-squares cubic through
/// (`t`, `x`) (times scaled by `scale` for the normal equations' sake);
/// None with fewer than 6 rows or a singular fit.
fn local_cubic_curvature(t: &[f64], x: &[f64], at: f64, scale: f64) -> Option<f64> {
    if t.len() < 6 {
        return None;
    }
    let mut a = nalgebra::Matrix4::<f64>::zeros();
    let mut b = nalgebra::Vector4::<f64>::zeros();
    for (&tk, &xk) in t.iter().zip(x) {
        let u = (tk - at) / scale;
        let p = [1.0, u, u * u, u * u * u];
        for i in 0..4 {
            b[i] += p[i] * xk;
            for j in 0..4 {
                a[(i, j)] += p[i] * p[j];
            }
        }
    }
    let sol = a.cholesky()?.solve(&b);
    let v = 2.0 * sol[2] / (scale * scale);
    v.is_finite().then_some(v)
}

/// Whether the run turns: reaches [`ROTATING_DPS`].
pub fn rotating(inp: &Inputs) -> bool {
    inp.w.iter().any(|w| w.abs() >= ROTATING_DPS)
}

/// What a term of the fit is.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Kind {
    /// The constant every fit carries (a bias's column).
    Constant,
    Effect(Effect),
    Shape(Shape),
    /// A step of the output at time x.
    Step,
    /// A periodic disturbance of period x: a sinusoid of any phase.
    Periodic,
    /// The warm-up's decaying form, exp(-t/x): with the constant, the same
    /// as the warm-up's A (1 - exp(-t/x)); alone, a warm-up that settles
    /// to no bias.
    Decay,
}

impl Kind {
    /// Whether the term is one of the library's effects.
    pub fn effect(self) -> Option<Effect> {
        match self {
            Kind::Effect(e) => Some(e),
            _ => None,
        }
    }

    /// Free parameters.
    pub fn dof(self) -> usize {
        match self {
            Kind::Effect(e) => e.dof(),
            Kind::Step | Kind::Decay => 2,
            Kind::Periodic => 3,
            _ => 1,
        }
    }

    /// Its name in the report.
    pub fn describe(self) -> String {
        match self {
            Kind::Constant => "constant".into(),
            Kind::Effect(e) => e.name().into(),
            Kind::Shape(s) => s.describe(),
            Kind::Step => "a step".into(),
            Kind::Periodic => "a periodic disturbance".into(),
            Kind::Decay => "a decaying warm-up".into(),
        }
    }
}

/// A term at its non-linear parameter (the effect's, or a step's time).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Term {
    pub kind: Kind,
    pub x: f64,
}

impl Term {
    pub fn of(kind: Kind) -> Self {
        Self { kind, x: 0.0 }
    }
}

impl Term {
    /// Its name in the report, with its time or period.
    pub fn describe(&self) -> String {
        match self.kind {
            Kind::Step => format!("a step at {:.0} s", self.x),
            Kind::Periodic => format!("a periodic disturbance of period {:.0} s", self.x),
            k => k.describe(),
        }
    }
}

/// Shortest period of a periodic disturbance offered, s (faster ones are
/// a vibration's or noise's).
pub const PERIODIC_MIN_S: f64 = 600.0;

/// The periods a periodic disturbance is searched over on a record of
/// `span` s: log-spaced from [`PERIODIC_MIN_S`] to 1.5 times the record
/// (a longer period is a curvature, for the ramp and the time squared),
/// none on a record shorter than three of the shortest.
pub fn periodic_grid(span: f64) -> Vec<f64> {
    if span < 3.0 * PERIODIC_MIN_S {
        return vec![];
    }
    let (a, b) = (PERIODIC_MIN_S.ln(), (1.5 * span).ln());
    let n = 36;
    (0..n)
        .map(|i| (a + (b - a) * i as f64 / (n - 1) as f64).exp())
        .collect()
}

/// `terms` without its `j`-th: the model a term's worth is judged against.
pub fn without(terms: &[Term], j: usize) -> Vec<Term> {
    terms
        .iter()
        .enumerate()
        .filter(|(i, _)| *i != j)
        .map(|(_, t)| *t)
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn curvature_is_exact_for_a_cubic_up_to_the_record_ends() {
        // x = a t^3 + b t^2 over 1 h at 1 Hz: x'' = 6 a t + 2 b everywhere,
        // the first and last rows included (the nested one-sided slopes
        // there were off by up to half).
        let (a, b) = (1e-10, 3e-6);
        let t: Vec<f64> = (0..3600).map(|k| k as f64).collect();
        let x: Vec<f64> = t.iter().map(|s| a * s * s * s + b * s * s).collect();
        let c = curvature(&t, &x, CURVATURE_HALF_WIDTH_S);
        for k in [0, 1, 60, 239, 240, 1800, 3360, 3500, 3599] {
            let want = 6.0 * a * t[k] + 2.0 * b;
            assert!((c[k] / want - 1.0).abs() < 1e-6, "{k}: {} vs {want}", c[k]);
        }
    }
}
