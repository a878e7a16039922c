//! The FOG scale-factor table in fixed point (fog/scale_factor.rs) against
//! its floating-point model (`ScaleFactorTable::eval`), the coil-sensor lead
//! against a simulated lagging sensor, and the fault paths.

use gyro_coeffs::fog_scale_factor::MAX_NODES;
use gyro_sim::CoilThermal;
use gyro_sp::fog::scale_factor::{
    FogTempFlags, ScaleFactorComp, ScaleFactorConfig, ScaleFactorTable, LEAD_FILTER_TAU_S,
};
use gyro_sp::fog::{FogConfig, FogParams};
use proptest::prelude::*;

fn fog() -> FogConfig {
    FogConfig::new(FogParams::default()).unwrap()
}

/// A table like the fitted one: a knee at 48 degC, the bias rising.
fn table() -> ScaleFactorTable {
    ScaleFactorTable::from_nodes(
        &[-40.0, 48.0, 60.0],
        &[60.0, 192.0, 282.0],
        &[0.15, 0.49, 0.53],
        30.0,
    )
}

/// A comp that has read `t_c` (no lead: a steady temperature).
fn at(cfg: &ScaleFactorConfig, t_c: f64) -> ScaleFactorComp {
    let mut c = ScaleFactorComp::default();
    for _ in 0..3 {
        c.update_temperature(cfg, Some((t_c * 256.0).round() as i32));
    }
    c
}

/// Frame-angle LSB of a rate (deg/s) over `steps` closure steps.
fn angle(fog: &FogConfig, rate_dps: f64, steps: u16) -> f64 {
    rate_dps.to_radians() * steps as f64 * fog.closure_period_s() / fog.rad_per_angle_lsb()
}

#[test]
fn compensation_inverts_the_model() {
    // Output y = (1 + sf(T)) w + b(T) over a frame; compensated, w comes back
    // to the multiply's precision (2^-32) and the bias's Q16 deg/h.
    let fog = fog();
    let t = table();
    let cfg = ScaleFactorConfig::new(&t, &fog, 1.0);
    for &tc in &[-40.0, -12.3, 20.0, 47.9, 48.0, 48.1, 55.5, 60.0] {
        let comp = at(&cfg, tc);
        let (sf, b, out) = t.eval(((tc * 256.0_f64).round()) / 256.0);
        assert!(!out, "{tc} inside the calibrated range");
        for &w in &[50.0, -100.0, 500.0, 0.0] {
            let y = w * (1.0 + sf * 1e-6) + b / 3600.0;
            let steps = 25;
            let (c, words) = comp.compensate(&cfg, angle(&fog, y, steps).round() as i64, steps);
            let want = angle(&fog, w, steps);
            // Bias Q16 deg/h: 1/65536 deg/h of error at most (about 1 LSB
            // per 2^16 of the per-step angle), the table's interpolation of
            // 1/(1+sf) under 1e-8.
            let tol = 1e-8 * want.abs() + angle(&fog, 2.0 / 65_536.0 / 3600.0, steps) + 2.0;
            assert!(
                (c as f64 - want).abs() <= tol,
                "T {tc} w {w}: {c} vs {want} (tol {tol})"
            );
            assert_eq!(words.flags, FogTempFlags::empty());
            assert_eq!(words.t_coil_q8 as i32, (tc * 256.0_f64).round() as i32);
            let corr = words.sf_corr_q32 as f64 / 4_294_967_296.0;
            assert!(
                (corr - (1.0 / (1.0 + sf * 1e-6) - 1.0)).abs() < 1e-8,
                "{corr}"
            );
        }
    }
}

#[test]
fn clamped_outside_the_calibrated_range_and_flagged() {
    let fog = fog();
    let t = table();
    let cfg = ScaleFactorConfig::new(&t, &fog, 1.0);
    for (tc, node) in [(-50.0, 0usize), (75.0, 2)] {
        let comp = at(&cfg, tc);
        let (_, w) = comp.compensate(&cfg, 1 << 40, 25);
        assert_eq!(w.flags, FogTempFlags::OUT_OF_RANGE, "{tc}");
        let g = 1.0 / (1.0 + t.sf_ppm[node] * 1e-6) - 1.0;
        assert!((w.sf_corr_q32 as f64 / 4_294_967_296.0 - g).abs() < 1e-9);
        assert_eq!(w.bias_q16_dph, (t.bias_dph[node] * 65_536.0).round() as i32);
    }
}

