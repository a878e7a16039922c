//! The named physical effects of docs/interfaces.md (`discover`), each the
//! formula written once, here: what it adds to the gyro's output
//! (deg/s) from the run's inputs. A model (gyro_model.rs) evaluates these;
//! the discovery (discovery/) fits them as regressors.
//!
//! An effect adds `sum_i p_i * column_i(inputs; x)` plus, for lock-in, a
//! fixed form `offset(inputs; x)`, with p_i its linear parameters (in the
//! units their names state) and x its one non-linear parameter, if any.
//!
//! | effect | adds (deg/s) | inputs |
//! |---|---|---|
//! | bias | b/3600 | - |
//! | scale_factor_error | e 1e-6 w | - |
//! | scale_factor_asymmetry | (a/2) 1e-6 abs(w) (scale factor of positive rates exceeds negative by a) | - |
//! | scale_factor_temperature | k 1e-6 w (T - 20) | temp_c |
//! | scale_factor_knee | d 1e-6 w max(0, T - T_k) | temp_c |
//! | vibration_rectification | c eps^2/3600 (eps the angular acceleration, deg/s^2; docs/fog.md) | ref_acc_dps2 or ref_rate_dps |
//! | lock_in | sign(w) sqrt(w^2 - W_L^2) - w, or -w inside the lock band (docs/rlg.md) | - |
//! | thermal_difference | k1 dT/3600, dT = t_mono_a - t_mono_b | t_mono_a_c, t_mono_b_c |
//! | thermal_gradient | k2 d(dT)/dt /3600, the rate of dT as the least-squares slope over +-60 s or more (inputs.rs: wider for coarse sensors) | t_mono_a_c, t_mono_b_c |
//! | thermal_difference_squared | k3 dT^2/3600 | t_mono_a_c, t_mono_b_c |
//! | case_temperature | k4 (T_K - 20)/3600 | t_case_c |
//! | warm_up | A (1 - exp(-t/tau))/3600, t since power-on | - |
//! | bias_temperature | b (T - 20)/3600 (FOG coil; docs/fog.md, thermal bias) | temp_c |
//! | shupe | s dT/dt /3600, dT/dt the coil temperature's rate (the least-squares slope over +-30 s) | temp_c |
//! | bias_temperature_rate | s dT/dt /3600 (MEMS: a bias that follows the die temperature's rate, the package's thermal gradient and stress) | temp_c |
//!
//! Which gyro each belongs to ([`Effect::applies_to`]): lock-in and the
//! monoblock and case terms to the RLG (physics.md 2.3), rectification
//! and the Shupe bias to the FOG, the rate term under its own name to the
//! MEMS gyro (no Shupe effect there: no fibre), the knee to the FOG and
//! RLG; the bias, the scale factor and its temperature term, the bias
//! over temperature (FOG and MEMS) and the warm-up as the physics says.
//!
//! The gradient's coefficient k2 is the physical one (deg/h per degC/s):
//! the firmware applies it to its causal 20 s filtered derivative, whose
//! noise on quantised sensors (a hundredth of a degree every few seconds
//! differenced and filtered) is as large as the rate itself; fitted on it
//! the coefficient is attenuated and the effect loses to smoother shapes
//! (issue 31). The lab has the whole record and uses the centred slope.
//!
//! Each parameter has a physical range (ranges.rs): a fit outside it is
//! not that effect.

use super::gyro_kind::GyroKind;
use super::inputs::Inputs;
use crate::data::run_file::Column;

/// A named effect.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Effect {
    Bias,
    ScaleFactorError,
    ScaleFactorAsymmetry,
    ScaleFactorTemperature,
    ScaleFactorKnee,
    VibrationRectification,
    LockIn,
    ThermalDifference,
    ThermalGradient,
    ThermalDifferenceSquared,
    CaseTemperature,
    WarmUp,
    BiasTemperature,
    Shupe,
    BiasTemperatureRate,
}

/// An effect's contribution for a non-linear parameter: its columns (deg/s
/// per unit of each linear parameter) and a fixed part (deg/s).
pub struct Basis {
    pub cols: Vec<Vec<f64>>,
    pub offset: Option<Vec<f64>>,
}

