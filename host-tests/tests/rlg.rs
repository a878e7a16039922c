//! RLG core: pulse counting and thermal compensation against plain references.

use gyro_sp::rlg::coeffs::{CoeffError, RECORD_LEN};
use gyro_sp::rlg::thermal::{RlgFlags, ThermalConfig, STUCK_READS};
use gyro_sp::rlg::{PulseCounter, Temperatures, ThermalCoeffs, ThermalComp};
use proptest::prelude::*;

proptest! {
    /// Any sequence of count increments below 2^15 per read is recovered
    /// exactly from the wrapping 16-bit register: no count is lost.
    #[test]
    fn counter_loses_no_counts(start in any::<u16>(), steps in proptest::collection::vec(-32_767i32..=32_767, 1..500)) {
        let mut c = PulseCounter::default();
        let mut reg = start;
        let mut truth = 0i64;
        c.update(reg);
        for d in steps {
            reg = reg.wrapping_add(d as u16);
            truth += d as i64;
            prop_assert_eq!(c.update(reg), d);
        }
        prop_assert_eq!(c.angle_counts(), truth);
    }

    /// Any corrupted byte makes the record refused.
    #[test]
    fn corrupt_record_refused(pos in 0usize..RECORD_LEN, flip in 1u8..=255) {
        let mut r = coeffs().to_record();
        r[pos] ^= flip;
        prop_assert!(ThermalCoeffs::from_record(&r).is_err());
    }
}

fn coeffs() -> ThermalCoeffs {
    ThermalCoeffs {
        bias0_dph: 0.35,
        k1_dph_per_c: 0.08,
        k2_dph_per_c_per_s: 12.0,
        k3_dph_per_c2: -0.004,
        k4_dph_per_c: 0.0025,
        k5_dph: -0.2,
        tau_warm_s: 900.0,
    }
}

#[test]
fn record_round_trip_and_refusals() {
    let c = coeffs();
    assert_eq!(ThermalCoeffs::from_record(&c.to_record()), Ok(c));
    assert_eq!(
        ThermalCoeffs::from_record(&c.to_record()[..10]),
        Err(CoeffError::Corrupt)
    );
    let wild = ThermalCoeffs {
        k1_dph_per_c: f64::NAN,
        ..c
    };
    assert_eq!(
        ThermalCoeffs::from_record(&wild.to_record()),
        Err(CoeffError::Range)
    );
    let cfg = ThermalConfig::new(&wild, 0.125);
    let mut comp = ThermalComp::default();
    let t = Temperatures {
        mono_a_q8: Some(5000),
        mono_b_q8: Some(4900),
        case_q8: Some(6000),
    };
    assert_eq!(
        comp.update(&cfg, &t),
        0,
        "refused coefficients compensate nothing"
    );
    assert!(comp.flags().contains(RlgFlags::COEFFS_DEFAULT));
}

/// The fixed-point compensation follows the model evaluated in f64 (with the
/// same filtered differentiator and warm-up law) within 1e-4 deg/h over a
/// two-hour thermal ramp and cycle.
#[test]
fn compensation_matches_float_model() {
    let c = coeffs();
    let dt = 0.125;
    let cfg = ThermalConfig::new(&c, dt);
    let mut comp = ThermalComp::default();
    let (mut prev, mut grad) = (None::<f64>, 0.0f64);
    let a = dt / (gyro_sp::rlg::thermal::GRAD_TAU_S + dt);
    let mut worst = 0.0f64;
    for k in 0..(7200.0 / dt) as u64 {
        let t = k as f64 * dt;
        let ta = -20.0 + 60.0 * (t / 7200.0) + 0.5 * (t / 300.0).sin();
        let tb = ta - 0.8 * (t / 1000.0).cos();
        let tk = 10.0 + 30.0 * (t / 7200.0);
        let q8 = |x: f64| (x * 256.0).round() as i32;
        let reads = Temperatures {
            mono_a_q8: Some(q8(ta)),
            mono_b_q8: Some(q8(tb)),
            case_q8: Some(q8(tk)),
        };
        let b = comp.update(&cfg, &reads) as f64 / 65_536.0;
        // Reference in f64 on the same quantised reads.
        let (ta, tb, tk) = (
            q8(ta) as f64 / 256.0,
            q8(tb) as f64 / 256.0,
            q8(tk) as f64 / 256.0,
        );
        let d = ta - tb;
        let slope = prev.map_or(0.0, |p| (d - p) / dt);
        prev = Some(d);
        grad += a * (slope - grad);
        let warm = 1.0 - (-(k as f64 + 1.0) * dt / c.tau_warm_s).exp();
        let r = c.bias0_dph
            + c.k1_dph_per_c * d
            + c.k2_dph_per_c_per_s * grad
            + c.k3_dph_per_c2 * d * d
            + c.k4_dph_per_c * tk
            + c.k5_dph * warm;
        worst = worst.max((b - r).abs());
    }
    assert!(worst < 1e-4, "worst difference {worst} deg/h");
    assert_eq!(comp.flags(), RlgFlags::empty());
}

