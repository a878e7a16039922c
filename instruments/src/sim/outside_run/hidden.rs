//! What the outside generator hides in a run: a term outside the library
//! (physical or an event), a library effect, or nothing; its shape per
//! row for a unit coefficient (deg/h), computed from the TRUE state (row
//! means of the true rate, the true temperatures and their exact
//! derivatives, the true acceleration), never from the sensors the run
//! file carries. The formulas are this generator's own: quadratics about a
//! temperature other than 20 degC, a step with a finite (tanh) rise, a
//! sinusoid of any phase, a ramp and an exponential settling that start
//! mid-run.

use super::profiles::State;
use super::thermal::Temp;
use std::collections::BTreeMap;

#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Hidden {
    None,
    /// k w^2, k w^3, k w|w| (dph per (deg/s)^n).
    W2,
    W3,
    WAbsW,
    /// k (T - t0)^2, dph/degC^2 (coil).
    BiasTempQuadratic {
        t0_c: f64,
    },
    /// k ppm/degC^2: w (T - t0)^2 1e-6.
    SfTempQuadratic {
        t0_c: f64,
    },
    /// k d2T/dt2 of the coil, dph/(degC/s^2).
    CoilCurvature,
    /// k ppm/(degC/s): w dT/dt 1e-6 (coil).
    SfTempRate,
    /// k (T_case - (T_a + T_b)/2), dph/degC (RLG).
    CaseMinusMono,
    /// k dT_case/dt, dph/(degC/s) (RLG).
    CaseRate,
    /// k |angular acceleration|, dph/(deg/s^2).
    AbsAcc,
    /// a (1 + tanh((t - t0)/rise))/2, dph.
    Step {
        t0_s: f64,
        rise_s: f64,
    },
    /// a sin(2 pi t/period + phase), dph.
    Periodic {
        period_s: f64,
        phase_rad: f64,
    },
    /// k (t - t1)/3600 from t1 on, dph/h.
    Ramp {
        t1_s: f64,
    },
    /// a (1 - exp(-(t - t1)/tau)) from t1 on, dph.
    Settling {
        t1_s: f64,
        tau_s: f64,
    },
    /// Library effects, in the library's terms: error_ppm w, dph_per_c
    /// (T - 20) of the coil, dph_per_c (T_case - 20).
    ScaleFactorError,
    BiasTemperature,
    CaseTemperature,
}

/// deg/s -> deg/h.
const DPH: f64 = 3600.0;

