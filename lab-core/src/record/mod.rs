//! What a record is, checked against the data before any analysis trusts
//! it: the units its rates are in (units.rs), whether it holds still
//! (stationarity.rs), and how it was sampled (sampling.rs). Each check
//! gives warnings with a code scripts test for, or a refusal where going
//! on would give a confident wrong answer.

pub mod sampling;
pub mod stationarity;
pub mod units;

/// A warning on a record: `code` for scripts, `message` for people (in
/// the JSON the code is also `kind`, as the calibrations' warnings name
/// it).
#[derive(Clone, Debug, PartialEq)]
pub struct Warning {
    pub code: &'static str,
    pub message: String,
}

impl serde::Serialize for Warning {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        use serde::ser::SerializeStruct;
        let mut m = s.serialize_struct("Warning", 3)?;
        m.serialize_field("kind", self.code)?;
        m.serialize_field("code", self.code)?;
        m.serialize_field("message", &self.message)?;
        m.end()
    }
}

impl Warning {
    pub fn new(code: &'static str, message: impl Into<String>) -> Self {
        Self {
            code,
            message: message.into(),
        }
    }
}

/// Mean and sample standard deviation.
pub(crate) fn mean_sd(x: &[f64]) -> (f64, f64) {
    let n = x.len().max(1) as f64;
    let m = x.iter().sum::<f64>() / n;
    let v = x.iter().map(|v| (v - m) * (v - m)).sum::<f64>() / (n - 1.0).max(1.0);
    (m, v.sqrt())
}

/// The white noise of a series: the scatter of its first differences
/// over sqrt(2) (slow drift and a bias drop out), robust to a few spikes
/// (the median absolute difference, scaled to a normal's sigma; the RMS
/// difference where quantisation makes most differences zero).
pub(crate) fn white_sd(x: &[f64]) -> f64 {
    let mut d: Vec<f64> = x.windows(2).map(|w| (w[1] - w[0]).abs()).collect();
    if d.is_empty() {
        return 0.0;
    }
    let rms = (d.iter().map(|v| v * v).sum::<f64>() / d.len() as f64).sqrt();
    let med = crate::numerics::stats::median_mut(&mut d);
    if med > 0.0 {
        med / (0.674_489_750 * std::f64::consts::SQRT_2)
    } else {
        rms / std::f64::consts::SQRT_2
    }
}
