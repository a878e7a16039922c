//! Are the rates in the unit they are read in? A wrong unit gives a
//! confident wrong answer by a round factor (57.3 for rad/s, 3600 for
//! deg/h), so the data is asked, in the order of the evidence's weight:
//!
//! 1. where the table turns, the output follows the reference with a slope
//!    of 1 (a scale-factor error is ppm, a unit is a factor): a slope near
//!    a unit's factor is refused, one near -1 is an axis the wrong way;
//! 2. a column's name that states another unit than the one in effect
//!    (`gyro_z_rad_s` read as deg/s) is refused where no unit was given;
//! 3. at a constant, non-zero reference (the Earth-rate component), a
//!    mean that is the reference times a unit's factor;
//! 4. the values on a grid whose step is a round number of degrees but
//!    not of the unit read (a deg/s logger's 0.01 converted to rad/s);
//! 5. on a static record, a white noise and a bias that no gyro has
//!    together, but a gyro of some grade has at a unit's factor.
//!
//! 1 to 4 decide; 5 is a judgement from typical parts and only warns. A
//! static record with none of them is said to be unchecked.

use super::{mean_sd, white_sd, Warning};
use crate::data::units::{rate_unit_of_name, RateUnit};

/// What the check was given: the rates as read (deg/s after the unit in
/// effect), the column's name as the file has it, and the unit given.
pub struct RateColumn<'a> {
    pub t: &'a [f64],
    pub rate_dps: &'a [f64],
    pub reference_dps: Option<&'a [f64]>,
    pub name: &'a str,
    pub given: Option<RateUnit>,
    pub reference_given: Option<RateUnit>,
    /// The rows' period, s, where the caller has judged it (the median
    /// interval of `t` otherwise).
    pub period_s: Option<f64>,
}

/// The outcome: warnings, and how far the unit could be checked.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct UnitCheck {
    pub warnings: Vec<Warning>,
    /// How the unit was confirmed, or why it could not be.
    pub basis: String,
    /// The white noise of the rate less its reference (`white_sd`), deg/s,
    /// where the check reached it: later checks of the same rows reuse it.
    pub white_sd_dps: Option<f64>,
}

/// The units the file could be in instead, with the factor that turns
/// what was read into deg/s: `true = factor * read`.
fn alternatives(read_as: RateUnit) -> Vec<(RateUnit, f64)> {
    RateUnit::ALL
        .into_iter()
        .filter(|u| *u != read_as)
        .map(|u| (u, u.to_dps() / read_as.to_dps()))
        .collect()
}

/// The Earth's rate, deg/h.
pub const EARTH_DPH: f64 = 15.041;

/// Where a slope (or ratio) of the rate on its reference is a unit's
/// factor to within `tol`: which column is in which unit, in words.
fn mixed_units(s: f64, read_as: RateUnit, ref_as: RateUnit, tol: f64) -> Option<String> {
    let near = |f: f64| (s.abs() / f - 1.0).abs() < tol;
    for u in RateUnit::ALL {
        // The rate in u: it reads 1/f of the reference.
        let f = u.to_dps() / read_as.to_dps();
        if u != read_as && near(1.0 / f) {
            return Some(format!(
                "a factor of {} where a gyro's scale factor is 1 to within percents. Is the rate in {u} and the reference in {ref_as}? Give the rate's unit with --rate-unit {u} (and the reference's with --ref-rate-unit {ref_as})",
                factor_text(1.0 / f)
            ));
        }
        // The reference in u: the rate reads f of it.
        let g = u.to_dps() / ref_as.to_dps();
        if u != ref_as && near(g) {
            return Some(format!(
                "a factor of {} where a gyro's scale factor is 1 to within percents. Is the reference in {u} and the rate in {read_as}? Give the reference's unit with --ref-rate-unit {u}",
                factor_text(g)
            ));
        }
    }
    None
}

