//! The gyro's grade (physics.md 4): navigation, tactical, industrial or
//! consumer. It sets the physical ranges of the effects' parameters
//! (ranges.rs): a consumer MEMS gyro drifts tens to hundreds of deg/h per
//! degC, which on a navigation FOG is no thermal bias but something else
//! imitating one. Given by the user (`--grade`) or judged from the run's
//! own white noise, the angle random walk: the one level no slow effect
//! and no drift can raise.
//!
//! | grade | angle random walk, deg/sqrt(h) | bias stability, deg/h | range factor (bias terms, scale-factor terms) |
//! |---|---|---|---|
//! | navigation | below 0.01 | 0.001 .. 0.01 | 1, 1 |
//! | tactical | 0.01 .. 0.1 | 0.1 .. 10 | 10, 4 |
//! | industrial | 0.1 .. 0.5 | 10 .. 100 | 100, 10 |
//! | consumer | 0.5 and above | 100 and more | 1000, 20 |
//!
//! The white-noise bounds are those of the classes' typical parts:
//! navigation FOGs and RLGs 0.0005 .. 0.005 deg/sqrt(h); tactical FOGs and
//! MEMS 0.012 (a 1 km-class FOG) .. 0.1; industrial MEMS near 0.1 .. 0.5
//! (0.3 for the common 0.005 deg/s/sqrt(Hz) parts); consumer parts, with
//! their board noise and coarse words, above. A part at a boundary gets
//! the wider ranges of the grade above: a range only decides whether a fit
//! is that effect at all, and a consumer gyro's thermal bias refused as
//! implausible is the failure issue 31 reports.

/// A gyro's grade.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub enum Grade {
    Navigation,
    Tactical,
    Industrial,
    Consumer,
}

/// Upper angle random walk of each grade but the last, deg/sqrt(h).
const ARW_BOUNDS: [(Grade, f64); 3] = [
    (Grade::Navigation, 0.01),
    (Grade::Tactical, 0.1),
    (Grade::Industrial, 0.5),
];

impl Grade {
    pub const ALL: [Grade; 4] = [
        Grade::Navigation,
        Grade::Tactical,
        Grade::Industrial,
        Grade::Consumer,
    ];

    pub fn name(self) -> &'static str {
        match self {
            Grade::Navigation => "navigation",
            Grade::Tactical => "tactical",
            Grade::Industrial => "industrial",
            Grade::Consumer => "consumer",
        }
    }

    pub fn from_name(s: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|g| g.name() == s)
    }

    /// How much wider than a navigation gyro's the ranges of the bias-like
    /// effects (bias, thermal terms, warm-up) are.
    pub fn bias_factor(self) -> f64 {
        match self {
            Grade::Navigation => 1.0,
            Grade::Tactical => 10.0,
            Grade::Industrial => 100.0,
            Grade::Consumer => 1000.0,
        }
    }

    /// ... and those of the scale-factor effects.
    pub fn scale_factor_factor(self) -> f64 {
        match self {
            Grade::Navigation => 1.0,
            Grade::Tactical => 4.0,
            Grade::Industrial => 10.0,
            Grade::Consumer => 20.0,
        }
    }

    /// The most slow noise a gyro of the grade has: bias instability
    /// (deg/h), rate random walk (deg/h/sqrt(h)) and a first-order Markov
    /// wander (deg/h). Generous (ten times the grade's bias stability and
    /// more): they only decide whether a residual wandering beyond them is
    /// called unexplained, never what is named. A navigation gyro with a
    /// random walk of a deg/h/sqrt(h) is a sinusoidal bias or a thermal
    /// term the noise model swallowed (issue 31), not a noisy gyro.
    pub fn noise_caps(self) -> (f64, f64, f64) {
        match self {
            Grade::Navigation => (0.1, 0.1, 0.1),
            Grade::Tactical => (30.0, 10.0, 30.0),
            Grade::Industrial => (300.0, 100.0, 300.0),
            Grade::Consumer => (3000.0, 1000.0, 3000.0),
        }
    }

    /// The grade a white noise of `arw_dpsh` deg/sqrt(h) tells.
    pub fn of_white_noise(arw_dpsh: f64) -> Self {
        ARW_BOUNDS
            .iter()
            .find(|(_, b)| arw_dpsh < *b)
            .map_or(Grade::Consumer, |(g, _)| *g)
    }

    /// The angle random walk range of the grade, deg/sqrt(h) (lo, hi;
    /// infinite for the last).
    pub fn arw_range(self) -> (f64, f64) {
        let i = Self::ALL.iter().position(|g| *g == self).unwrap_or(0);
        let lo = if i == 0 { 0.0 } else { ARW_BOUNDS[i - 1].1 };
        let hi = ARW_BOUNDS.get(i).map_or(f64::INFINITY, |b| b.1);
        (lo, hi)
    }
}

impl std::fmt::Display for Grade {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl serde::Serialize for Grade {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(self.name())
    }
}

/// The grade a discovery judges ranges at, whether it was inferred, and
/// why (the JSON's `grade`).
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct GradeChoice {
    pub value: Grade,
    pub inferred: bool,
    pub reason: String,
}

impl GradeChoice {
    /// The grade the user gave.
    pub fn given(g: Grade) -> Self {
        Self {
            value: g,
            inferred: false,
            reason: format!("given (--grade {g})"),
        }
    }

    /// The grade the run's white noise tells: `arw_dpsh` its angle random
    /// walk (from the noise floor of its window means).
    pub fn inferred(arw_dpsh: f64) -> Self {
        let g = Grade::of_white_noise(arw_dpsh);
        let (lo, hi) = g.arw_range();
        let span = if hi.is_finite() {
            format!("{lo} .. {hi}")
        } else {
            format!("{lo} and above")
        };
        Self {
            value: g,
            inferred: true,
            reason: format!(
                "judged from the run's white noise: angle random walk {} deg/sqrt(h), in the {g} range ({span} deg/sqrt(h)); give --grade to set it",
                crate::report::text::sig(arw_dpsh)
            ),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn white_noise_tells_the_grade() {
        assert_eq!(Grade::of_white_noise(0.003), Grade::Navigation);
        assert_eq!(Grade::of_white_noise(0.05), Grade::Tactical);
        assert_eq!(Grade::of_white_noise(0.3), Grade::Industrial);
        assert_eq!(Grade::of_white_noise(2.0), Grade::Consumer);
        assert_eq!(Grade::Tactical.arw_range(), (0.01, 0.1));
        assert!(Grade::Consumer.arw_range().1.is_infinite());
    }
}
