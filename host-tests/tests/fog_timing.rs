//! The sampling phase on the board's chain (docs/timing.md): the firmware's
//! closed loop (the hw layout, one closure of DAC latency) around the
//! simulated chain built from `gyro_fw::timing::BOARD_CHAIN`, with the ADC's
//! sample train started `phase` TIM1 ticks after each DAC word's update.
//!
//! The sweep runs a 16-bit ADC: at 12 bits the ADC's rounding leaves about
//! 0.3 deg/h at 150 deg/s that moves with the exact detector levels (a 1 ppm
//! scale-factor scatter the linearity test averages for 10 s per rate), which
//! would hide the flat region's sub-ppm level; the transient does not depend
//! on the ADC's resolution.

use gyro_fw::app::{fog_params, SAMPLING_PHASE_TICKS, TIM1_TICKS_PER_HALF};
use gyro_fw::timing::{ticks_to_ns, BOARD_CHAIN, TIM1_CLK_HZ};
use gyro_sim::{Chain, FogOptics, OpticsParams, Profile, Segment};
use gyro_sp::fog::{Faults, FogConfig};
use host_tests::*;

const NS: f64 = 1e-9;
/// The flat region: bias and scale-factor error this close to the idealised
/// detector's (the front end of every other host test).
const BIAS_TOL_DPH: f64 = 0.02;
const SF_TOL_PPM: f64 = 0.3;
/// The default's least margin to each edge of the flat region, TIM1 ticks
/// (0.25 us): more than the chain's uncertain parts (the DMA's arbitration,
/// the ADC's trigger latency: 0.1 us together).
const MIN_MARGIN_TICKS: u32 = 42;
/// The rates of each point, deg/s; bias and scale factor by a least-squares line.
const RATES_DPS: [f64; 5] = [-150.0, -30.0, 0.0, 30.0, 150.0];
/// Per rate: a 2 000 deg/s^2 ramp, then settling and the mean, s.
const SETTLE_S: f64 = 0.15;
const MEAN_S: f64 = 0.4;

/// The simulated chain of the board with the sample train started
/// `phase_ticks` after the update; the ADC holds its aperture delay later.
fn chain(phase_ticks: u32) -> Chain<f64> {
    let c = BOARD_CHAIN;
    // Framed from the update as the DMA buffer is: a hold past the next update
    // starts the train in the next half period.
    let hold = phase_ticks as f64 / TIM1_CLK_HZ as f64 + c.adc_aperture_ns as f64 * NS;
    Chain {
        sample_delay_s: hold,
        dac_delay_s: c.dac_delay_ns() as f64 * NS,
        dac_slew_codes_per_s: 65_536.0 / (c.dac_full_scale_slew_ns as f64 * NS),
        fibre_delay_s: c.fibre_ns as f64 * NS,
        filter_tau_s: c.filter_tau_ns as f64 * NS,
        crosstalk_lsb: c.crosstalk_lsb as f64,
    }
}

fn optics(o: &mut OpticsParams<f64>, phase: Option<u32>) {
    let c = BOARD_CHAIN;
    o.adc_bits = 16;
    o.detector_tau_s = c.detector_tau_ns as f64 * NS;
    o.chain = phase.map(chain);
}

/// Output error at `rate_dps`, deg/h, and the faults seen.
fn error_at(phase: Option<u32>, rate_dps: f64) -> (f64, Faults) {
    let ramp_s = rate_dps.abs() / 2000.0;
    let profile = Profile::new(&[
        Segment::Ramp {
            from: 0.0,
            to: rate_dps * DEG,
            duration: ramp_s,
        },
        Segment::Constant {
            rate: rate_dps * DEG,
            duration: f64::INFINITY,
        },
    ]);
    let mut r = rig(fog_params(1), |o| optics(o, phase), profile);
    let start = closures_in(ramp_s + SETTLE_S);
    let m = mean_error(&mut r, start, start + closures_in(MEAN_S));
    (m.corrected_dph, m.faults_seen)
}

#[derive(Clone, Copy, Debug)]
struct Point {
    bias_dph: f64,
    sf_ppm: f64,
    faults: Faults,
}

