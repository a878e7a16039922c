//! Epsilon-squared vibration drift (docs/fog.md): the simulated drift against
//! the formula, and the online correction.
//!
//! These use a 16-bit ADC: with the STM32's 12-bit ADC and no noise the
//! quantisation floor (about 0.01 deg/h) exceeds 5 % of the 1 000 deg/s^2 drift.

use gyro_sp::fog::FogParams;
use host_tests::*;
use std::f64::consts::PI;

/// The 16-bit ADC's depth dither spans 240 codes (+-0.012 rad at 3pi/4, a
/// quarter of the 12-bit default's +-0.05 rad). At 1 000 deg/s^2 the drift
/// is a twentieth of an ADC code per step; the default 60 codes left a
/// rounding artefact of -0.001 deg/h (-11 %) at 20 Hz, 240 codes leave none
/// above the standard error.
fn instrument(phi0: f64, closure: f64) -> FogParams {
    FogParams {
        phi0_rad: phi0,
        closure_hz: closure,
        vibration_correction: true,
        dither_adc_codes: 240.0,
        ..FogParams::default()
    }
}

/// Steps before measuring: five time constants of the DC filter (4 096 steps),
/// which sets the loop gain.
const SETTLE: u64 = 5 * 4_096;

/// The two reference instruments: (phi0, closure rate).
const INSTRUMENTS: [(f64, f64); 2] = [(0.75 * PI, 12_500.0), (0.875 * PI, 6_250.0)];

/// Formula drift and the measured drift (deg/h), the raw mean to a standard
/// error of 0.5 % of the formula, or 15 simulated minutes (the 1 000 deg/s^2
/// points stop there, near 1.5 %).
fn drift(params: FogParams, eps: f64, freq: f64) -> (f64, Drift) {
    let (phi0, closure) = (params.phi0_rad, params.closure_hz);
    let mut r = rig(params, |o| o.adc_bits = 16, vibration(eps, freq));
    let formula = r.cfg.predicted_vibration_drift((eps * DEG).powi(2) / 2.0) * DPH;
    let d = vibration_drift(&mut r, freq, SETTLE, 0.005 * formula.abs(), (2.0, 900.0));
    println!(
        "phi0 {phi0:.4} {closure} Hz closure, {freq} Hz, eps {eps}: formula {formula:.5} raw {:.5} +- {:.5} ({:+.2} %) corrected {:.5} ({:+.2} %) deg/h over {:.0} s",
        d.raw_dph,
        d.raw_se_dph,
        (d.raw_dph / formula - 1.0) * 100.0,
        d.corrected_dph,
        d.corrected_dph / formula * 100.0,
        d.seconds
    );
    assert!(
        d.raw_se_dph < 0.02 * formula.abs(),
        "eps {eps}: standard error {} too large to test 5 %",
        d.raw_se_dph
    );
    (formula, d)
}

/// One test point: the drift within 5 % of the formula (when `raw_too`) and
/// at least 95 % of it removed by the correction; what fails goes into
/// `failures`.
fn check(params: FogParams, eps: f64, freq: f64, raw_too: bool, failures: &mut Vec<String>) {
    let (f, d) = drift(params, eps, freq);
    let at = format!("{freq} Hz phi0 {:.3} eps {eps}", params.phi0_rad);
    if raw_too && (d.raw_dph / f - 1.0).abs() > 0.05 {
        failures.push(format!("{at}: drift {:.5} vs formula {f:.5}", d.raw_dph));
    }
    if d.corrected_dph.abs() > 0.05 * f {
        failures.push(format!("{at}: corrected {:.5} of {f:.5}", d.corrected_dph));
    }
}

/// Both reference instruments over 1 000 .. 50 000 deg/s^2 at 60 Hz: the
/// drift within 5 % of the formula, at least 95 % of it removed by the
/// correction. Each point is averaged until its standard error is small
/// against 5 % (3pi/4 at 1 000 deg/s^2 averages 15 minutes).
#[test]
fn drift_matches_formula_and_correction_removes_it() {
    let mut failures = Vec::new();
    for (phi0, closure) in INSTRUMENTS {
        for eps in [1_000.0, 5_000.0, 20_000.0, 50_000.0] {
            check(instrument(phi0, closure), eps, 60.0, true, &mut failures);
        }
    }
    assert!(failures.is_empty(), "{failures:#?}");
}

/// The correction at 20 Hz and 200 Hz still removes at least 95 % of the
/// drift: both instruments at 1 000, 5 000 and 50 000 deg/s^2. It inverts
/// each step's own measurement, so the loop's lag at 200 Hz (w*dt_p = 0.2 at
/// 6.25 kHz) does not enter.
#[test]
fn correction_works_at_20_and_200_hz() {
    let mut failures = Vec::new();
    for freq in [20.0, 200.0] {
        for (phi0, closure) in INSTRUMENTS {
            for eps in [1_000.0, 5_000.0, 50_000.0] {
                check(instrument(phi0, closure), eps, freq, false, &mut failures);
            }
        }
    }
    assert!(failures.is_empty(), "{failures:#?}");
}

/// The hw board's DMA ping-pong applies the words one step later
/// (`dac_latency = 1`). The loop then lags a rate ramp by 1/g + 1 steps
/// instead of 1/g, so the drift doubles at unit gain
/// (`FogConfig::predicted_vibration_drift`); the correction, which inverts
/// each step's own measurement, needs no change. Both instruments, 60 Hz and
/// 200 Hz, 5 000 deg/s^2 up to 50 000 (3pi/4) or 20 000 (7pi/8): the drift
/// within 5 % of the derived formula at 60 Hz, at least 95 % of it removed.
/// Not at 7pi/8 and 50 000 deg/s^2: the doubled residual reaches 0.40 rad,
/// where the AGC's second-order model of the residual's DC (from the
/// compressed measured residual) sets the loop gain 4.6 % low (0.992 without
/// latency): measured drift +9.5 % off the formula, 9.0 % left by the
/// correction. The hw build runs 3pi/4 at 12.5 kHz.
#[test]
fn dac_latency_doubles_the_drift_and_the_correction_removes_it() {
    let mut failures = Vec::new();
    for (phi0, closure) in INSTRUMENTS {
        let top = if phi0 > 0.8 * PI { 20_000.0 } else { 50_000.0 };
        for (freq, eps) in [(60.0, 5_000.0), (60.0, top), (200.0, top)] {
            let params = FogParams {
                dac_latency: 1,
                ..instrument(phi0, closure)
            };
            check(params, eps, freq, freq < 100.0, &mut failures);
        }
    }
    assert!(failures.is_empty(), "{failures:#?}");
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
        instrument(0.875 * PI, 6_250.0),
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
    assert!((gain - 1.0).abs() < 0.025, "residual gain {gain}");
}

/// With noise and no vibration the correction's mean is zero: the step's
/// residual and slope share samples, but the two halves' noise has the same
/// statistics, so their product has no mean.
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
            moved.abs() < 1e-3,
            "correction moved the mean output by {moved} deg/h at rest"
        );
    }
}
