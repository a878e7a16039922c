//! The Allan deviation plot's series (measured points with intervals, the
//! fitted model and each present term, deg/h), shared by the `allan` and
//! `discover` reports.

use crate::noise::analysis::Allan;
use crate::noise::terms::{self, COUNT, NAMES};
use crate::report::plot::Series;

const DPH: f64 = 3600.0;

/// The Allan deviation plot (measured points with intervals, the fitted
/// model and each present term), in deg/h.
pub fn adev_series(an: &Allan, label: &str, color: usize, terms: bool) -> Vec<Series> {
    let pts: Vec<(f64, f64)> = an
        .taus
        .iter()
        .zip(&an.avar)
        .map(|(t, v)| (*t, v.sqrt() * DPH))
        .collect();
    let errs: Vec<(f64, f64)> = an
        .avar_lo
        .iter()
        .zip(&an.avar_hi)
        .map(|(l, h)| (l.sqrt() * DPH, h.sqrt() * DPH))
        .collect();
    let mut v = vec![Series::points(label, pts, Some(errs), color)];
    if terms {
        let grid: Vec<f64> = (0..=200)
            .map(|i| {
                let (a, b) = (an.taus[0].ln(), an.taus[an.taus.len() - 1].ln());
                (a + (b - a) * i as f64 / 200.0).exp()
            })
            .collect();
        v.push(Series::line(
            "fitted model",
            grid.iter()
                .map(|&t| (t, an.terms.model_at(t).sqrt() * DPH))
                .collect(),
            1,
        ));
        for j in 0..COUNT {
            if an.terms.present[j] {
                v.push(Series::dashed(
                    NAMES[j],
                    grid.iter()
                        .map(|&t| (t, (an.terms.c[j] * terms::basis(j, t)).sqrt() * DPH))
                        .collect(),
                    2 + j,
                ));
            }
        }
    }
    v
}