/// Bias and scale-factor error at one phase (None: the idealised detector):
/// the least-squares line through the errors at `RATES_DPS`.
fn point(phase: Option<u32>) -> Point {
    let (mut errors, mut faults) = ([0.0; RATES_DPS.len()], Faults::empty());
    for (e, &rate) in errors.iter_mut().zip(&RATES_DPS) {
        let (err, f) = error_at(phase, rate);
        *e = err;
        faults |= f;
    }
    let n = RATES_DPS.len() as f64;
    let mx = RATES_DPS.iter().sum::<f64>() / n;
    let my = errors.iter().sum::<f64>() / n;
    let sxx: f64 = RATES_DPS.iter().map(|x| (x - mx).powi(2)).sum();
    let sxy: f64 = RATES_DPS
        .iter()
        .zip(&errors)
        .map(|(x, y)| (x - mx) * (y - my))
        .sum();
    // deg/h per deg/s.
    let k = sxy / sxx;
    Point {
        bias_dph: my - k * mx,
        sf_ppm: k / 3600.0 * 1e6,
        faults,
    }
}

fn flat(p: &Point, ideal: &Point) -> bool {
    (p.bias_dph - ideal.bias_dph).abs() <= BIAS_TOL_DPH
        && (p.sf_ppm - ideal.sf_ppm).abs() <= SF_TOL_PPM
}

/// Points at `phases`, on two threads (CI has two cores).
fn points(phases: &[u32]) -> Vec<Point> {
    let mut out = vec![None; phases.len()];
    std::thread::scope(|s| {
        let (a, b) = out.split_at_mut(phases.len().div_ceil(2));
        let (pa, pb) = phases.split_at(a.len());
        let h = s.spawn(move || {
            for (o, &ph) in b.iter_mut().zip(pb) {
                *o = Some(point(Some(ph)));
            }
        });
        for (o, &ph) in a.iter_mut().zip(pa) {
            *o = Some(point(Some(ph)));
        }
        h.join().expect("sweep thread");
    });
    out.into_iter()
        .map(|p| p.expect("every point run"))
        .collect()
}

/// Between a flat phase and one that is not, the last flat phase to within
/// 3 ticks (bisection; the region's edge is where the tolerance is crossed).
fn edge(mut flat_at: u32, mut leak_at: u32, ideal: &Point) -> u32 {
    while flat_at.abs_diff(leak_at) > 3 {
        let mid = (flat_at + leak_at) / 2;
        if flat(&point(Some(mid)), ideal) {
            flat_at = mid;
        } else {
            leak_at = mid;
        }
    }
    flat_at
}

