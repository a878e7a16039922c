//! The run's inputs the effects are built from, one value per row: time,
//! reference rate, the temperatures the run has, and the angular
//! acceleration.

use crate::data::run_file::Column;
use crate::numerics::thermal_difference::dt_and_gradient;
use std::collections::BTreeMap;

/// Least half width of the monoblock difference's slope, s: its lags are
/// thousands of seconds.
pub const GRADIENT_HALF_WIDTH_S: f64 = 60.0;
/// Most half width, s.
pub const GRADIENT_HALF_WIDTH_MAX_S: f64 = 900.0;

/// The resolution of a sensor's readings: the smallest step between
/// neighbours (0 where it never steps).
pub fn resolution(x: &[f64]) -> f64 {
    x.windows(2)
        .map(|p| (p[1] - p[0]).abs())
        .filter(|d| *d > 1e-9)
        .fold(f64::INFINITY, f64::min)
        .min(1e9)
}

/// The half width of the slope of `dt` (the monoblock difference) over
/// `t`, its sensors read to `q` degC: a sensor read in tenths of a degree
/// turns a difference moving at 1e-3 degC/s into a staircase of 100 s
/// treads, and the slope of a step inside the window errs by about
/// 1.5 q/(2 h), as much as the rate itself over a minute. The half width
/// keeps that below a tenth of the difference's own typical rate (taken
/// over the longest half width), within [`GRADIENT_HALF_WIDTH_S`] ..
/// [`GRADIENT_HALF_WIDTH_MAX_S`] and a twentieth of the record.
pub fn gradient_half_width(t: &[f64], dt: &[f64], q: f64) -> f64 {
    let span = t.last().copied().unwrap_or(0.0) - t.first().copied().unwrap_or(0.0);
    let hi = GRADIENT_HALF_WIDTH_MAX_S
        .min(span / 20.0)
        .max(GRADIENT_HALF_WIDTH_S);
    if !(q.is_finite() && q > 0.0) || t.len() < 3 {
        return GRADIENT_HALF_WIDTH_S;
    }
    let rough = centered_slope(t, dt, hi);
    let rms = (rough.iter().map(|v| v * v).sum::<f64>() / rough.len() as f64).sqrt();
    if rms <= 0.0 {
        return hi;
    }
    (7.5 * q / rms).clamp(GRADIENT_HALF_WIDTH_S, hi)
}

/// Half width of the temperature rate's slope, s: wide enough to average
/// a sensor's quantization and noise, short against a coil's thermal lag
/// (minutes).
pub const RATE_HALF_WIDTH_S: f64 = 30.0;

/// The least-squares slope of `x` over `t` within `half` s either side of
/// each row (fewer rows at the ends), per second. Cumulative sums: O(n).
pub fn centered_slope(t: &[f64], x: &[f64], half: f64) -> Vec<f64> {
    let n = t.len();
    let t0 = t.first().copied().unwrap_or(0.0);
    let mut c = vec![[0.0f64; 5]; n + 1];
    for k in 0..n {
        let u = t[k] - t0;
        let p = c[k];
        c[k + 1] = [
            p[0] + 1.0,
            p[1] + u,
            p[2] + u * u,
            p[3] + x[k],
            p[4] + u * x[k],
        ];
    }
    let (mut lo, mut hi) = (0usize, 0usize);
    (0..n)
        .map(|k| {
            while t[lo] < t[k] - half {
                lo += 1;
            }
            while hi < n && t[hi] <= t[k] + half {
                hi += 1;
            }
            let s: [f64; 5] = std::array::from_fn(|j| c[hi][j] - c[lo][j]);
            let den = s[0] * s[2] - s[1] * s[1];
            if s[0] < 2.0 || den <= 1e-12 * s[0] * s[2].max(1e-300) {
                0.0
            } else {
                (s[0] * s[4] - s[1] * s[3]) / den
            }
        })
        .collect()
}

