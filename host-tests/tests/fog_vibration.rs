//! Epsilon-squared vibration drift (docs/fog.md): the simulated drift against
//! the formula, and the online correction, on a representative subset of the
//! envelope of issue 23 (the whole table: `cargo lab bench eps2`).
//!
//! These use a 16-bit ADC: with the STM32's 12-bit ADC and no noise the
//! quantisation floor (about 0.01 deg/h) exceeds 1 % of the 1 000 deg/s^2 drift.

use gyro_sim::vibration_drift::{eps2_instrument, eps2_point, Eps2Point, EPS2_NOISE_SEED};
use gyro_sp::fog::FogParams;
use host_tests::*;
use std::f64::consts::PI;

/// Steps before measuring: five time constants of the DC filter (4 096 steps),
/// which sets the loop gain.
const SETTLE: u64 = 5 * 4_096;

const SEVEN_EIGHTHS: (f64, f64) = (0.875 * PI, 6_250.0);
const THREE_QUARTERS: (f64, f64) = (0.75 * PI, 12_500.0);

/// The subset: every instrument, latency and frequency, the accelerations
/// that average to a quarter of 1 % within seconds of simulated time
/// (5 000 deg/s^2 and up; the 1 000 deg/s^2 points need 2 000 to 35 000 s
/// each and stay in the bench). The weak point, 7pi/8 with latency
/// at 50 000 deg/s^2 (9 % left before), is in it at 60 and 200 Hz.
/// (instrument, DAC latency, Hz, deg/s^2)
const SUBSET: [((f64, f64), u32, f64, f64); 10] = [
    (SEVEN_EIGHTHS, 1, 60.0, 50_000.0),
    (SEVEN_EIGHTHS, 1, 200.0, 50_000.0),
    (SEVEN_EIGHTHS, 1, 20.0, 20_000.0),
    (SEVEN_EIGHTHS, 0, 20.0, 50_000.0),
    (SEVEN_EIGHTHS, 0, 200.0, 5_000.0),
    (THREE_QUARTERS, 0, 60.0, 50_000.0),
    (THREE_QUARTERS, 0, 20.0, 5_000.0),
    (THREE_QUARTERS, 1, 200.0, 20_000.0),
    (THREE_QUARTERS, 1, 60.0, 5_000.0),
    (THREE_QUARTERS, 0, 200.0, 50_000.0),
];

/// Each subset point averaged until the share left has a standard error of
/// at most a quarter of 1 % (gyro-sim's `eps2_point`): at most 1 % of the
/// formula's drift left by the correction, the loop gain within 1 % of
/// unity, and the uncorrected drift within 5 % of the formula (which holds
/// the DAC latency's doubling and the loop's lag at 200 Hz).
#[test]
fn correction_leaves_at_most_one_percent_on_the_subset() {
    let mut failures = Vec::new();
    for ((phi0, closure), latency, freq, eps) in SUBSET {
        let params = eps2_instrument(phi0, closure, latency);
        let p: Eps2Point =
            eps2_point(params, EPS2_NOISE_SEED, eps, freq, 0.0025, 600.0, |_| {}).unwrap();
        let d = p.drift;
        let at = format!(
            "{:.0}pi/8 {closure} Hz L{latency} {freq} Hz {eps} deg/s2",
            phi0 / PI * 8.0
        );
        println!(
            "{at}: formula {:.6} raw {:.6} ({:+.2} %) corrected {:.7} deg/h, left {:+.3} % +- {:.3} %, gain {:.4}, {:.0} s",
            p.formula_dph,
            d.raw_dph,
            p.raw_off_formula() * 100.0,
            d.corrected_dph,
            p.share_left() * 100.0,
            p.share_left_se() * 100.0,
            d.loop_gain,
            d.seconds
        );
        if p.share_left_se() > 0.0025 {
            failures.push(format!(
                "{at}: standard error {} not reached",
                p.share_left_se()
            ));
        }
        if p.share_left().abs() > 0.01 {
            failures.push(format!("{at}: {:+.3} % left", p.share_left() * 100.0));
        }
        if (d.loop_gain - 1.0).abs() > 0.01 {
            failures.push(format!("{at}: loop gain {}", d.loop_gain));
        }
        if p.raw_off_formula().abs() > 0.05 {
            failures.push(format!(
                "{at}: drift {:.5} vs formula {:.5}",
                d.raw_dph, p.formula_dph
            ));
        }
    }
    assert!(failures.is_empty(), "{failures:#?}");
}

/// Near the dark fringe (7pi/8) the residual's spread under vibration raises
/// the detector DC by A*|cos phi0|*<delta^2>/2: 12 % at 50 000 deg/s^2 and
/// 6.25 kHz. The AGC must not read that as more light, or the loop gain (and
/// with it the drift, by 1/g) moves. The measured residual against the true one
/// (from the simulated Sagnac phase and the feedback actually applied) stays
/// within 1 % of unit gain: the closure measures asin of the demodulated
/// residual and the AGC's DC moment holds the residual's and the spread's
/// terms to r^6 (0.9986 here).
#[test]
fn loop_gain_holds_under_vibration_near_dark_fringe() {
    let mut r = rig(
        eps2_instrument(0.875 * PI, 6_250.0, 0),
        |o| o.adc_bits = 16,
        vibration(50_000.0, 60.0),
    );
    let (a, b) = whole_periods(&r.cfg, 60.0, SETTLE, 1.0);
    let (ks, lsb) = (r.cfg.k_sagnac_s, gyro_sp::RAD_PER_PHASE_LSB);
    let (mut md, mut dd) = (0.0, 0.0);
    while r.closure_index() < b {
        let k = r.closure_index();
        let s = r.run_closure();
        if k >= a {
            let applied = (s.out.sagnac_phase - s.out.residual as i64) as f64 * lsb;
            let truth = ks * s.true_rate - applied;
            md += s.out.residual as f64 * lsb * truth;
            dd += truth * truth;
        }
    }
    let gain = md / dd;
    println!("measured/true residual gain {gain:.4}");
    assert!((gain - 1.0).abs() < 0.01, "residual gain {gain}");
}

/// With noise and no vibration the correction's mean is zero: the step's
/// residual and slope share samples, but the two halves' noise has the same
/// statistics, so their product has no mean. What it moves the mean output
/// by at rest stays at most 1e-5 deg/h (issue 23).
#[test]
fn correction_adds_no_drift_at_rest_with_noise() {
    for seed in [1, 2] {
        let mut r = rig(
            FogParams::default(),
            |o| {
                o.noise = true;
                o.seed = seed
            },
            gyro_sim::Profile::constant(0.0),
        );
        let m = mean_error(&mut r, 100, 100 + closures_in(5.0));
        let moved = m.corrected_dph - m.raw_dph;
        println!(
            "seed {seed}: correction moved the mean by {moved:e} deg/h (raw bias {:.4})",
            m.raw_dph
        );
        assert!(
            moved.abs() <= 1e-5,
            "correction moved the mean output by {moved} deg/h at rest"
        );
    }
}