/// Sweeps the phase over the half period; prints bias and scale-factor error
/// against it; the default sits in the flat region with its margins, and a
/// phase whose kept samples see the edge's transient shows a bias and a
/// scale-factor error.
#[test]
fn sampling_phase_sweep() {
    let t0 = std::time::Instant::now();
    let ideal = point(None);
    let step = TIM1_TICKS_PER_HALF / 20;
    let grid: Vec<u32> = (0..TIM1_TICKS_PER_HALF).step_by(step as usize).collect();
    let swept = points(&grid);
    let default = point(Some(SAMPLING_PHASE_TICKS));

    // The flat run of grid points around the default, then its edges.
    let below = grid
        .iter()
        .rposition(|&g| g <= SAMPLING_PHASE_TICKS)
        .unwrap();
    let lo_grid = (0..=below).rev().find(|&i| !flat(&swept[i], &ideal));
    let hi_grid = (below + 1..grid.len()).find(|&i| !flat(&swept[i], &ideal));
    let (Some(lo_i), Some(hi_i)) = (lo_grid, hi_grid) else {
        panic!("no phase leaks the transient: the sweep shows nothing");
    };
    let lo_edge = edge(grid[lo_i + 1].min(SAMPLING_PHASE_TICKS), grid[lo_i], &ideal);
    let hi_edge = edge(grid[hi_i - 1].max(SAMPLING_PHASE_TICKS), grid[hi_i], &ideal);

    let ns = |t: u32| ticks_to_ns(t, TIM1_CLK_HZ);
    let hold = |t: u32| ns(t) + BOARD_CHAIN.adc_aperture_ns;
    println!(
        "sampling phase sweep: hw layout, dac_latency 1, 16-bit ADC, rates {RATES_DPS:?} deg/s; \
         the light sweeps from {} ns after the update (the DAC starts at {} ns); \
         flat: |bias - ideal| <= {BIAS_TOL_DPH} deg/h and |SF - ideal| <= {SF_TOL_PPM} ppm",
        BOARD_CHAIN.light_delay_ns(),
        BOARD_CHAIN.dac_delay_ns(),
    );
    println!(
        "{:>6} {:>8} {:>8} {:>12} {:>12} {:>10} {:>10}  note",
        "phase", "compare", "sample0", "bias", "SF error", "d bias", "d SF"
    );
    println!(
        "{:>6} {:>8} {:>8} {:>12} {:>12} {:>10} {:>10}",
        "ticks", "ns", "hold ns", "deg/h", "ppm", "deg/h", "ppm"
    );
    println!(
        "{:>6} {:>8} {:>8} {:>12.4} {:>12.3} {:>10} {:>10}  idealised detector",
        "-", "-", "-", ideal.bias_dph, ideal.sf_ppm, "", ""
    );
    let mut rows: Vec<(u32, Point)> = grid.iter().copied().zip(swept.iter().copied()).collect();
    rows.push((SAMPLING_PHASE_TICKS, default));
    rows.sort_by_key(|r| r.0);
    for (ph, p) in &rows {
        let note = if *ph == SAMPLING_PHASE_TICKS {
            "default".to_string()
        } else if p.bias_dph.abs() > 1e3 {
            // Most kept samples in the next half period: the slope's sign
            // flips and the loop holds the neighbouring zero of the error.
            "locked on the wrong slope".to_string()
        } else if flat(p, &ideal) {
            "flat".to_string()
        } else {
            "transient in kept samples".to_string()
        };
        let note = if p.faults.is_empty() {
            note
        } else {
            format!("{note}, faults {:?}", p.faults)
        };
        println!(
            "{:>6} {:>8} {:>8} {:>12.4} {:>12.3} {:>10.4} {:>10.3}  {note}",
            ph,
            ns(*ph),
            hold(*ph),
            p.bias_dph,
            p.sf_ppm,
            p.bias_dph - ideal.bias_dph,
            p.sf_ppm - ideal.sf_ppm,
        );
    }
    let (below_margin, above_margin) = (
        SAMPLING_PHASE_TICKS - lo_edge,
        hi_edge - SAMPLING_PHASE_TICKS,
    );
    let window = BOARD_CHAIN
        .phase_window_ns(5_000, 4, 1)
        .expect("the chain's window");
    println!(
        "flat region {lo_edge}..{hi_edge} ticks ({}..{} ns) to within 3 ticks; default \
         {SAMPLING_PHASE_TICKS} ticks ({} ns): margin {below_margin} ticks ({} ns) below, \
         {above_margin} ticks ({} ns) above; the chain's derived window {}..{} ns; {:.1} s",
        ns(lo_edge),
        ns(hi_edge),
        ns(SAMPLING_PHASE_TICKS),
        ns(below_margin),
        ns(above_margin),
        window.0,
        window.1,
        t0.elapsed().as_secs_f64(),
    );

    assert!(
        flat(&default, &ideal),
        "default phase: bias {:.4} deg/h, SF {:.3} ppm against {:.4}, {:.3}",
        default.bias_dph,
        default.sf_ppm,
        ideal.bias_dph,
        ideal.sf_ppm
    );
    assert!(default.faults.is_empty(), "faults {:?}", default.faults);
    assert!(
        below_margin >= MIN_MARGIN_TICKS && above_margin >= MIN_MARGIN_TICKS,
        "margins {below_margin} / {above_margin} ticks, at least {MIN_MARGIN_TICKS}"
    );
    // Outside: the sample train started with the DAC word (phase 0), and a
    // quarter sample period past the upper edge. Both leak the transient into
    // kept samples, and both show it as a bias and a scale-factor error.
    for ph in [0, hi_edge + 52] {
        let p = point(Some(ph));
        let (db, dk) = (p.bias_dph - ideal.bias_dph, p.sf_ppm - ideal.sf_ppm);
        assert!(
            db.abs() > 5.0 * BIAS_TOL_DPH && dk.abs() > 5.0 * SF_TOL_PPM,
            "phase {ph}: bias {db:.4} deg/h and SF {dk:.3} ppm off the ideal: the leak does not show"
        );
    }
}

/// The derivation's settling criterion (`BOARD_CHAIN.settle_time_constants`)
/// from the loop's sensitivity: a leak of e LSB in one kept sample of every
/// half period, with the half period's sign, moves the error the loop nulls by
/// e; the loop answers with a residual e / (kept * (P0/2) * sin(phi0)) rad,
/// which is that over K_s in rad/s.
#[test]
fn settling_criterion_from_the_bias_per_lsb() {
    let params = fog_params(1);
    let o = OpticsParams::<f64>::nominal(params.tau_s, 4, params.dac_codes_per_turn);
    let cfg = FogConfig::new(o.matched(params)).unwrap();
    let kept = (params.samples_per_half - params.skip_samples) as f64;
    let rad_per_lsb = 1.0 / (kept * o.peak_lsb / 2.0 * params.phi0_rad.sin());
    let dph_per_lsb = rad_per_lsb / cfg.k_sagnac_s * DPH;
    // 1 / (3 x 29 000 x 0.7071) / 1.352 s -> 2.48 deg/h.
    assert!(
        (dph_per_lsb - 2.48).abs() < 0.01,
        "{dph_per_lsb} deg/h per LSB"
    );
    let c = BOARD_CHAIN;
    let left = c.crosstalk_lsb as f64 * (-(c.settle_time_constants as f64)).exp();
    assert!(
        left * dph_per_lsb <= BIAS_TOL_DPH,
        "crosstalk left after settling: {left} LSB, {} deg/h",
        left * dph_per_lsb
    );
}

