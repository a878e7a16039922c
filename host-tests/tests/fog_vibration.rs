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
    let se_target = 0.005 * formula.abs();
    let d = vibration_drift(&mut r, freq, SETTLE, |d| {
        (d.blocks >= 8 && d.seconds >= 2.0 && d.raw_se_dph < se_target) || d.seconds >= 900.0
    });
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

/// The eps^2 table over the whole envelope (48 points), for the record:
/// `cargo test --profile host-test -p host-tests --test fog_vibration --
/// --ignored eps2_table --nocapture`. EPS2_SE (share-left standard error
/// target, default 0.0025), EPS2_MAX_S (simulated seconds per point at
/// most, default 1e5), EPS2_THREADS (default 1), EPS2_ONLY (a substring of
/// the point's label, e.g. "1000 deg/s2") narrow it.
#[test]
#[ignore]
fn eps2_table() {
    use gyro_sim::vibration_drift::*;
    let env = |k: &str, d: f64| std::env::var(k).ok().and_then(|v| v.parse().ok()).unwrap_or(d);
    let se = env("EPS2_SE", 0.0025);
    let max_s = env("EPS2_MAX_S", 1e5);
    let threads = env("EPS2_THREADS", 1.0) as usize;
    let only = std::env::var("EPS2_ONLY").unwrap_or_default();
    let mut points = Vec::new();
    for (phi0, closure) in EPS2_INSTRUMENTS {
        for latency in EPS2_DAC_LATENCIES {
            for freq in EPS2_FREQUENCIES_HZ {
                for eps in EPS2_ACCELERATIONS_DPS2 {
                    let label = format!(
                        "{}pi/8 {closure} Hz L{latency} {freq} Hz {eps} deg/s2",
                        (phi0 / PI * 8.0).round()
                    );
                    if label.contains(&only) {
                        points.push((label, eps2_instrument(phi0, closure, latency), eps, freq));
                    }
                }
            }
        }
    }
    let queue = std::sync::Mutex::new(points.into_iter().enumerate().collect::<Vec<_>>());
    let results = std::sync::Mutex::new(Vec::new());
    let t0 = std::time::Instant::now();
    std::thread::scope(|s| {
        for _ in 0..threads.max(1) {
            s.spawn(|| loop {
                let Some((i, (label, params, eps, freq))) = queue.lock().unwrap().pop() else {
                    break;
                };
                let p = eps2_point(params, eps, freq, se, max_s, |_| {}).unwrap();
                let d = p.drift;
                println!(
                    "{label:<36} raw {:+.6} ({:+.2} %) formula {:+.6} corrected {:+.7} left {:+.3} % +- {:.3} % gain {:.4} {:.0} s [{:.0} s]",
                    d.raw_dph,
                    p.raw_off_formula() * 100.0,
                    p.formula_dph,
                    d.corrected_dph,
                    p.share_left() * 100.0,
                    p.share_left_se() * 100.0,
                    d.loop_gain,
                    d.seconds,
                    t0.elapsed().as_secs_f64()
                );
                results.lock().unwrap().push((i, label, p));
            });
        }
    });
    let mut results = results.into_inner().unwrap();
    results.sort_by_key(|r| r.0);
    println!("| point | uncorrected deg/h | formula deg/h | corrected deg/h | left % | SE % | loop gain | s |");
    println!("|---|---|---|---|---|---|---|---|");
    for (_, label, p) in &results {
        let d = p.drift;
        println!(
            "| {label} | {:.6} | {:.6} | {:.7} | {:+.3} | {:.3} | {:.4} | {:.0} |",
            d.raw_dph,
            p.formula_dph,
            d.corrected_dph,
            p.share_left() * 100.0,
            p.share_left_se() * 100.0,
            d.loop_gain,
            d.seconds
        );
    }
    let worst = results
        .iter()
        .map(|r| r.2.share_left().abs())
        .fold(0.0, f64::max);
    let worst_gain = results
        .iter()
        .map(|r| (r.2.drift.loop_gain - 1.0).abs())
        .fold(0.0, f64::max);
    println!(
        "{{\"points\": {}, \"worst_share_left\": {worst:.5}, \"worst_gain_error\": {worst_gain:.5}, \"seconds\": {:.1}}}",
        results.len(),
        t0.elapsed().as_secs_f64()
    );
}