/// The run's inputs the effects are built from, one value per row.
#[derive(Clone, Debug, Default)]
pub struct Inputs {
    /// Time since power-on, s.
    pub t: Vec<f64>,
    /// Reference rate, deg/s.
    pub w: Vec<f64>,
    /// Main temperature sensor (FOG coil), degC, and its rate of change
    /// (the least-squares slope over [`RATE_HALF_WIDTH_S`] either side),
    /// degC/s.
    pub temp: Option<Vec<f64>>,
    pub temp_rate: Option<Vec<f64>>,
    /// Monoblock difference dT (clamped to +-32 degC as the firmware does)
    /// and its rate (the least-squares slope over [`gradient_half_width`]
    /// either side), degC and degC/s.
    pub dt: Option<Vec<f64>>,
    pub grad: Option<Vec<f64>>,
    /// The monoblocks' mean, degC.
    pub mono_mean: Option<Vec<f64>>,
    /// The two monoblock sensors as read, degC (for terms that name them).
    pub mono: Option<(Vec<f64>, Vec<f64>)>,
    /// Case sensor, degC.
    pub case: Option<Vec<f64>>,
    /// Angular acceleration, deg/s^2, and whether it was derived from the
    /// reference rate (no `ref_acc_dps2` column).
    pub acc: Vec<f64>,
    pub acc_derived: bool,
}

impl Inputs {
    /// From the run's columns (the optional ones None when absent).
    pub fn new(
        t: Vec<f64>,
        w: Vec<f64>,
        temp: Option<Vec<f64>>,
        mono: Option<(Vec<f64>, Vec<f64>)>,
        case: Option<Vec<f64>>,
        acc: Option<Vec<f64>>,
    ) -> Self {
        let mono_mean = mono
            .as_ref()
            .map(|(a, b)| a.iter().zip(b).map(|(x, y)| 0.5 * (x + y)).collect());
        let (dt, grad) = match &mono {
            Some((a, b)) => {
                let (d, _) = dt_and_gradient(&t, a, b);
                let h = gradient_half_width(&t, &d, resolution(a).max(resolution(b)));
                let g = centered_slope(&t, &d, h);
                (Some(d), Some(g))
            }
            None => (None, None),
        };
        let temp_rate = temp
            .as_ref()
            .map(|x| centered_slope(&t, x, RATE_HALF_WIDTH_S));
        let acc_derived = acc.is_none();
        let acc = acc.unwrap_or_else(|| {
            // Central differences (one-sided at the ends).
            let n = w.len();
            (0..n)
                .map(|k| {
                    let (a, b) = (k.saturating_sub(1), (k + 1).min(n - 1));
                    if b > a {
                        (w[b] - w[a]) / (t[b] - t[a])
                    } else {
                        0.0
                    }
                })
                .collect()
        });
        Self {
            t,
            w,
            temp,
            temp_rate,
            dt,
            grad,
            mono_mean,
            mono,
            case,
            acc,
            acc_derived,
        }
    }

    /// The run's input columns present, by their run-file names (what a
    /// term's formula reads; the acceleration only where the run has it).
    pub fn columns(&self) -> BTreeMap<&'static str, &[f64]> {
        let mut c = BTreeMap::new();
        c.insert(Column::Time.name(), self.t.as_slice());
        c.insert(Column::RefRate.name(), self.w.as_slice());
        if let Some(x) = &self.temp {
            c.insert(Column::Temp.name(), x.as_slice());
        }
        if let Some((a, b)) = &self.mono {
            c.insert(Column::MonoA.name(), a.as_slice());
            c.insert(Column::MonoB.name(), b.as_slice());
        }
        if let Some(x) = &self.case {
            c.insert(Column::Case.name(), x.as_slice());
        }
        if !self.acc_derived {
            c.insert(Column::RefAcc.name(), self.acc.as_slice());
        }
        c
    }

    pub fn len(&self) -> usize {
        self.t.len()
    }

    pub fn is_empty(&self) -> bool {
        self.t.is_empty()
    }
}