/// A factor in words (57.3, 1/57.3, 3600, 1/3600).
pub fn factor_text(f: f64) -> String {
    if f >= 1.0 {
        crate::report::text::sig(f).to_string()
    } else {
        format!("1/{}", crate::report::text::sig(1.0 / f))
    }
}

/// Least-squares slope of `y` on `x`.
fn slope(x: &[f64], y: &[f64]) -> f64 {
    let (mx, _) = mean_sd(x);
    let (my, _) = mean_sd(y);
    let (mut sxy, mut sxx) = (0.0, 0.0);
    for (a, b) in x.iter().zip(y) {
        sxy += (a - mx) * (b - my);
        sxx += (a - mx) * (a - mx);
    }
    sxy / sxx
}

/// The typical parts of each grade: white noise (angle random walk,
/// deg/sqrt(h)) and the largest bias a static record of one shows, deg/h
/// (the Earth rate's 15 deg/h included, where the reference leaves it
/// in): navigation FOGs and RLGs, tactical FOGs and MEMS, industrial and
/// consumer MEMS (whose uncalibrated zero-rate level reaches tens of
/// deg/s).
const GRADES: [(&str, f64, f64, f64); 4] = [
    ("navigation", 1e-4, 0.01, 20.0),
    ("tactical", 0.005, 0.5, 50.0),
    ("industrial", 0.1, 3.0, 7_200.0),
    ("consumer", 0.2, 30.0, 72_000.0),
];

/// The grade a white noise and a bias fit, if any.
fn grade_of(arw_dpsh: f64, bias_dph: f64) -> Option<&'static str> {
    GRADES
        .iter()
        .find(|g| (g.1..=g.2).contains(&arw_dpsh) && bias_dph.abs() <= g.3)
        .map(|g| g.0)
}

/// The step of the grid `x` lies on, if it lies on one (at least 90 % of
/// the nonzero differences whole multiples of the smallest).
fn grid_step(x: &[f64]) -> Option<f64> {
    // Two passes over the differences, none kept (a day at 100 Hz is 10^7
    // of them); the second stops once a tenth are off the grid, as they
    // are at once in a record that lies on none.
    let steps = || {
        x.windows(2)
            .map(|w| (w[1] - w[0]).abs())
            .filter(|v| *v > 0.0)
    };
    let (n, q) = smallest_step(x);
    if n < 20 || q <= 0.0 {
        return None;
    }
    let allowed_off = n - (n * 9).div_ceil(10);
    let mut off = 0;
    for v in steps() {
        let k = v / q;
        if (k - k.round()).abs() >= 1e-6 * k.max(1.0) {
            off += 1;
            if off > allowed_off {
                return None;
            }
        }
    }
    Some(q)
}

/// The number of nonzero first differences of `x` and the smallest of
/// them: branch-free over lanes, so the compiler vectorises it.
fn smallest_step(x: &[f64]) -> (usize, f64) {
    const L: usize = 8;
    let (mut n, mut q) = ([0usize; L], [f64::INFINITY; L]);
    let d = |i: usize| (x[i + 1] - x[i]).abs();
    let m = x.len().saturating_sub(1);
    let whole = m / L * L;
    for i in (0..whole).step_by(L) {
        for j in 0..L {
            let v = d(i + j);
            let nz = v > 0.0;
            n[j] += nz as usize;
            q[j] = q[j].min(if nz { v } else { f64::INFINITY });
        }
    }
    for i in whole..m {
        let v = d(i);
        if v > 0.0 {
            n[0] += 1;
            q[0] = q[0].min(v);
        }
    }
    (
        n.iter().sum(),
        q.iter().copied().fold(f64::INFINITY, f64::min),
    )
}