/// The chain's timing against the two-pole response of its crosstalk alone
/// (no light): each DAC step is a pulse of height h with the step's sign for
/// step/slew, from the update's DAC delay on; every ADC sample, at the phase's
/// hold instant and every tau/4 after, is the pulses' filtered sum.
#[test]
fn chain_samples_the_crosstalk_at_its_instants() {
    let c = BOARD_CHAIN;
    let tau = 5e-6;
    let phase = 100;
    let mut ch = chain(phase);
    ch.crosstalk_lsb = 2_000.0;
    let mut p = OpticsParams::<f64>::nominal(tau, 4, 49_152);
    optics(&mut p, Some(phase));
    p.chain = Some(ch);
    p.power = 0.0;
    p.adc_offset_lsb = 30_000.0;
    let mut o = FogOptics::new(p);
    // Steps of +-12 000 codes: pulses of 91.6 ns.
    let dac: [u16; 16] = core::array::from_fn(|j| if j % 2 == 0 { 20_000 } else { 8_000 });
    let (t1, t2) = (c.detector_tau_ns as f64 * NS, c.filter_tau_ns as f64 * NS);
    // The cascade's step response.
    let g = |t: f64| {
        if t <= 0.0 {
            0.0
        } else {
            1.0 - (t1 * (-t / t1).exp() - t2 * (-t / t2).exp()) / (t1 - t2)
        }
    };
    let mut adc = [0u16; 64];
    for closure in 0..3 {
        o.run_step_next(&dac, Some(dac[0]), &[0.0; 16], &mut adc);
        if closure == 0 {
            // The first closure starts from code 0 (a step of 20 000 codes).
            continue;
        }
        for (k, &s) in adc.iter().enumerate() {
            let t = ch.sample_delay_s + k as f64 * tau / 4.0;
            // Pulses of the half periods up to the sample (the earlier ones
            // have decayed below 1e-9).
            let y: f64 = (-2..=16)
                .map(|j: i32| {
                    let start = j as f64 * tau + c.dac_delay_ns() as f64 * NS;
                    let width = 12_000.0 / ch.dac_slew_codes_per_s;
                    let sign = if j.rem_euclid(2) == 0 { 1.0 } else { -1.0 };
                    sign * ch.crosstalk_lsb * (g(t - start) - g(t - start - width))
                })
                .sum();
            let expected = 30_000.0 + y;
            assert!(
                (s as f64 - expected).abs() <= 0.5 + 1e-6,
                "closure {closure}, sample {k}: {s} against {expected:.3}"
            );
        }
    }
}

/// With the light settled, the kept samples are the interferometer's level
/// exactly (the idealised detector's), and the first sample of a half period
/// at the default phase is in the sweep's transient.
#[test]
fn settled_samples_are_the_interferometer_level() {
    let tau = 5e-6;
    let mut p = OpticsParams::<f64>::nominal(tau, 4, 49_152);
    optics(&mut p, Some(SAMPLING_PHASE_TICKS));
    let mut o = FogOptics::new(p);
    // phi0 = 3*pi/4 is 18 432 codes: a square wave around 20 000.
    let dac: [u16; 16] = core::array::from_fn(|j| if j % 2 == 0 { 29_216 } else { 10_784 });
    let sagnac = [0.01; 16];
    let mut adc = [0u16; 64];
    for _ in 0..3 {
        o.run_step_next(&dac, Some(dac[0]), &sagnac, &mut adc);
    }
    let rad_per_code = std::f64::consts::TAU / 49_152.0;
    for (j, half) in adc.chunks_exact(4).enumerate() {
        let step = if j % 2 == 0 { 18_432.0 } else { -18_432.0 };
        let level = 1_024.0 + 29_000.0 * (1.0 + (0.01 + step * rad_per_code).cos());
        for &s in &half[1..] {
            assert!(
                (s as f64 - level).abs() <= 0.5 + 1e-6,
                "half {j}: {s} against {level:.3}"
            );
        }
        // The skipped sample still sees the sweep through the bright fringe.
        assert!(
            half[0] as f64 - level > 100.0,
            "half {j}: skipped sample {}",
            half[0]
        );
    }
}
