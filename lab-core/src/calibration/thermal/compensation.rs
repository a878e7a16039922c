//! The firmware's RLG thermal compensation (rlg/thermal.rs, the same code
//! and fixed-point arithmetic) applied to a chamber run.

use super::fit::ThermalData;
use gyro_sp::rlg::thermal::{Temperatures, ThermalComp, ThermalConfig};
use gyro_sp::rlg::{compensate_rate_ndps, ThermalCoeffs};

/// B_TC per row by the firmware's own fixed-point compensation, one sensor
/// update per row (the period from `t_s`), F(tau) preset to the operating
/// time before the first row. Returns B_TC, Q16 deg/h, and flags.
pub fn firmware_bias(c: &ThermalCoeffs, d: &ThermalData) -> (Vec<i64>, Vec<u8>) {
    let n = d.t.len();
    let mut comp = ThermalComp::default();
    let first_dt = if n > 1 { d.t[1] - d.t[0] } else { 1.0 };
    comp.preset_operating_time(c, d.t[0] - first_dt);
    let q8 = |x: f64| Some((x * 256.0).round() as i32);
    let mut cfg = ThermalConfig::new(c, first_dt);
    let mut cfg_dt = first_dt;
    let (mut bias, mut flags) = (Vec::with_capacity(n), Vec::with_capacity(n));
    for k in 0..n {
        let h = if k > 0 { d.t[k] - d.t[k - 1] } else { first_dt };
        if (h - cfg_dt).abs() > 1e-9 * cfg_dt {
            cfg = ThermalConfig::new(c, h);
            cfg_dt = h;
        }
        let b = comp.update(
            &cfg,
            &Temperatures {
                mono_a_q8: q8(d.a[k]),
                mono_b_q8: q8(d.b[k]),
                case_q8: q8(d.case[k]),
            },
        );
        bias.push(b);
        flags.push(comp.flags().bits());
    }
    (bias, flags)
}

/// The run's rate (deg/s) compensated as the firmware does, and the sensor
/// flags of each row.
pub fn compensate(c: &ThermalCoeffs, d: &ThermalData, rate_dps: &[f64]) -> (Vec<f64>, Vec<u8>) {
    let (bias, flags) = firmware_bias(c, d);
    let comp = rate_dps
        .iter()
        .zip(&bias)
        .map(|(r, b)| compensate_rate_ndps((r * 1e9).round() as i64, *b) as f64 * 1e-9)
        .collect();
    (comp, flags)
}
