//! The Allan analysis of one rate record (IEEE 952, docs/noise.md):
//! overlapping Allan deviation at log-spaced averaging times (adev.rs) with
//! chi-square intervals from Greenhall's degrees of freedom (edf.rs), the
//! noise terms fitted to the whole curve and checked against it (fit.rs,
//! uncertainty.rs), and the conventional readings (readings.rs).

use super::model::TermFit;
use super::readings::{self, Readings};
use super::{adev, edf, fit, terms};

/// Averaging times per decade.
pub const PER_DECADE: usize = 10;
/// Largest deviation of a sample interval from the median interval, relative.
pub const SAMPLING_TOLERANCE: f64 = 0.01;

/// The analysis of one record.
pub struct Allan {
    pub tau0: f64,
    pub n: usize,
    pub ms: Vec<usize>,
    pub taus: Vec<f64>,
    /// Overlapping Allan variance, (deg/s)^2, and its 95 % interval.
    pub avar: Vec<f64>,
    pub avar_lo: Vec<f64>,
    pub avar_hi: Vec<f64>,
    pub terms: TermFit,
    /// The conventional readings off the measured curve.
    pub readings: Readings,
    /// Mean rate, deg/s, and its standard error: the fitted model's Allan
    /// deviation at the record's length (for white noise exactly the
    /// standard error of the mean; it holds for correlated noise too).
    pub mean_dps: f64,
    pub mean_se_dps: f64,
}

/// Why a record cannot be analysed.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum AllanError {
    /// Fewer than 3 samples (this many).
    TooShort(usize),
    /// Every sample the same.
    Constant,
}

impl std::fmt::Display for AllanError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            AllanError::TooShort(n) => write!(
                f,
                "{n} samples: too short for even one averaging time (3 needed for tau = tau0)"
            ),
            AllanError::Constant => f.write_str(
                "the record is constant: its Allan deviation is zero, there is no noise to analyse",
            ),
        }
    }
}

/// Analyses `y` sampled every `tau0` s (the units of `y` carry through:
/// deg/s for the reported terms; the mean's standard error in `y`'s unit).
pub fn analyse(y: &[f64], tau0: f64) -> Result<Allan, AllanError> {
    let n = y.len();
    if n < 3 {
        return Err(AllanError::TooShort(n));
    }
    let first = y[0];
    if y.iter().all(|&v| v == first) {
        return Err(AllanError::Constant);
    }
    let ms = adev::averaging_factors(n, PER_DECADE);
    let taus: Vec<f64> = ms.iter().map(|&m| m as f64 * tau0).collect();
    let avar = adev::oavar(y, &ms);
    let terms = fit::fit(&taus, &avar, &ms, n + 1);
    let (mut lo, mut hi) = (vec![], vec![]);
    for (i, &a) in avar.iter().enumerate() {
        let (l, h) = edf::interval(a.sqrt(), terms.edf[i], terms::CONF);
        lo.push(l * l);
        hi.push(h * h);
    }
    let dph = |v: &[f64]| -> Vec<f64> { v.iter().map(|v| v.sqrt() * 3600.0).collect() };
    let readings = readings::read(&taus, &dph(&avar), &dph(&lo), &dph(&hi));
    let mut terms = terms;
    let floor_hi = taus
        .iter()
        .position(|&t| t == readings.floor_tau_s)
        .map_or(f64::NAN, |i| hi[i].sqrt() * 3600.0);
    bound_bias(&mut terms, &readings, floor_hi);
    let mean = y.iter().sum::<f64>() / n as f64;
    let mean_se = terms.model_at(n as f64 * tau0).sqrt();
    Ok(Allan {
        tau0,
        n,
        ms,
        taus,
        avar,
        avar_lo: lo,
        avar_hi: hi,
        terms,
        readings,
        mean_dps: mean,
        mean_se_dps: mean_se,
    })
}

/// On a curve whose floor is not resolved the flicker's level cannot be
/// read: the floor is only an upper bound on it (a longer record may show
/// the curve going on down). A fitted B above floor/0.664 puts the model's
/// flat part above the measured floor, which the curve contradicts: B's
/// value is held to floor/0.664 and reported as an upper bound, and the
/// top of its interval to what the floor point's own 95 % interval allows,
/// `floor_hi_dph`/0.664 (the floor is the lowest of many scattered points,
/// so the truth may lie above it).
fn bound_bias(t: &mut TermFit, r: &Readings, floor_hi_dph: f64) {
    const B: usize = 2;
    if r.resolved || !t.present[B] || !r.bias_instability_dph.is_finite() {
        return;
    }
    let bound = terms::from_units(B, r.bias_instability_dph);
    t.bias_upper_bound = true;
    t.c[B] = t.c[B].min(bound);
    if floor_hi_dph.is_finite() {
        t.hi[B] = t.hi[B].min(terms::from_units(B, floor_hi_dph / 0.664));
    }
    t.hi[B] = t.hi[B].max(t.c[B]);
    t.lo[B] = t.lo[B].min(t.c[B]);
}

/// Why a record's sampling does not suit the Allan variance.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum SamplingError {
    /// The median interval is not positive: time does not increase.
    NotIncreasing,
    /// Interval `row - 1 .. row` strays from the median.
    Uneven {
        row: usize,
        interval: f64,
        median: f64,
    },
}

impl SamplingError {
    /// The row the error is at.
    pub fn row(&self) -> usize {
        match self {
            SamplingError::NotIncreasing => 1,
            SamplingError::Uneven { row, .. } => *row,
        }
    }
}

impl std::fmt::Display for SamplingError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            SamplingError::NotIncreasing => f.write_str("time does not increase"),
            SamplingError::Uneven {
                interval, median, ..
            } => write!(
                f,
                "sampling not uniform: interval {} s where the median is {} s (tolerance {} %); \
                 the Allan variance needs uniform samples",
                interval,
                median,
                SAMPLING_TOLERANCE * 100.0
            ),
        }
    }
}