#[test]
fn lead_recovers_the_coil_temperature_from_a_lagging_sensor() {
    // The coil ramps at 1 degC/min; its sensor lags 30 s (1 degC/2 behind).
    // With the table's lag the estimate is the coil's to the filter's
    // settling; without it, 0.5 degC behind.
    let fog = fog();
    let cfg = ScaleFactorConfig::new(&table(), &fog, 1.0);
    let no_lead = ScaleFactorConfig::new(
        &ScaleFactorTable {
            sensor_lag_s: 0.0,
            ..table()
        },
        &fog,
        1.0,
    );
    let mut th = CoilThermal::new(0.0);
    th.tau_sensor_s = 30.0;
    let (mut a, mut b) = (ScaleFactorComp::default(), ScaleFactorComp::default());
    let rate = 1.0 / 60.0;
    let mut worst_late = 0.0f64;
    for k in 1..=3600 {
        let coil = rate * k as f64;
        let s = th.step_coil(1.0, coil);
        let read = Some((s * 256.0).round() as i32);
        a.update_temperature(&cfg, read);
        b.update_temperature(&no_lead, read);
        if k as f64 > 10.0 * LEAD_FILTER_TAU_S {
            let ea = a.coil_q8().unwrap() as f64 / 256.0 - coil;
            let eb = b.coil_q8().unwrap() as f64 / 256.0 - coil;
            worst_late = worst_late.max(ea.abs());
            assert!((eb + 0.5).abs() < 0.01, "no lead: {eb}");
        }
    }
    // 1/256 degC rounding of the reads and of the estimate.
    assert!(worst_late < 0.01, "lead error {worst_late} degC");
}

#[test]
fn bad_sensor_holds_and_flags() {
    let fog = fog();
    let cfg = ScaleFactorConfig::new(&table(), &fog, 1.0);
    let mut c = ScaleFactorComp::default();
    // Before any read: the middle of the calibrated range, flagged.
    let (_, w) = c.compensate(&cfg, 1 << 30, 25);
    assert_eq!(w.flags, FogTempFlags::COIL_SENSOR);
    assert_eq!(w.t_coil_q8 as i32, 10 * 256);
    c.update_temperature(&cfg, Some(30 * 256));
    assert_eq!(c.compensate(&cfg, 0, 25).1.flags, FogTempFlags::empty());
    // A failed read, then nonsense (above the TMP117's range): held, flagged.
    for read in [None, Some(200 * 256), Some(-60 * 256)] {
        c.update_temperature(&cfg, read);
        let (_, w) = c.compensate(&cfg, 0, 25);
        assert_eq!(w.flags, FogTempFlags::COIL_SENSOR, "{read:?}");
        assert_eq!(w.t_sensor_q8 as i32, 30 * 256);
    }
    // Back: cleared.
    c.update_temperature(&cfg, Some(31 * 256));
    assert_eq!(c.compensate(&cfg, 0, 25).1.flags, FogTempFlags::empty());
    // Stuck: the same value for STUCK_READS reads.
    for _ in 0..=gyro_sp::sensor::STUCK_READS {
        c.update_temperature(&cfg, Some(31 * 256));
    }
    assert_eq!(c.compensate(&cfg, 0, 25).1.flags, FogTempFlags::COIL_SENSOR);
}

#[test]
fn refused_table_compensates_nothing_and_flags() {
    let fog = fog();
    let wild = ScaleFactorTable {
        sensor_lag_s: -1.0,
        ..table()
    };
    let cfg = ScaleFactorConfig::new(&wild, &fog, 1.0);
    assert!(cfg.coeffs_refused);
    let comp = at(&cfg, 25.0);
    let (c, w) = comp.compensate(&cfg, 123_456_789_012, 25);
    assert_eq!(c, 123_456_789_012);
    assert_eq!(w.flags, FogTempFlags::COEFFS_REFUSED);
    // Out of order nodes, too many nodes, values beyond the fixed-point range.
    for bad in [
        ScaleFactorTable::from_nodes(&[10.0, 0.0], &[0.0, 0.0], &[0.0, 0.0], 0.0),
        {
            let too_many: Vec<f64> = (0..=MAX_NODES).map(|k| k as f64).collect();
            let zeros = vec![0.0; MAX_NODES + 1];
            ScaleFactorTable::from_nodes(&too_many, &zeros, &zeros, 0.0)
        },
        ScaleFactorTable::from_nodes(&[0.0, 10.0], &[30_000.0, 0.0], &[0.0, 0.0], 0.0),
        ScaleFactorTable::from_nodes(&[0.0, 10.0], &[0.0, 0.0], &[f64::NAN, 0.0], 0.0),
    ] {
        assert!(bad.check().is_err(), "{bad:?}");
        assert!(ScaleFactorTable::from_record(&bad.to_record()).is_err());
    }
    assert_eq!(
        ScaleFactorTable::from_record(&table().to_record()),
        Ok(table())
    );
}