/// Diagnostic (temporary): one point with optics knobs from the environment.
#[test]
#[ignore]
fn eps2_diag() {
    use gyro_sim::vibration_drift::*;
    let env = |k: &str, d: f64| std::env::var(k).ok().and_then(|v| v.parse().ok()).unwrap_or(d);
    let phi0 = env("PHI0_8", 7.0) * PI / 8.0;
    let closure = env("CLOSURE", 6250.0);
    let lat = env("LAT", 0.0) as u32;
    let eps = env("EPS", 50_000.0);
    let freq = env("FREQ", 60.0);
    let det = env("DET_TAU", 0.15e-6);
    let secs = env("SECS", 10.0);
    let mut p = eps2_instrument(phi0, closure, lat);
    p.dither_adc_codes = env("DITHER", 240.0);
    p.detector_tau_s = env("FW_DET_TAU", det);
    p.gain_loop_gain = env("GLG", 0.05);
    p.dac_codes_per_turn = env("CODES", 49_152.0) as u32;
    let power = env("POWER", 1.0);
    let delay = env("DELAY", 0.0);
    let prof = if delay > 0.0 {
        gyro_sim::Profile::new(&[
            gyro_sim::Segment::Constant { rate: 0.0, duration: delay },
            gyro_sim::Segment::Oscillation { offset: 0.0, eps_peak: eps * DEG, freq_hz: freq, duration: f64::INFINITY },
        ])
    } else {
        vibration(eps, freq)
    };
    let mut r = rig(p, |o| {o.adc_bits = 16; o.detector_tau_s = det; o.peak_lsb *= power}, prof);
    let formula = r.cfg.predicted_vibration_drift((eps * DEG).powi(2) / 2.0) * DPH;
    let chunk = env("CHUNK", 1e9);
    let mut next = chunk;
    let d = vibration_drift(&mut r, freq, EPS2_SETTLE_CLOSURES, |d| {
        if d.seconds >= next {
            println!("  {:.0} s: corrected {:.7} +- {:.7}", d.seconds, d.corrected_dph, d.corrected_se_dph);
            next += chunk;
        }
        d.seconds >= secs
    });
    println!("formula {formula:.6} raw {:.6} ({:+.3} %) corrected {:.7} +- {:.7} left {:+.3} % +- {:.3} gain {:.5}",
        d.raw_dph, (d.raw_dph / formula - 1.0) * 100.0, d.corrected_dph, d.corrected_se_dph, d.corrected_dph / formula * 100.0,
        d.corrected_se_dph / formula.abs() * 100.0, d.loop_gain);
}