const PPM: f64 = 1e-6;
/// deg/s per deg/h.
pub const DPH: f64 = 1.0 / 3600.0;

impl Effect {
    pub const ALL: [Effect; 15] = [
        Effect::Bias,
        Effect::ScaleFactorError,
        Effect::ScaleFactorAsymmetry,
        Effect::ScaleFactorTemperature,
        Effect::ScaleFactorKnee,
        Effect::VibrationRectification,
        Effect::LockIn,
        Effect::ThermalDifference,
        Effect::ThermalGradient,
        Effect::ThermalDifferenceSquared,
        Effect::CaseTemperature,
        Effect::WarmUp,
        Effect::BiasTemperature,
        Effect::Shupe,
        Effect::BiasTemperatureRate,
    ];

    pub fn name(self) -> &'static str {
        match self {
            Effect::Bias => "bias",
            Effect::ScaleFactorError => "scale_factor_error",
            Effect::ScaleFactorAsymmetry => "scale_factor_asymmetry",
            Effect::ScaleFactorTemperature => "scale_factor_temperature",
            Effect::ScaleFactorKnee => "scale_factor_knee",
            Effect::VibrationRectification => "vibration_rectification",
            Effect::LockIn => "lock_in",
            Effect::ThermalDifference => "thermal_difference",
            Effect::ThermalGradient => "thermal_gradient",
            Effect::ThermalDifferenceSquared => "thermal_difference_squared",
            Effect::CaseTemperature => "case_temperature",
            Effect::WarmUp => "warm_up",
            Effect::BiasTemperature => "bias_temperature",
            Effect::Shupe => "shupe",
            Effect::BiasTemperatureRate => "bias_temperature_rate",
        }
    }

    /// The names of `effects` joined by `sep`.
    pub fn names(effects: &[Effect], sep: &str) -> String {
        effects
            .iter()
            .map(|e| e.name())
            .collect::<Vec<_>>()
            .join(sep)
    }

    pub fn from_name(s: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|e| e.name() == s)
    }

    /// Whether `param` is the knee temperature, a parameter judged in
    /// degC rather than relative to its value.
    pub fn is_knee_temperature(param: &str) -> bool {
        Effect::ScaleFactorKnee.nonlinear_param() == Some(param)
    }

    /// The effects of each gyro's physics (the module's table).
    pub fn applies_to(self, g: GyroKind) -> bool {
        use GyroKind::*;
        match self {
            Effect::LockIn
            | Effect::ThermalDifference
            | Effect::ThermalGradient
            | Effect::ThermalDifferenceSquared
            | Effect::CaseTemperature => g == Rlg,
            Effect::VibrationRectification | Effect::Shupe => g == Fog,
            Effect::BiasTemperature => g == Fog || g == Mems,
            Effect::BiasTemperatureRate => g == Mems,
            Effect::ScaleFactorKnee => g != Mems,
            Effect::Bias
            | Effect::ScaleFactorError
            | Effect::ScaleFactorAsymmetry
            | Effect::ScaleFactorTemperature
            | Effect::WarmUp => true,
        }
    }

    /// Effects that scale with the input rate: a run that never turns
    /// (the input is only the Earth-rate component) cannot show them,
    /// whatever a fit says (physics.md 1.6: at rest a temperature-shaped
    /// bias is a bias, not a scale factor).
    pub fn needs_rotation(self) -> bool {
        matches!(
            self,
            Effect::ScaleFactorError
                | Effect::ScaleFactorAsymmetry
                | Effect::ScaleFactorTemperature
                | Effect::ScaleFactorKnee
                | Effect::LockIn
        )
    }

    /// Free parameters (linear and non-linear).
    pub fn dof(self) -> usize {
        self.linear_params().len() + usize::from(self.nonlinear_param().is_some())
    }

    /// Linear parameters, in the order of the basis columns.
    pub fn linear_params(self) -> &'static [&'static str] {
        match self {
            Effect::Bias => &["bias_dph"],
            Effect::ScaleFactorError => &["error_ppm"],
            Effect::ScaleFactorAsymmetry => &["asymmetry_ppm"],
            Effect::ScaleFactorTemperature => &["ppm_per_c"],
            Effect::ScaleFactorKnee => &["slope_change_ppm_per_c"],
            Effect::VibrationRectification => &["dph_per_dps2_sq"],
            Effect::LockIn => &[],
            Effect::ThermalDifference => &["dph_per_c"],
            Effect::ThermalGradient => &["dph_per_c_per_s"],
            Effect::ThermalDifferenceSquared => &["dph_per_c2"],
            Effect::CaseTemperature => &["dph_per_c"],
            Effect::WarmUp => &["amplitude_dph"],
            Effect::BiasTemperature => &["dph_per_c"],
            Effect::Shupe | Effect::BiasTemperatureRate => &["dph_per_c_per_s"],
        }
    }

    /// The non-linear parameter, found by search.
    pub fn nonlinear_param(self) -> Option<&'static str> {
        match self {
            Effect::ScaleFactorKnee => Some("knee_c"),
            Effect::LockIn => Some("lock_in_dps"),
            Effect::WarmUp => Some("tau_s"),
            _ => None,
        }
    }

    /// Every parameter name, linear first.
    pub fn params(self) -> Vec<&'static str> {
        let mut v = self.linear_params().to_vec();
        v.extend(self.nonlinear_param());
        v
    }

    /// The run columns the effect needs, and whether `inp` has them.
    pub fn needs(self) -> &'static [Column] {
        match self {
            Effect::ScaleFactorTemperature
            | Effect::ScaleFactorKnee
            | Effect::BiasTemperature
            | Effect::Shupe
            | Effect::BiasTemperatureRate => &[Column::Temp],
            Effect::ThermalDifference
            | Effect::ThermalGradient
            | Effect::ThermalDifferenceSquared => &[Column::MonoA, Column::MonoB],
            Effect::CaseTemperature => &[Column::Case],
            _ => &[],
        }
    }

    pub fn available(self, inp: &Inputs) -> bool {
        match self {
            Effect::ScaleFactorTemperature
            | Effect::ScaleFactorKnee
            | Effect::BiasTemperature
            | Effect::Shupe
            | Effect::BiasTemperatureRate => inp.temp.is_some(),
            Effect::ThermalDifference
            | Effect::ThermalGradient
            | Effect::ThermalDifferenceSquared => inp.dt.is_some(),
            Effect::CaseTemperature => inp.case.is_some(),
            _ => true,
        }
    }

    /// The basis at non-linear parameter `x` (ignored by effects without
    /// one). Call only when [`Self::available`].
    pub fn basis(self, inp: &Inputs, x: f64) -> Basis {
        let w = &inp.w;
        let n = inp.len();
        let col = |f: &dyn Fn(usize) -> f64| -> Vec<f64> { (0..n).map(f).collect() };
        let zeros = vec![0.0; n];
        let temp = inp.temp.as_ref().unwrap_or(&zeros);
        let dt = inp.dt.as_ref().unwrap_or(&zeros);
        let cols = match self {
            Effect::Bias => vec![vec![DPH; n]],
            Effect::ScaleFactorError => vec![col(&|k| PPM * w[k])],
            Effect::ScaleFactorAsymmetry => vec![col(&|k| 0.5 * PPM * w[k].abs())],
            Effect::ScaleFactorTemperature => vec![col(&|k| PPM * w[k] * (temp[k] - 20.0))],
            Effect::ScaleFactorKnee => vec![col(&|k| PPM * w[k] * (temp[k] - x).max(0.0))],
            Effect::VibrationRectification => vec![col(&|k| DPH * inp.acc[k] * inp.acc[k])],
            Effect::LockIn => vec![],
            Effect::ThermalDifference => vec![col(&|k| DPH * dt[k])],
            Effect::ThermalGradient => {
                let g = inp.grad.as_ref().unwrap_or(&zeros);
                vec![col(&|k| DPH * g[k])]
            }
            Effect::ThermalDifferenceSquared => vec![col(&|k| DPH * dt[k] * dt[k])],
            Effect::CaseTemperature => {
                let c = inp.case.as_ref().unwrap_or(&zeros);
                vec![col(&|k| DPH * (c[k] - 20.0))]
            }
            Effect::WarmUp => vec![col(&|k| DPH * (1.0 - (-inp.t[k] / x.max(1e-9)).exp()))],
            Effect::BiasTemperature => vec![col(&|k| DPH * (temp[k] - 20.0))],
            Effect::Shupe | Effect::BiasTemperatureRate => {
                let g = inp.temp_rate.as_ref().unwrap_or(&zeros);
                vec![col(&|k| DPH * g[k])]
            }
        };
        let offset = (self == Effect::LockIn).then(|| col(&|k| lock_in_output(w[k], x) - w[k]));
        Basis { cols, offset }
    }

    /// The effect's contribution, deg/s, with its parameters by name.
    pub fn contribution(
        self,
        inp: &Inputs,
        params: &std::collections::BTreeMap<String, f64>,
    ) -> Vec<f64> {
        let x = self
            .nonlinear_param()
            .and_then(|p| params.get(p).copied())
            .unwrap_or(0.0);
        let b = self.basis(inp, x);
        let mut out = b.offset.unwrap_or_else(|| vec![0.0; inp.len()]);
        for (name, c) in self.linear_params().iter().zip(&b.cols) {
            let p = params.get(*name).copied().unwrap_or(0.0);
            for (o, v) in out.iter_mut().zip(c) {
                *o += p * v;
            }
        }
        out
    }

    /// Search grid of the non-linear parameter on this run.
    pub fn search_grid(self, inp: &Inputs) -> Vec<f64> {
        let log = |a: f64, b: f64, n: usize| -> Vec<f64> {
            (0..n)
                .map(|i| (a.ln() + (b.ln() - a.ln()) * i as f64 / (n - 1) as f64).exp())
                .collect()
        };
        match self {
            Effect::ScaleFactorKnee => {
                // Inside the rotating rows' temperatures, 3 degC from the ends.
                let temp = inp.temp.as_deref().unwrap_or(&[]);
                let (lo, hi) = (0..inp.len())
                    .filter(|&k| inp.w[k].abs() >= 1.0)
                    .map(|k| temp[k])
                    .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), t| {
                        (a.min(t), b.max(t))
                    });
                // 1 degC apart; golden section refines between.
                let mut g = vec![];
                let mut t = lo + 3.0;
                while t <= hi - 3.0 {
                    g.push(t);
                    t += 1.0;
                }
                g
            }
            Effect::WarmUp => {
                // From 2 minutes (a gyro warms up over minutes to hours; a
                // shorter warm-up is a bias after its first minutes, and
                // reads as one) to the record's length: a warm-up must
                // settle inside the record to be told from a drift
                // (ranges.rs).
                let span = inp.t.last().copied().unwrap_or(1.0).max(240.0);
                log(120.0, span, 28)
            }
            Effect::LockIn => {
                let wmax = inp.w.iter().fold(0.0f64, |a, x| a.max(x.abs()));
                log(1e-3, wmax.clamp(0.01, 10.0), 40)
            }
            _ => vec![0.0],
        }
    }

    /// Whether the non-linear parameter is searched in logarithm (positive,
    /// spanning decades).
    pub fn search_log(self) -> bool {
        matches!(self, Effect::WarmUp | Effect::LockIn)
    }
}

/// An effect reads and writes as its name.
impl std::fmt::Display for Effect {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl serde::Serialize for Effect {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(self.name())
    }
}

/// The rate an RLG indicates near lock-in: its beat, K sqrt(W^2 - W_L^2)
/// (docs/rlg.md), with the input's sign; zero inside the lock band.
pub fn lock_in_output(w: f64, w_l: f64) -> f64 {
    let a = w.abs();
    if a <= w_l {
        0.0
    } else {
        w.signum() * (a * a - w_l * w_l).sqrt()
    }
}
