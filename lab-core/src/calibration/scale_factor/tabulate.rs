//! The fitted model as the firmware's piecewise-linear table.
//!
//! The breakpoints (the calibrated range's ends and the knees) are nodes;
//! between them the model is a polynomial of degree at most 3, tabulated at
//! equal spacing, the fewest nodes for which linear interpolation stays
//! within [`TOLERANCE_PPM`] of it (the chord's error on a piece of width h
//! is at most h^2 max|s''| / 8). Node temperatures are rounded to the
//! firmware's Q8 degC before the model is evaluated there, so the table
//! holds the model exactly at its nodes. The error stated is that of the
//! firmware's own fixed-point lookup (g = 1/(1 + sf) interpolated, Q8
//! input) against the model, on a 1/16 degC grid over the range.

use gyro_coeffs::fog_scale_factor::{ScaleFactorTable, MAX_NODES, MIN_NODE_GAP_C};
use gyro_sp::fog::scale_factor::ScaleFactorConfig;
use gyro_sp::fog::{FogConfig, FogParams};

/// Target of the tabulation, ppm: half the 0.1 ppm the table may cost, the
/// rest left to the fixed-point arithmetic and the Q8 node temperatures.
pub const TOLERANCE_PPM: f64 = 0.05;

/// How the model was tabulated.
#[derive(Clone, Debug, serde::Serialize)]
pub struct Tabulation {
    pub nodes: usize,
    /// Node spacing in each piece between breakpoints, degC.
    pub spacing_c: Vec<f64>,
    /// The tolerance the spacing was chosen for, ppm (above
    /// [`TOLERANCE_PPM`] only when the table ran out of nodes).
    pub tolerance_ppm: f64,
    /// Largest |firmware lookup - model| over the range, ppm.
    pub max_error_ppm: f64,
}

fn q8(t: f64) -> f64 {
    (t * 256.0).round() / 256.0
}

/// Largest |chord - f| over [a, b] on 32 points.
fn chord_error(f: &impl Fn(f64) -> f64, a: f64, b: f64) -> f64 {
    let (fa, fb) = (f(a), f(b));
    (1..32)
        .map(|i| {
            let u = i as f64 / 32.0;
            let t = a + u * (b - a);
            (f(t) - (fa + u * (fb - fa))).abs()
        })
        .fold(0.0, f64::max)
}

/// Sub-intervals per piece for tolerance `tol`.
fn counts(breaks: &[f64], f: &impl Fn(f64) -> f64, tol: f64) -> Vec<usize> {
    breaks
        .windows(2)
        .map(|w| {
            let (a, b) = (w[0], w[1]);
            let most = ((b - a) / MIN_NODE_GAP_C).floor().max(1.0) as usize;
            let mut m = 1;
            while m < most {
                let h = (b - a) / m as f64;
                let worst = (0..m)
                    .map(|i| chord_error(f, a + i as f64 * h, a + (i + 1) as f64 * h))
                    .fold(0.0, f64::max);
                if worst <= tol {
                    break;
                }
                m += 1;
            }
            m
        })
        .collect()
}

/// Node temperatures (Q8) and the sub-interval counts for the model `f`
/// (ppm) between the sorted `breaks`: the tolerance grows by a quarter at a
/// time until the nodes fit the table.
pub fn nodes(breaks: &[f64], f: impl Fn(f64) -> f64) -> (Vec<f64>, Vec<usize>, f64) {
    let mut tol = TOLERANCE_PPM;
    let mut m = counts(breaks, &f, tol);
    while m.iter().sum::<usize>() + 1 > MAX_NODES && tol < 1e6 {
        tol *= 1.25;
        m = counts(breaks, &f, tol);
    }
    let mut t = vec![q8(breaks[0])];
    for (w, &k) in breaks.windows(2).zip(&m) {
        for i in 1..=k {
            t.push(q8(w[0] + (w[1] - w[0]) * i as f64 / k as f64));
        }
    }
    t.dedup();
    (t, m, tol)
}