proptest! {
    /// Any corrupted byte of the record is refused.
    #[test]
    fn corrupt_record_refused(pos in 0usize..gyro_coeffs::fog_scale_factor::RECORD_LEN, flip in 1u8..=255) {
        let mut r = table().to_record();
        r[pos] ^= flip;
        prop_assert!(ScaleFactorTable::from_record(&r).is_err());
        let cfg = ScaleFactorConfig::from_record(&r, &fog(), 1.0);
        prop_assert!(cfg.coeffs_refused);
    }

    /// The fixed-point lookup follows the floating-point table at any
    /// temperature (to its Q8 input) for any valid table.
    #[test]
    fn lookup_follows_the_model(
        t0 in -55.0f64..0.0,
        gaps in proptest::collection::vec(0.0f64..1.0, 1..MAX_NODES),
        spread in 1.0f64..40.0,
        sf in proptest::collection::vec(-20_000.0f64..20_000.0, MAX_NODES),
        bias in proptest::collection::vec(-1_000.0f64..1_000.0, MAX_NODES),
        t_q8 in -60 * 256i32..160 * 256,
    ) {
        let mut temps = vec![t0];
        // Gaps from 0.5 degC to 40 degC; with a small spread, tables of up
        // to the 64 nodes a tabulated polynomial takes.
        for g in &gaps {
            let next = temps[temps.len() - 1] + 0.5 + g * spread;
            if next > 150.0 { break; }
            temps.push(next);
        }
        let n = temps.len();
        // Node temperatures as the firmware holds them (Q8).
        let temps: Vec<f64> = temps.iter().map(|t| (t * 256.0).round() / 256.0).collect();
        let t = ScaleFactorTable::from_nodes(&temps, &sf[..n], &bias[..n], 0.0);
        prop_assume!(t.check().is_ok());
        let cfg = ScaleFactorConfig::new(&t, &fog(), 1.0);
        let (g, b, out) = cfg.lookup(t_q8);
        let (sf_m, b_m, out_m) = t.eval(t_q8 as f64 / 256.0);
        prop_assert_eq!(out, out_m);
        // Interpolating g = 1/(1+sf) instead of sf: g''/8 (d sf)^2 at most,
        // g'' = 2/(1+sf)^3, with d sf between two nodes.
        let g_m = 1.0 / (1.0 + sf_m * 1e-6) - 1.0;
        let i = temps.iter().rposition(|&x| x <= t_q8 as f64 / 256.0).unwrap_or(0).min(n.saturating_sub(2));
        let dsf = if n > 1 { (sf[i + 1] - sf[i]).abs() * 1e-6 } else { 0.0 };
        let bound = 2.0 / (1.0f64 - 0.02).powi(3) / 8.0 * dsf * dsf + 1e-9;
        prop_assert!((g as f64 / 4_294_967_296.0 - g_m).abs() < bound);
        prop_assert!((b as f64 / 65_536.0 - b_m).abs() < 1e-3);
    }

    /// Never panics, whatever the reads, angle and step count.
    #[test]
    fn never_panics(
        reads in proptest::collection::vec(proptest::option::of(any::<i32>()), 0..20),
        angle in any::<i64>(),
        steps in any::<u16>(),
    ) {
        let fog = fog();
        let cfg = ScaleFactorConfig::new(&table(), &fog, 1.0);
        let mut c = ScaleFactorComp::default();
        for r in reads {
            c.update_temperature(&cfg, r);
            let _ = c.compensate(&cfg, angle, steps);
        }
    }
}
