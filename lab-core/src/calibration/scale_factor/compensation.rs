//! The firmware's scale-factor compensation (fog/scale_factor.rs, the same
//! code and fixed-point arithmetic) applied to a run: one coil sensor update
//! per row (period from `t_s`), then the row's angle increment compensated
//! as frames of its closure steps.

use super::input::each_sensor_update;
use gyro_coeffs::ScaleFactorTable;
use gyro_sp::fog::scale_factor::ScaleFactorComp;
use gyro_sp::fog::{FogConfig, FogParams};

const DEG: f64 = std::f64::consts::PI / 180.0;

/// The compensated rate (deg/s) and the flags of each row.
pub fn compensate_rows(
    table: &ScaleFactorTable,
    t: &[f64],
    rate_dps: &[f64],
    temp_c: &[f64],
) -> (Vec<f64>, Vec<u8>) {
    let fog = FogConfig::new(FogParams::default()).expect("reference FOG configuration");
    let lsb = fog.rad_per_angle_lsb();
    let dt_p = fog.closure_period_s();
    let mut comp = ScaleFactorComp::default();
    let (mut out, mut flags) = (Vec::with_capacity(t.len()), Vec::with_capacity(t.len()));
    let first = if t.len() > 1 { t[1] - t[0] } else { 1.0 };
    each_sensor_update(t, &fog, table, |k, cfg| {
        comp.update_temperature(cfg, Some((temp_c[k] * 256.0).round() as i32));
        let h = if k > 0 { t[k] - t[k - 1] } else { first };
        // The row as frames of at most 1 s of closure steps (the frame word
        // counts steps in a u16).
        let steps = (h / dt_p).round().max(1.0);
        let chunks = (steps / 12_500.0).ceil().max(1.0);
        let angle = rate_dps[k] * DEG * h / lsb / chunks;
        let mut sum = 0.0;
        let mut f = 0u8;
        for _ in 0..chunks as usize {
            let (a, w) =
                comp.compensate(cfg, angle.round() as i64, (steps / chunks).round() as u16);
            sum += a as f64;
            f |= w.flags.bits();
        }
        out.push(sum * lsb / DEG / h);
        flags.push(f);
    });
    (out, flags)
}
