//! What each effect's parameters can be: the domain (where the formula
//! means something: a time constant is positive, a knee lies inside the
//! temperatures the run covers), which a model file must respect, and the
//! physical range, outside which a fit is not that effect but something
//! the library has no name for imitating it (docs/discovery.md). The
//! ranges below are a navigation-grade gyro's; a coarser grade (grade.rs)
//! widens them: the bias-like effects (bias, monoblock and case terms,
//! warm-up amplitude, bias over temperature and its rate, Shupe) by its
//! bias factor (10, 100, 1000), the scale-factor effects (error,
//! asymmetry, temperature, knee slope) and rectification by its
//! scale-factor factor (4, 10, 20). Lock-in and the warm-up's time
//! constant do not scale.
//!
//! | effect | parameter | navigation range | why |
//! |---|---|---|---|
//! | bias | bias_dph | +-1000 | a gyro biased by more than a quarter deg/s is broken, not drifting |
//! | scale_factor_error | error_ppm | +-5000 | the nominal scale factor is known to better than 0.5 % (L D / lambda) |
//! | scale_factor_asymmetry | asymmetry_ppm | +-2000 | a closed loop's asymmetry is ppm to hundreds of ppm |
//! | scale_factor_temperature | ppm_per_c | +-200 | L D and an unstabilised source's wavelength: tens of ppm/degC; thousands is not a FOG |
//! | scale_factor_knee | slope_change_ppm_per_c | +-200 | as the slope |
//! | vibration_rectification | dph_per_dps2_sq | +-1e-6 | the eps^2 term (docs/fog.md) is 1e-8 at the reference loop; sixty times that at most |
//! | lock_in | lock_in_dps | 0 .. 2 | RLG lock-in rates are 0.01 .. 0.5 deg/s |
//! | thermal_difference | dph_per_c | +-2 | 0.6 .. 0.7 deg/h over -40 .. +50 degC in all (docs/rlg.md) |
//! | thermal_gradient | dph_per_c_per_s | +-2000 | |
//! | thermal_difference_squared | dph_per_c2 | +-1 | |
//! | case_temperature | dph_per_c | +-0.5 | |
//! | warm_up | amplitude_dph | +-20 | |
//! | warm_up | tau_s | 60 .. the record | a time constant longer than the record is a drift, not a warm-up |
//! | bias_temperature | dph_per_c | +-5 | a coil's bias over temperature (physics.md 1.6) |
//! | shupe | dph_per_c_per_s | +-5000 | a quadrupolar 1 km coil: tens of deg/h per degC/s |
//! | bias_temperature_rate | dph_per_c_per_s | +-5000 | as the Shupe bias (a MEMS gyro's is its package's gradient) |
//!
//! Domains: `tau_s` > 0, `lock_in_dps` >= 0, `knee_c` inside the
//! temperatures the run covers (where the run has them); every other
//! parameter any finite number.

use super::effects::Effect;
use super::grade::Grade;

/// What a run covers, for the ranges that depend on it, and the grade of
/// the gyro its ranges are judged at.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Extent {
    /// Length of the record, s.
    pub record_s: f64,
    /// Lowest and highest main temperature (where the run has one), degC.
    pub temp_c: Option<(f64, f64)>,
    pub grade: Grade,
}

/// The physical range of `param` of `e` on a run of extent `x`: None where
/// any value is plausible.
pub fn physical(e: Effect, param: &str, x: &Extent) -> Option<(f64, f64)> {
    let b = x.grade.bias_factor();
    let s = x.grade.scale_factor_factor();
    let sym = |a: f64| Some((-a, a));
    match (e, param) {
        (Effect::Bias, _) => sym(1000.0 * b),
        (Effect::ScaleFactorError, _) => sym(5000.0 * s),
        (Effect::ScaleFactorAsymmetry, _) => sym(2000.0 * s),
        (Effect::ScaleFactorTemperature, _) => sym(200.0 * s),
        (Effect::ScaleFactorKnee, "slope_change_ppm_per_c") => sym(200.0 * s),
        (Effect::VibrationRectification, _) => sym(1e-6 * s),
        (Effect::LockIn, _) => Some((0.0, 2.0)),
        (Effect::ThermalDifference, _) => sym(2.0 * b),
        (Effect::ThermalGradient, _) => sym(2000.0 * b),
        (Effect::ThermalDifferenceSquared, _) => sym(1.0 * b),
        (Effect::CaseTemperature, _) => sym(0.5 * b),
        (Effect::WarmUp, "amplitude_dph") => sym(20.0 * b),
        (Effect::WarmUp, "tau_s") => Some((60.0, x.record_s.max(60.0))),
        (Effect::BiasTemperature, _) => sym(5.0 * b),
        (Effect::Shupe | Effect::BiasTemperatureRate, _) => sym(5000.0 * b),
        _ => None,
    }
}

/// Why `value` of `param` of `e` is outside the formula's domain (on a run
/// of extent `x`, where known), or None.
pub fn domain_error(e: Effect, param: &str, value: f64, x: Option<&Extent>) -> Option<String> {
    if !value.is_finite() {
        return Some(format!("`{param}` is not a finite number"));
    }
    match (e, param) {
        (Effect::WarmUp, "tau_s") if value <= 0.0 => Some(format!(
            "`tau_s` = {value}: a time constant must be positive"
        )),
        (Effect::LockIn, "lock_in_dps") if value < 0.0 => Some(format!(
            "`lock_in_dps` = {value}: a lock-in rate is not negative"
        )),
        (Effect::ScaleFactorKnee, "knee_c") => {
            let (lo, hi) = x?.temp_c?;
            (value < lo || value > hi).then(|| {
                format!(
                    "`knee_c` = {value} degC: outside the temperatures this run covers ({lo:.2} .. {hi:.2} degC)"
                )
            })
        }
        _ => None,
    }
}

/// The parameters of a fit outside their physical range: (name, value,
/// range).
pub fn outside(e: Effect, params: &[(&str, f64)], x: &Extent) -> Vec<(String, f64, (f64, f64))> {
    params
        .iter()
        .filter_map(|&(p, v)| {
            let r = physical(e, p, x)?;
            (v < r.0 || v > r.1).then(|| (p.to_owned(), v, r))
        })
        .collect()
}
