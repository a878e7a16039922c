//! Decomposes one eps^2 point's output error (issue 23) closure by closure.
//!
//! The rig's optics are noise-free and deterministic, so each closure's
//! samples can be rebuilt from its DAC words and the true Sagnac phases (the
//! same formulas as `fog_optics`'s idealised detector). Per closure, in
//! phase LSB, the output error `raw = sagnac_phase - K_s * true_rate` is
//! split exactly into:
//! - `dac`: the feedback phase the DSP counts less the phase the DAC words
//!   applied (telescopes: mean 0);
//! - `rect`: the rectification an exact demodulator would see, asin of the
//!   unquantised levels' demodulated sine (exact depth of this closure) less
//!   the true mean residual: the eps^2 drift itself;
//! - `adc`: asin of the rebuilt *rounded* samples less that of the
//!   unquantised ones: the ADC's rounding (the white noise of these runs);
//! - `dsp`: the DSP's residual less asin of the rounded samples: what its
//!   arithmetic and normalisation (AGC, dither factor) add.
//!
//! and `rect` is compared with the correction's formula on the true slope
//! and residual, and that with the correction the DSP subtracted: the
//! corrected error is the sum of the five terms printed. Means over blocks of whole periods with their standard
//! errors (as `vibration_drift`); `--adc-noise SIGMA` adds Gaussian noise of
//! SIGMA LSB at the operating level before the ADC (then `adc` holds it too).
//!
//! `cargo run --release -p gyro-sim --example eps2_decompose -- --eighths 6
//! --closure 12500 --lat 0 --eps 1000 --hz 200 --secs 3000 [--glg 0]`
use gyro_sim::vibration_drift::{
    eps2_instrument, eps2_rig, vibration, Welford, DEG, DPH, EPS2_NOISE_SEED, EPS2_SETTLE_CLOSURES,
};
use gyro_sp::RAD_PER_PHASE_LSB;
use std::f64::consts::{PI, TAU};

fn arg(name: &str, default: f64) -> f64 {
    let args: Vec<String> = std::env::args().collect();
    args.iter()
        .position(|a| a == name)
        .and_then(|i| args.get(i + 1))
        .and_then(|v| v.parse().ok())
        .unwrap_or(default)
}

/// Running block means of the terms, phase LSB.
#[derive(Default)]
struct Terms {
    corrected: Welford,
    raw: Welford,
    dac: Welford,
    rect_less_formula: Welford,
    adc: Welford,
    dsp: Welford,
    codes_per_turn_error: Welford,
    formula_less_bias: Welford,
}