/// The table of the model: sf (ppm) from `sf_ppm`, bias (deg/h) from
/// `bias_dph`, at the nodes for the breakpoints; with how it was made.
pub fn table(
    breaks: &[f64],
    sf_ppm: impl Fn(f64) -> f64,
    bias_dph: impl Fn(f64) -> f64,
    lag_s: f64,
) -> (ScaleFactorTable, Tabulation) {
    let (t, m, tol) = nodes(breaks, &sf_ppm);
    let sf: Vec<f64> = t.iter().map(|&x| sf_ppm(x)).collect();
    let b: Vec<f64> = t.iter().map(|&x| bias_dph(x)).collect();
    let table = ScaleFactorTable::from_nodes(&t, &sf, &b, lag_s);
    let spacing_c = breaks
        .windows(2)
        .zip(&m)
        .map(|(w, &k)| (w[1] - w[0]) / k as f64)
        .collect();
    let tab = Tabulation {
        nodes: table.n,
        spacing_c,
        tolerance_ppm: tol,
        max_error_ppm: firmware_error_ppm(&table, &sf_ppm),
    };
    (table, tab)
}

/// Largest |sf the firmware's lookup applies - the model| over the table's
/// range on a 1/16 degC grid, ppm (the firmware holds g = 1/(1 + sf) - 1
/// at 2^-32).
pub fn firmware_error_ppm(table: &ScaleFactorTable, sf_ppm: impl Fn(f64) -> f64) -> f64 {
    let Ok(fog) = FogConfig::new(FogParams::default()) else {
        return f64::NAN;
    };
    let cfg = ScaleFactorConfig::new(table, &fog, 1.0);
    if cfg.coeffs_refused {
        return f64::INFINITY;
    }
    let n = table.n.max(1);
    let (lo, hi) = (
        (table.temps_c[0] * 16.0).ceil() as i64,
        (table.temps_c[n - 1] * 16.0).floor() as i64,
    );
    (lo..=hi)
        .map(|k| {
            let t_q8 = (k * 16) as i32;
            let (g, _, _) = cfg.lookup(t_q8);
            let sf_fw = (1.0 / (1.0 + g as f64 / 4_294_967_296.0) - 1.0) * 1e6;
            (sf_fw - sf_ppm(t_q8 as f64 / 256.0)).abs()
        })
        .fold(0.0, f64::max)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A quadratic of 0.02 ppm/degC^2 over -40..+60 degC: the chord rule
    /// h^2 s''/8 <= 0.05 ppm gives h <= 3.16 degC, so 32 pieces of
    /// 3.125 degC; the firmware's lookup stays within 0.1 ppm.
    #[test]
    fn quadratic_within_a_tenth_of_a_ppm() {
        let f = |t: f64| 150.0 + 1.5 * (t - 20.0) + 0.02 * (t - 10.0).powi(2);
        let (tab, how) = table(&[-40.0, 60.0], f, |_| 0.1, 30.0);
        let h_max = (8.0 * TOLERANCE_PPM / 0.04f64).sqrt();
        assert!(how.spacing_c[0] <= h_max, "{how:?}");
        assert!(how.spacing_c[0] > 0.9 * h_max, "{how:?}");
        assert_eq!(how.nodes, tab.n);
        assert!(how.max_error_ppm < 0.1, "{how:?}");
        assert!(tab.check().is_ok());
    }

    /// Knees are nodes: a piecewise-linear model is held exactly but for
    /// the Q8 rounding of its knee.
    #[test]
    fn knees_are_nodes() {
        let f = |t: f64| 150.0 + 1.5 * (t - 20.0) + 6.0 * (t - 48.013).max(0.0);
        let (tab, how) = table(&[-39.9, 48.013, 59.9], f, |_| 0.0, 30.0);
        assert_eq!(how.nodes, 3);
        assert!(how.max_error_ppm < 0.02, "{how:?}");
        assert!((tab.temps_c[1] - 48.013).abs() <= 1.0 / 512.0);
    }
}