/// Diagnostic (temporary): per-closure regression of the correction's
/// miss on candidate terms.
#[test]
#[ignore]
fn eps2_terms() {
    use gyro_sim::vibration_drift::*;
    let env = |k: &str, d: f64| std::env::var(k).ok().and_then(|v| v.parse().ok()).unwrap_or(d);
    let phi0 = env("PHI0_8", 7.0) * PI / 8.0;
    let closure = env("CLOSURE", 6250.0);
    let lat = env("LAT", 0.0) as u32;
    let eps = env("EPS", 50_000.0);
    let freq = env("FREQ", 60.0);
    let det = env("DET_TAU", 0.15e-6);
    let secs = env("SECS", 10.0);
    let mut p = eps2_instrument(phi0, closure, lat);
    p.dither_adc_codes = env("DITHER", 240.0);
    p.detector_tau_s = env("FW_DET_TAU", det);
    p.gain_loop_gain = env("GLG", 0.05);
    let mut r = rig(p, |o| {o.adc_bits = 16; o.detector_tau_s = det}, vibration(eps, freq));
    let prof = vibration(eps, freq);
    for _ in 0..EPS2_SETTLE_CLOSURES { r.run_closure(); }
    let ks = r.cfg.k_sagnac_s;
    let lsb = gyro_sp::RAD_PER_PHASE_LSB;
    let n = r.cfg.n_half as f64;
    let tau = r.cfg.params.tau_s;
    let kappa = 1.0 / phi0.tan();
    let closures = (secs / r.cfg.closure_period_s()) as usize;
    // terms: b*x, b*x^3, x^3, b^2*x, 1
    let names = ["bx", "bx^3", "x^3", "b^2x", "bx^5", "1"];
    let k = names.len();
    let mut ata = vec![vec![0.0; k]; k];
    let mut atb = vec![0.0; k];
    let (mut miss, mut err_sum, mut bias_sum) = (0.0, 0.0, 0.0);
    let (mut model_err, mut model_bias) = (0.0, 0.0);
    let mut cpt_sum = 0.0;
    let mut rmax: f64 = 0.0;
    let (mut exact_err, mut exact_bias) = (0.0, 0.0);
    let (mut even_miss, mut odd_miss, mut odd_err, mut odd_bias) = (0.0, 0.0, 0.0, 0.0);
    for _ in 0..closures {
        let s = r.run_closure();
        let applied = (s.out.sagnac_phase - s.out.residual as i64) as f64 * lsb;
        let x = ks * s.true_rate - applied;
        let t_mid = s.t_end - n * tau / 2.0;
        let b = ks * prof.accel_at(t_mid) * tau; // per half period
        let err = s.out.residual as f64 * lsb - x;
        let bias = (s.out.sagnac_phase - s.out.sagnac_phase_corrected) as f64 * lsb;
        let y = err - bias;
        miss += y;
        cpt_sum += s.out.codes_per_turn_q8 as f64;
        rmax = rmax.max((s.out.residual as f64 * lsb).abs());
        // The ideal closure: levels of delta_j = x + b*(j - (n-1)/2).
        let model = |x: f64, b: f64| {
            let nn = n as usize;
            let (mut ra, mut rb) = (0.0, 0.0);
            for j in 0..nn {
                let dj = x + b * (j as f64 - (n - 1.0) / 2.0);
                let sj = if j % 2 == 0 { 1.0 } else { -1.0 };
                let v = dj.sin() - kappa * sj * dj.cos();
                if j < nn / 2 { ra += v } else { rb += v }
            }
            let (ra, rb) = (ra * 2.0 / n, rb * 2.0 / n);
            let rm = (ra + rb) / 2.0;
            let dm = rb - ra;
            (rm.asin() - x, -(kappa / n) * dm * rm / (1.0 - rm * rm))
        };
        // The exact per-half residuals (the profile's rate at each half's middle).
        {
            let nn = n as usize;
            let first = (s.t_end / tau).round() as u64 - nn as u64;
            let (mut ra, mut rb) = (0.0, 0.0);
            for j in 0..nn {
                let tj = (first + j as u64) as f64 * tau + tau / 2.0;
                let dj = ks * prof.rate_at(tj) - applied;
                let sj = if j % 2 == 0 { 1.0 } else { -1.0 };
                let v = dj.sin() - kappa * sj * dj.cos();
                if j < nn / 2 { ra += v } else { rb += v }
            }
            let (ra, rb) = (ra * 2.0 / n, rb * 2.0 / n);
            let rm = (ra + rb) / 2.0;
            let dm = rb - ra;
            exact_err += rm.asin() - x;
            exact_bias += -(kappa / n) * dm * rm / (1.0 - rm * rm);
        }
        let (e1, b1) = model(x, b);
        let (e2, b2) = model(-x, -b);
        model_err += e1;
        model_bias += b1;
        even_miss += ((e1 - b1) + (e2 - b2)) / 2.0;
        odd_miss += ((e1 - b1) - (e2 - b2)) / 2.0;
        odd_err += (e1 - e2) / 2.0;
        odd_bias += (b1 - b2) / 2.0;
        err_sum += err;
        bias_sum += bias;
        let f = [b * x * kappa, b * x.powi(3) * kappa, x.powi(3), b * b * x, b * x.powi(5) * kappa, 1.0];
        for i in 0..k {
            atb[i] += f[i] * y;
            for j in 0..k {
                ata[i][j] += f[i] * f[j];
            }
        }
    }
    let m = closures as f64;
    println!("mean err {:.4e} mean bias {:.4e} mean miss {:.4e} rad ({:+.3} % of err)", err_sum / m, bias_sum / m, miss / m, miss / err_sum * 100.0);
    println!("exact halves: err {:.4e} ({:+.3} % vs sim) bias {:.4e} ({:+.3} % vs sim; miss {:+.3} %)", exact_err / m, (exact_err / err_sum - 1.0) * 100.0, exact_bias / m, (exact_bias / bias_sum - 1.0) * 100.0, (exact_err - exact_bias) / exact_err * 100.0);
    println!("largest |residual| {rmax:.4} rad (sine {:.4})", rmax.sin());
    println!("codes per turn mean {:.4} (nominal {})", cpt_sum / m / 256.0, r.cfg.params.dac_codes_per_turn);
    println!("even miss {:+.4e} odd miss {:+.4e} odd err {:+.4e} odd bias {:+.4e} (rad, mean)", even_miss / m, odd_miss / m, odd_err / m, odd_bias / m);
    println!("ideal model: err {:.4e} ({:+.3} % vs sim) bias {:.4e} (miss {:+.3} %)", model_err / m, (model_err / err_sum - 1.0) * 100.0, model_bias / m, (model_err - model_bias) / model_err * 100.0);
    // solve
    let mut a = ata.clone();
    let mut bb = atb.clone();
    for i in 0..k {
        let p = a[i][i];
        for j in 0..k { a[i][j] /= p; }
        bb[i] /= p;
        for r2 in 0..k {
            if r2 != i {
                let f = a[r2][i];
                for j in 0..k { a[r2][j] -= f * a[i][j]; }
                bb[r2] -= f * bb[i];
            }
        }
    }
    for i in 0..k { println!("{}: {:+.4e}", names[i], bb[i]); }
}