/// A sensor that stops answering, reads nonsense or sticks raises its flag;
/// the compensation holds its last good value and recovers when it returns.
#[test]
fn sensor_faults_flag_and_hold() {
    let cfg = ThermalConfig::new(&coeffs(), 0.125);
    let mut comp = ThermalComp::default();
    let good = |k: i32| Temperatures {
        mono_a_q8: Some(5000 + k),
        mono_b_q8: Some(4900 - k),
        case_q8: Some(6000 + k),
    };
    let mut b = 0;
    for k in 0..100 {
        b = comp.update(&cfg, &good(k));
    }
    assert_eq!(comp.flags(), RlgFlags::empty());
    // Case sensor NACKs: flagged, bias continues from its last good value.
    let mut t = good(100);
    t.case_q8 = None;
    let held = comp.update(&cfg, &t);
    assert!(comp.flags().contains(RlgFlags::SENSOR_CASE));
    assert!((held - b).abs() < 65_536 / 10, "bias jumped: {b} -> {held}");
    // Monoblock A reads nonsense (+300 degC): flagged.
    let mut t = good(101);
    t.mono_a_q8 = Some(300 * 256);
    comp.update(&cfg, &t);
    assert!(comp.flags().contains(RlgFlags::SENSOR_A));
    // Monoblock B sticks.
    for k in 0..=STUCK_READS as i32 {
        comp.update(
            &cfg,
            &Temperatures {
                mono_b_q8: Some(4800),
                ..good(102 + k)
            },
        );
    }
    assert!(comp.flags().contains(RlgFlags::SENSOR_B));
    // All good again.
    comp.update(&cfg, &good(300));
    assert_eq!(comp.flags(), RlgFlags::empty());
}

/// The frame words: the compensated rate is counts/(K*T) - B_TC (formula, in
/// f64) to the micro-deg/s word's resolution, for rates up to +-500 deg/s.
#[test]
fn channel_words_match_formula() {
    use gyro_sp::rlg::{RlgChannel, RlgConfig};
    let coeffs = ThermalCoeffs {
        bias0_dph: 0.5,
        k4_dph_per_c: 0.01,
        ..ThermalCoeffs::SAFE
    };
    let k = 8000.0;
    let cfg = RlgConfig::new(ThermalConfig::new(&coeffs, 0.1), k, 500);
    for &rate_dps in &[0.0, 1e-3, 15.0 / 3600.0, -123.456, 499.9] {
        let mut ch = RlgChannel::default();
        let temps = Temperatures {
            mono_a_q8: Some(20 * 256),
            mono_b_q8: Some(20 * 256),
            case_q8: Some(40 * 256),
        };
        let mut raw = 0u16;
        let mut angle = 0.0f64;
        ch.update(&cfg, 0, raw, Some(&temps));
        ch.take_frame();
        for _ in 0..100 {
            angle += rate_dps / 500.0 * k;
            raw = (angle.floor() as i64) as u16;
            ch.update(&cfg, 0, raw, None);
        }
        let span = ch.take_frame();
        let (counts, n) = (span.counts(), span.updates);
        let w = ch.words(&cfg, &span);
        let expect = counts as f64 / k / (n as f64 / 500.0) - (0.5 + 0.01 * 40.0) / 3600.0;
        assert!(
            (w.rate_comp_udps as f64 * 1e-6 - expect).abs() <= 1.5e-6,
            "{rate_dps}: {} vs {expect}",
            w.rate_comp_udps as f64 * 1e-6
        );
        assert_eq!(w.t_case_q8, 40 * 256);
    }
}
