//! The run's inputs the effects are built from, one value per row: time,
//! reference rate, the temperatures the run has, and the angular
//! acceleration.

use crate::numerics::thermal_difference::dt_and_gradient;

/// The run's inputs the effects are built from, one value per row.
#[derive(Clone, Debug, Default)]
pub struct Inputs {
    /// Time since power-on, s.
    pub t: Vec<f64>,
    /// Reference rate, deg/s.
    pub w: Vec<f64>,
    /// Main temperature sensor (FOG coil), degC.
    pub temp: Option<Vec<f64>>,
    /// Monoblock difference dT (clamped to +-32 degC as the firmware does)
    /// and its filtered derivative, degC and degC/s.
    pub dt: Option<Vec<f64>>,
    pub grad: Option<Vec<f64>>,
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
        let (dt, grad) = match mono {
            Some((a, b)) => {
                let (d, g) = dt_and_gradient(&t, &a, &b);
                (Some(d), Some(g))
            }
            None => (None, None),
        };
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
            dt,
            grad,
            case,
            acc,
            acc_derived,
        }
    }

    pub fn len(&self) -> usize {
        self.t.len()
    }

    pub fn is_empty(&self) -> bool {
        self.t.is_empty()
    }
}