/// Whether `v` is a round decimal (1, 2, 2.5 or 5 times a power of ten, or
/// a part's LSB of 4.375, 8.75, 17.5, 35 or 70 times one), within 1e-6.
fn round_decimal(v: f64) -> bool {
    let e = v.abs().log10().floor();
    let m = v.abs() / 10f64.powf(e);
    [1.0, 2.0, 2.5, 5.0, 4.375, 8.75, 1.75, 3.5, 7.0, 10.0]
        .iter()
        .any(|r| (m - r).abs() < 1e-6 * r)
}

/// A unit the data shows wrong: the sentence, for the caller to place at
/// the column.
#[derive(Clone, Debug, PartialEq)]
pub struct Refusal(pub String);

/// Checks the unit of a rate column. `Err` where the data shows the unit
/// is wrong.
pub fn check(c: &RateColumn) -> Result<UnitCheck, Refusal> {
    let read_as = c.given.unwrap_or_default();
    let mut out = UnitCheck::default();
    // 2: the name (our own column name, kept from a template, says
    // nothing the user chose).
    let ours = crate::data::run_file::Column::ALL
        .iter()
        .any(|col| col.name() == c.name);
    if let Some(named) = rate_unit_of_name(c.name).filter(|_| !ours) {
        if named != read_as {
            let f = named.to_dps() / read_as.to_dps();
            let msg = format!(
                "the column's name says {named}, but it is read as {read_as} (a factor of {})",
                factor_text(f)
            );
            if c.given.is_none() {
                return Err(Refusal(format!("{msg}: give --rate-unit {named}")));
            }
            out.warnings.push(Warning::new(
                "unit",
                format!("{msg}; --rate-unit {read_as} was given, so it is read so"),
            ));
        }
    }
    let ref_as = c.reference_given.or(c.given).unwrap_or_default();
    // 1: the reference, where the table turns.
    if let Some(w) = c.reference_dps {
        let (lo, hi) = w.iter().fold((f64::INFINITY, f64::NEG_INFINITY), |a, &v| {
            (a.0.min(v), a.1.max(v))
        });
        if hi - lo > 1.0 && c.rate_dps.len() >= 10 {
            let s = slope(w, c.rate_dps);
            let what = format!("the rate follows the reference (which turns {lo:.3} .. {hi:.3} deg/s) with a slope of {}", crate::report::text::sig(s));
            if let Some(m) = mixed_units(s, read_as, ref_as, 0.05) {
                return Err(Refusal(format!("{what}: {m}")));
            }
            if (s + 1.0).abs() < 0.1 {
                out.warnings.push(Warning::new(
                    "sign",
                    format!(
                        "the rate follows the reference with a slope of {:.4}: the gyro's axis points the other way to the table's (or one sign convention differs); the analysis takes the data as it is",
                        s
                    ),
                ));
            } else if !(0.8..=1.25).contains(&s) {
                out.warnings.push(Warning::new(
                    "unit",
                    format!(
                        "the rate follows the reference with a slope of {:.4}, far from 1 and from any unit's factor: check the columns' units and the gyro's nominal scale factor",
                        s
                    ),
                ));
            }
            out.basis = format!("the rate follows the reference with a slope of {s:.6}");
            return Ok(out);
        }
    }
    // A table held at one rate, or the Earth-rate component at rest: the
    // mean follows it with a ratio of 1 (less a bias).
    if let Some(w) = c.reference_dps {
        let (r0, _) = mean_sd(w);
        let (m, _) = mean_sd(c.rate_dps);
        let sd = white_sd(c.rate_dps);
        let se = sd / (c.rate_dps.len() as f64).sqrt();
        let ratio = m / r0;
        let far = (m - r0).abs() > 10.0 * se && (ratio.abs() > 20.0 || ratio.abs() < 0.05);
        if r0 != 0.0 && se < 0.02 * m.abs() && far && c.rate_dps.len() >= 10 {
            if let Some(msg) = mixed_units(ratio, read_as, ref_as, 0.1) {
                return Err(Refusal(format!(
                    "the mean rate, {} deg/s, is {} times the constant reference ({} deg/s): {msg}",
                    crate::report::text::sig(m),
                    crate::report::text::sig(ratio),
                    crate::report::text::sig(r0)
                )));
            }
        }
        if r0.abs() > 1.0 && c.rate_dps.len() >= 10 {
            if (1.0..=15.05).contains(&r0.abs())
                && ref_as == RateUnit::DegPerS
                && (ratio - 1.0).abs() < 0.2
            {
                out.warnings.push(Warning::new(
                    "unit",
                    format!(
                        "the reference is a constant {} deg/s: a rate table held there, or, if the file is in deg/h, the Earth-rate component at rest ({} deg/h at most): is it? (--rate-unit deg/h, a factor of 1/3600)",
                        crate::report::text::sig(r0),
                        crate::report::text::sig(EARTH_DPH)
                    ),
                ));
            }
            out.basis =
                format!("the mean rate against the table's constant rate: a ratio of {ratio:.6}");
            return Ok(out);
        }
    }
    let bias: std::borrow::Cow<[f64]> = match c.reference_dps {
        Some(w) => c.rate_dps.iter().zip(w).map(|(y, w)| y - w).collect(),
        None => std::borrow::Cow::Borrowed(c.rate_dps),
    };
    let (mean_bias, _) = mean_sd(&bias);
    let sd = white_sd(&bias);
    out.white_sd_dps = Some(sd);
    // 4: a grid of round degrees that is not one of the unit read.
    if let Some(q) = grid_step(&bias) {
        if !round_decimal(q) {
            if let Some((u, f)) = alternatives(read_as)
                .into_iter()
                .find(|(_, f)| round_decimal(q * f))
            {
                out.warnings.push(Warning::new(
                    "unit",
                    format!(
                        "the rates lie on a grid of {} deg/s as read in {read_as}, not a round step; in {u} it would be {} deg/s exactly, a logger's resolution: is the file in {u}? (--rate-unit {u}, a factor of {})",
                        crate::report::text::sig(q),
                        crate::report::text::sig(q * f),
                        factor_text(f)
                    ),
                ));
            }
        }
    }
    // 5: the grade the white noise and the bias fit.
    let dt = c.period_s.unwrap_or_else(|| median_interval(c.t));
    let arw = sd * dt.sqrt() * 60.0;
    let bias_dph = mean_bias * 3600.0;
    if arw > 0.0 && grade_of(arw, bias_dph).is_none() {
        let fits: Vec<(RateUnit, f64, &str)> = alternatives(read_as)
            .into_iter()
            .filter_map(|(u, f)| grade_of(arw * f, bias_dph * f).map(|g| (u, f, g)))
            .collect();
        let what = format!(
            "as {read_as}, the record's white noise ({} deg/sqrt(h)) and its bias ({} deg/h) are no gyro's together",
            crate::report::text::sig(arw),
            crate::report::text::sig(bias_dph)
        );
        let msg = match fits.first() {
            Some((u, f, g)) => format!(
                "{what}; in {u} (a factor of {}) they are a {g} gyro's: is the file in {u}? (--rate-unit {u})",
                factor_text(*f)
            ),
            None => format!("{what}: check the rate's unit"),
        };
        out.warnings.push(Warning::new("unit", msg));
    }
    if out.basis.is_empty() {
        out.basis = match out.warnings.is_empty() {
            true => format!(
                "not confirmed: a static record shows no scale, only that its white noise ({} deg/sqrt(h)) and bias ({} deg/h) fit a gyro in {read_as}",
                crate::report::text::sig(arw),
                crate::report::text::sig(bias_dph)
            ),
            false => "doubtful (see the warnings)".into(),
        };
    }
    Ok(out)
}