fn main() {
    let phi0 = arg("--eighths", 6.0) / 8.0 * PI;
    let closure_hz = arg("--closure", 12_500.0);
    let eps = arg("--eps", 1_000.0);
    let hz = arg("--hz", 200.0);
    let secs = arg("--secs", 2_000.0);
    let mut params = eps2_instrument(phi0, closure_hz, arg("--lat", 0.0) as u32);
    params.gain_loop_gain = arg("--glg", params.gain_loop_gain);
    params.dither_adc_codes = arg("--dither", params.dither_adc_codes);
    let Ok(mut rig) = eps2_rig(params, EPS2_NOISE_SEED, vibration(eps, hz)) else {
        eprintln!("configuration refused");
        return;
    };
    // The bench's instrument carries detector noise; the rebuild needs the
    // optics deterministic, so it is off here unless asked for.
    let sigma = arg("--adc-noise", 0.0);
    let op = &mut rig.optics.p;
    op.noise = sigma > 0.0;
    if sigma > 0.0 {
        op.rin = 0.0;
        op.shot = sigma / op.operating_light(phi0).sqrt();
    }
    let formula = rig.cfg.predicted_vibration_drift((eps * DEG).powi(2) / 2.0) * DPH;
    let lsb_dph = rig.cfg.rad_s_per_phase_lsb() * DPH;
    let (ks, n, tau) = (rig.cfg.k_sagnac_s, rig.cfg.n_half, rig.cfg.params.tau_s);
    let op = rig.optics.p;
    let c_true = op.codes_per_turn;
    let rad_per_code = TAU / c_true;
    let (sph, skip) = (op.samples_per_half, rig.cfg.skip_samples);
    let decay: Vec<f64> = (0..sph)
        .map(|i| (-(tau * i as f64 / sph as f64) / op.detector_tau_s).exp())
        .collect();
    let kept: f64 = decay[skip..].iter().map(|d| 1.0 - d).sum();
    let a = op.peak_lsb / 2.0;
    let cot = 1.0 / phi0.tan();

    let mut prev_word = 0i32;
    while rig.closure_index() < EPS2_SETTLE_CLOSURES {
        prev_word = rig.applied_dac()[n - 1] as i32;
        rig.run_closure();
    }
    let block = ((hz.ceil() / hz) * closure_hz).round() as u64;
    let blocks = (secs * closure_hz / block as f64).ceil() as u64;
    let mut t = Terms::default();
    let mut wrap_closures = 0u64;
    for b in 0..blocks {
        let mut sum = [0.0f64; 8];
        for _ in 0..block {
            let words: Vec<i32> = rig.applied_dac().iter().map(|&w| w as i32).collect();
            let first = rig.closure_index() * n as u64;
            // Phase steps the words apply, rad (as the optics: the code
            // difference times the true phase per code).
            let mut dphi = [0.0f64; 64];
            let (mut unwrapped_codes, mut wraps) = (0.0, false);
            let mut p = prev_word;
            for (j, &w) in words.iter().enumerate() {
                dphi[j] = (w - p) as f64 * rad_per_code;
                let d = (w - p) as f64;
                let turns = (d / c_true).round();
                wraps |= turns != 0.0;
                unwrapped_codes += d - turns * c_true;
                p = w;
            }
            prev_word = words[n - 1];
            let applied_rad = -unwrapped_codes / n as f64 * rad_per_code;
            // This closure's depth (dither included, DAC-quantised).
            let depth = (0..n / 2)
                .map(|k| {
                    let dd = (dphi[2 * k] - dphi[2 * k + 1]) / 2.0;
                    dd - ((dd - phi0) / PI).round() * PI
                })
                .sum::<f64>()
                / (n / 2) as f64;
            // Signed level sums: unquantised (halves 1, 2) and rounded.
            let (mut s_half, mut s_round, mut delta_half) = ([0.0f64; 2], 0.0, [0.0f64; 2]);
            for (j, &step) in dphi.iter().enumerate().take(n) {
                let t_mid = (first as f64 + j as f64 + 0.5) * tau;
                let phi_s = ks * rig.profile.rate_at(t_mid);
                let level = a * (1.0 + (phi_s + step).cos());
                let sign = if j % 2 == 0 { 1.0 } else { -1.0 };
                s_half[2 * j / n] += sign * level * kept;
                for d in &decay[skip..] {
                    let y = level + (op.peak_lsb - level) * d + op.adc_offset_lsb;
                    s_round += sign * (y.round() - op.adc_offset_lsb);
                }
                let delta = phi_s + step - sign * depth;
                delta_half[2 * j / n] += (delta - (delta / TAU).round() * TAU) / (n / 2) as f64;
            }
            // (The glitch's and the offset's shares cancel in the signed sums.)
            let k = n as f64 * kept * a * depth.sin();
            let r_ideal = (-(s_half[0] + s_half[1]) / k).clamp(-1.0, 1.0).asin();
            let r_round = (-s_round / k).clamp(-1.0, 1.0).asin();
            let r_true = (delta_half[0] + delta_half[1]) / 2.0;
            let d_true = delta_half[0] - delta_half[1];
            let formula_true = (cot / n as f64) * d_true * r_true / (1.0 - r_true * r_true);

            let s = rig.run_closure();
            let lsb = RAD_PER_PHASE_LSB;
            let truth = ks * s.true_rate / lsb;
            let raw = s.out.sagnac_phase as f64 - truth;
            let applied = (s.out.sagnac_phase - s.out.residual as i64) as f64;
            let turn = 2f64.powi(32);
            let mut dac = applied - applied_rad / lsb;
            dac -= (dac / turn).round() * turn;
            wrap_closures += wraps as u64;
            let terms = [
                s.out.sagnac_phase_corrected as f64 - truth,
                raw,
                dac,
                (r_ideal - r_true - formula_true) / lsb,
                (r_round - r_ideal) / lsb,
                s.out.residual as f64 - r_round / lsb,
                s.out.codes_per_turn_q8 as f64 / 256.0 - c_true,
                formula_true / lsb - (s.out.sagnac_phase - s.out.sagnac_phase_corrected) as f64,
            ];
            for (acc, x) in sum.iter_mut().zip(terms) {
                *acc += x;
            }
        }
        let m = |i: usize| sum[i] / block as f64;
        t.corrected.push(m(0));
        t.raw.push(m(1));
        t.dac.push(m(2));
        t.rect_less_formula.push(m(3));
        t.adc.push(m(4));
        t.dsp.push(m(5));
        t.codes_per_turn_error.push(m(6));
        t.formula_less_bias.push(m(7));
        if (b + 1) % 500 == 0 || b + 1 == blocks {
            let f = |w: &Welford| format!("{:+.3} +- {:.3}", w.mean(), w.standard_error());
            let seconds = ((b + 1) * block) as f64 / closure_hz;
            println!(
                "{seconds:.0} s: corrected {} LSB ({:+.2} % +- {:.2} % of the formula's {:.2} LSB); raw {}",
                f(&t.corrected),
                t.corrected.mean() * lsb_dph / formula * 100.0,
                t.corrected.standard_error() * lsb_dph / formula * 100.0,
                formula / lsb_dph,
                f(&t.raw)
            );
            println!(
                "  sum of: rect - formula(true d, r) {}; formula(true) - correction {}; dac {}; adc rounding {}; dsp (arithmetic, normalisation) {}",
                f(&t.rect_less_formula),
                f(&t.formula_less_bias),
                f(&t.dac),
                f(&t.adc),
                f(&t.dsp)
            );
            println!(
                "  closures with a 2pi wrap in their words {:.3}; digital codes per turn - true {:+.4}",
                wrap_closures as f64 / ((b + 1) * block) as f64,
                t.codes_per_turn_error.mean()
            );
        }
    }
}