impl Hidden {
    /// The coefficient's name and unit.
    pub fn coefficient(self) -> &'static str {
        match self {
            Hidden::None => "none",
            Hidden::W2 => "k_dph_per_dps2",
            Hidden::W3 => "k_dph_per_dps3",
            Hidden::WAbsW => "k_dph_per_dps2",
            Hidden::BiasTempQuadratic { .. } => "k_dph_per_c2",
            Hidden::SfTempQuadratic { .. } => "k_ppm_per_c2",
            Hidden::CoilCurvature => "k_dph_per_c_per_s2",
            Hidden::SfTempRate => "k_ppm_per_c_per_s",
            Hidden::CaseMinusMono => "k_dph_per_c",
            Hidden::CaseRate => "k_dph_per_c_per_s",
            Hidden::AbsAcc => "k_dph_per_dps2",
            Hidden::Step { .. } | Hidden::Periodic { .. } | Hidden::Settling { .. } => {
                "amplitude_dph"
            }
            Hidden::Ramp { .. } => "k_dph_per_h",
            Hidden::ScaleFactorError => "error_ppm",
            Hidden::BiasTemperature | Hidden::CaseTemperature => "dph_per_c",
        }
    }

    /// What a gyro engineer would write for it (documentation only: the
    /// bench never reads it).
    pub fn describe(self) -> String {
        match self {
            Hidden::None => "nothing".into(),
            Hidden::W2 => "k * w^2 (row mean of the true rate squared)".into(),
            Hidden::W3 => "k * w^3".into(),
            Hidden::WAbsW => "k * w|w|".into(),
            Hidden::BiasTempQuadratic { t0_c } => format!("k * (T_coil - {t0_c:.2})^2"),
            Hidden::SfTempQuadratic { t0_c } => {
                format!("k * 1e-6 * w * (T_coil - {t0_c:.2})^2 (scale factor)")
            }
            Hidden::CoilCurvature => "k * d2T_coil/dt2 (true coil)".into(),
            Hidden::SfTempRate => "k * 1e-6 * w * dT_coil/dt (scale factor)".into(),
            Hidden::CaseMinusMono => "k * (T_case - (T_mono_a + T_mono_b)/2) (true)".into(),
            Hidden::CaseRate => "k * dT_case/dt (true)".into(),
            Hidden::AbsAcc => "k * |angular acceleration| (true)".into(),
            Hidden::Step { t0_s, rise_s } => {
                format!("a * (1 + tanh((t - {t0_s:.0})/{rise_s:.1}))/2")
            }
            Hidden::Periodic {
                period_s,
                phase_rad,
            } => format!("a * sin(2 pi t/{period_s:.0} + {phase_rad:.3})"),
            Hidden::Ramp { t1_s } => format!("k * (t - {t1_s:.0})/3600 from t = {t1_s:.0} s"),
            Hidden::Settling { t1_s, tau_s } => {
                format!("a * (1 - exp(-(t - {t1_s:.0})/{tau_s:.0})) from t = {t1_s:.0} s")
            }
            Hidden::ScaleFactorError => "library: scale_factor_error".into(),
            Hidden::BiasTemperature => "library: bias_temperature (true coil)".into(),
            Hidden::CaseTemperature => "library: case_temperature (true case)".into(),
        }
    }

    /// Its shape parameters (besides the coefficient).
    pub fn shape_parameters(self) -> BTreeMap<String, f64> {
        let v: Vec<(&str, f64)> = match self {
            Hidden::BiasTempQuadratic { t0_c } | Hidden::SfTempQuadratic { t0_c } => {
                vec![("t0_c", t0_c)]
            }
            Hidden::Step { t0_s, rise_s } => vec![("t0_s", t0_s), ("rise_s", rise_s)],
            Hidden::Periodic {
                period_s,
                phase_rad,
            } => vec![("period_s", period_s), ("phase_rad", phase_rad)],
            Hidden::Ramp { t1_s } => vec![("t1_s", t1_s)],
            Hidden::Settling { t1_s, tau_s } => vec![("t1_s", t1_s), ("tau_s", tau_s)],
            _ => vec![],
        };
        v.into_iter().map(|(k, x)| (k.to_owned(), x)).collect()
    }

    /// The shape for a unit coefficient, deg/h per row.
    pub fn shape(self, st: &State) -> Vec<f64> {
        let n = st.t.len();
        // A state without the temperature a term needs (a recipe's
        // mismatch, never drawn) reads zeros rather than panicking.
        let zero = Temp {
            v: vec![0.0; n],
            d1: vec![0.0; n],
            d2: vec![0.0; n],
        };
        let coil = || st.coil.as_ref().unwrap_or(&zero);
        let case = || st.case.as_ref().unwrap_or(&zero);
        let per = |f: &dyn Fn(usize) -> f64| (0..n).map(f).collect::<Vec<f64>>();
        match self {
            Hidden::None => vec![0.0; n],
            Hidden::W2 => st.w2.clone(),
            Hidden::W3 => st.w3.clone(),
            Hidden::WAbsW => st.wabsw.clone(),
            Hidden::BiasTempQuadratic { t0_c } => per(&|k| (coil().v[k] - t0_c).powi(2)),
            Hidden::SfTempQuadratic { t0_c } => {
                per(&|k| 1e-6 * DPH * st.w[k] * (coil().v[k] - t0_c).powi(2))
            }
            Hidden::CoilCurvature => coil().d2.clone(),
            Hidden::SfTempRate => per(&|k| 1e-6 * DPH * st.w[k] * coil().d1[k]),
            Hidden::CaseMinusMono => {
                let (a, b) = st.mono.as_ref().map_or((&zero, &zero), |(a, b)| (a, b));
                per(&|k| case().v[k] - 0.5 * (a.v[k] + b.v[k]))
            }
            Hidden::CaseRate => case().d1.clone(),
            Hidden::AbsAcc => st.abs_acc.clone(),
            Hidden::Step { t0_s, rise_s } => {
                per(&|k| 0.5 * (1.0 + ((st.t[k] - t0_s) / rise_s).tanh()))
            }
            Hidden::Periodic {
                period_s,
                phase_rad,
            } => per(&|k| (2.0 * std::f64::consts::PI * st.t[k] / period_s + phase_rad).sin()),
            Hidden::Ramp { t1_s } => per(&|k| (st.t[k] - t1_s).max(0.0) / 3600.0),
            Hidden::Settling { t1_s, tau_s } => per(&|k| {
                let s = st.t[k] - t1_s;
                if s > 0.0 {
                    1.0 - (-s / tau_s).exp()
                } else {
                    0.0
                }
            }),
            Hidden::ScaleFactorError => per(&|k| 1e-6 * DPH * st.w[k]),
            Hidden::BiasTemperature => per(&|k| coil().v[k] - 20.0),
            Hidden::CaseTemperature => per(&|k| case().v[k] - 20.0),
        }
    }
}