pub use crate::numerics::stats::median_interval;

#[cfg(test)]
mod tests {
    use super::*;

    fn noise(n: usize, sd: f64, seed: u64) -> Vec<f64> {
        // A small LCG with a Box-Muller pair: no dependency for a test.
        let mut s = seed
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        let mut u = || {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((s >> 11) as f64 + 0.5) / (1u64 << 53) as f64
        };
        (0..n)
            .map(|_| sd * (-2.0 * u().ln()).sqrt() * (2.0 * std::f64::consts::PI * u()).cos())
            .collect()
    }

    fn column<'a>(
        t: &'a [f64],
        y: &'a [f64],
        w: Option<&'a [f64]>,
        name: &'a str,
    ) -> RateColumn<'a> {
        RateColumn {
            t,
            rate_dps: y,
            reference_dps: w,
            name,
            given: None,
            reference_given: None,
            period_s: None,
        }
    }

    #[test]
    fn a_rate_in_rad_s_against_a_table_in_deg_s_is_refused_with_the_factor() {
        let n = 2000;
        let t: Vec<f64> = (0..n).map(|k| k as f64 * 0.1).collect();
        let w: Vec<f64> = (0..n)
            .map(|k| if k < n / 2 { 50.0 } else { -50.0 })
            .collect();
        let e = noise(n, 1e-3, 1);
        let rad: Vec<f64> = w.iter().zip(&e).map(|(w, e)| w / 57.29578 + e).collect();
        let err = check(&column(&t, &rad, Some(&w), "gyro_z")).unwrap_err().0;
        assert!(err.contains("factor of 1/57.29"), "{err}");
        let deg: Vec<f64> = w.iter().zip(&e).map(|(w, e)| w * 1.0001 + e).collect();
        let ok = check(&column(&t, &deg, Some(&w), "gyro_z")).unwrap();
        assert!(ok.warnings.is_empty(), "{:?}", ok.warnings);
        let flipped: Vec<f64> = deg.iter().map(|v| -v).collect();
        assert_eq!(
            check(&column(&t, &flipped, Some(&w), "g"))
                .unwrap()
                .warnings[0]
                .code,
            "sign"
        );
    }

    #[test]
    fn a_name_that_says_rad_is_refused_without_a_unit() {
        let t: Vec<f64> = (0..100).map(|k| k as f64).collect();
        let y = noise(100, 1e-3, 2);
        assert!(check(&column(&t, &y, None, "gyro_z_rad_s")).is_err());
        let mut c = column(&t, &y, None, "gyro_z_rad_s");
        c.given = Some(RateUnit::RadPerS);
        assert!(check(&c).is_ok());
    }

    #[test]
    fn a_navigation_gyro_in_rad_s_is_no_gyro_in_deg_s() {
        // 0.003 deg/sqrt(h) at 1 Hz, 0.05 deg/h bias: a navigation RLG.
        let n = 20_000;
        let t: Vec<f64> = (0..n).map(|k| k as f64).collect();
        let sd = 0.003 / 60.0;
        let y: Vec<f64> = noise(n, sd, 3).iter().map(|v| v + 0.05 / 3600.0).collect();
        assert!(check(&column(&t, &y, None, "omega"))
            .unwrap()
            .warnings
            .is_empty());
        let rad: Vec<f64> = y.iter().map(|v| v / 57.29578).collect();
        let w = check(&column(&t, &rad, None, "g")).unwrap().warnings;
        assert!(
            w.iter()
                .any(|w| w.code == "unit" && w.message.contains("57.29")),
            "{w:?}"
        );
    }

    #[test]
    fn a_grid_of_round_degrees_read_as_radians_is_seen() {
        let t: Vec<f64> = (0..300).map(|k| 15.0 * k as f64).collect();
        let y: Vec<f64> = noise(300, 0.03, 4)
            .iter()
            .map(|v| ((v - 1.0) * 100.0).round() / 100.0 / 57.29577951308232)
            .collect();
        let w = check(&column(&t, &y, None, "zaxis")).unwrap().warnings;
        assert!(w.iter().any(|w| w.message.contains("grid")), "{w:?}");
    }
}
