//! The model families of the continuous fit and the choice between them by
//! one information criterion (BIC):
//!
//! - knees: piecewise linear, 1..=3 knees (degree 1 with knees);
//! - polynomial: degree 1..=3 in T, no knee (degree 1 is the straight line);
//! - polynomial with knees: degree 2..=3 with 1..=3 knees.
//!
//! Each model is a (degree, knee count) cell of one grid; the criterion
//! scores every cell, the lowest wins, and the family of the winner is
//! named with the margin by which it beat the best of the other families.

/// A model family.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
pub enum Family {
    #[serde(rename = "knees")]
    Knees,
    #[serde(rename = "polynomial")]
    Polynomial,
    #[serde(rename = "polynomial_with_knees")]
    PolynomialWithKnees,
}

impl Family {
    /// The family of a model of polynomial `degree` (1..=3) with `knees`.
    pub fn of(degree: usize, knees: usize) -> Self {
        match (degree, knees) {
            (_, 0) => Family::Polynomial,
            (0 | 1, _) => Family::Knees,
            _ => Family::PolynomialWithKnees,
        }
    }

    pub fn name(self) -> &'static str {
        match self {
            Family::Knees => "knees",
            Family::Polynomial => "polynomial",
            Family::PolynomialWithKnees => "polynomial_with_knees",
        }
    }

    /// A reader's name.
    pub fn describe(self) -> &'static str {
        match self {
            Family::Knees => "piecewise linear with knees",
            Family::Polynomial => "polynomial in temperature",
            Family::PolynomialWithKnees => "polynomial with knees",
        }
    }

    /// The degree as the JSON states it: 0 for knees on straight lines.
    pub fn stated_degree(self, degree: usize) -> usize {
        match self {
            Family::Knees => 0,
            _ => degree,
        }
    }
}

impl std::fmt::Display for Family {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// One model the criterion scored.
#[derive(Clone, Debug, serde::Serialize)]
pub struct Scored {
    pub model: Family,
    /// Polynomial degree of the model's smooth part (1..=3).
    pub poly_degree: usize,
    pub knees: usize,
    pub knees_c: Vec<f64>,
    pub sensor_lag_s: f64,
    pub bic: f64,
    /// BIC above the chosen model's (0 for the chosen one).
    pub delta_bic: f64,
}

/// The best model of one family.
#[derive(Clone, Debug, serde::Serialize)]
pub struct FamilyBest {
    pub model: Family,
    /// As in the JSON's `degree` (0 for knees).
    pub degree: usize,
    pub knees: usize,
    pub bic: f64,
    pub delta_bic: f64,
}

/// The models scored: fills each one's `delta_bic`, returns the index of
/// the winner, the best of each family (in the order knees, polynomial,
/// polynomial with knees, those tried) and the winner's margin over the
/// best of the other families (infinite when no other family was tried).
pub fn choose(scored: &mut [Scored]) -> (usize, Vec<FamilyBest>, f64) {
    let best = (0..scored.len())
        .min_by(|&a, &b| scored[a].bic.total_cmp(&scored[b].bic))
        .unwrap_or(0);
    let b0 = scored.get(best).map_or(0.0, |s| s.bic);
    for s in scored.iter_mut() {
        s.delta_bic = s.bic - b0;
    }
    let mut families = vec![];
    for fam in [
        Family::Knees,
        Family::Polynomial,
        Family::PolynomialWithKnees,
    ] {
        if let Some(s) = scored
            .iter()
            .filter(|s| s.model == fam)
            .min_by(|a, b| a.bic.total_cmp(&b.bic))
        {
            families.push(FamilyBest {
                model: fam,
                degree: fam.stated_degree(s.poly_degree),
                knees: s.knees,
                bic: s.bic,
                delta_bic: s.delta_bic,
            });
        }
    }
    let winner = scored.get(best).map(|s| s.model);
    let margin = families
        .iter()
        .filter(|f| Some(f.model) != winner)
        .map(|f| f.delta_bic)
        .fold(f64::INFINITY, f64::min);
    (best, families, margin)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn s(degree: usize, knees: usize, bic: f64) -> Scored {
        Scored {
            model: Family::of(degree, knees),
            poly_degree: degree,
            knees,
            knees_c: vec![],
            sensor_lag_s: 0.0,
            bic,
            delta_bic: 0.0,
        }
    }

    #[test]
    fn families_and_the_margin() {
        assert_eq!(Family::of(1, 0), Family::Polynomial);
        assert_eq!(Family::of(1, 2), Family::Knees);
        assert_eq!(Family::of(3, 1), Family::PolynomialWithKnees);
        let mut v = vec![s(1, 0, 10.0), s(1, 1, 4.0), s(2, 0, 1.0), s(2, 1, 3.0)];
        let (i, fam, margin) = choose(&mut v);
        assert_eq!(i, 2);
        assert_eq!(fam.len(), 3);
        assert_eq!(fam[1].model, Family::Polynomial);
        assert_eq!(fam[1].degree, 2);
        assert_eq!(fam[0].degree, 0);
        // The best other family: polynomial with knees at 3.0.
        assert!((margin - 2.0).abs() < 1e-12);
    }
}
