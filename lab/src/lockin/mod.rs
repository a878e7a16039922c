//! RLG lock-in: the fringe simulator, the estimator and `gyro-lab lockin`.

pub mod estimate;
pub mod fringe_sim;

use crate::data::fringe_file::{FringeFile, FringeWriter};
use crate::error::LabError;
use clap::Args;
use std::path::PathBuf;

#[derive(Args, Debug, Clone)]
pub struct LockinArgs {
    /// Fringe file: `t_s`, `signal`, optional `signal_q`.
    #[arg(long)]
    pub data: PathBuf,
    /// Scale factor K, pulses (fringes) per degree.
    #[arg(long)]
    pub pulses_per_deg: f64,
    /// Input rate, deg/s (estimated from the record when not given).
    #[arg(long, allow_negative_numbers = true)]
    pub input_rate_dps: Option<f64>,
    #[arg(long)]
    pub json: bool,
}

pub fn run(a: &LockinArgs) -> Result<(), LabError> {
    if !(a.pulses_per_deg.is_finite() && a.pulses_per_deg > 0.0) {
        return Err(LabError::Usage(format!(
            "--pulses-per-deg {}: must be positive",
            a.pulses_per_deg
        )));
    }
    if let Some(w) = a.input_rate_dps {
        if !w.is_finite() || w == 0.0 {
            return Err(LabError::Usage(format!(
                "--input-rate-dps {w}: must be finite and non-zero"
            )));
        }
    }
    let f = FringeFile::read(&a.data, 64)?;
    let r = estimate::lock_in(
        &f.t_s,
        &f.signal,
        f.signal_q.as_deref(),
        a.pulses_per_deg,
        a.input_rate_dps,
    )
    .map_err(|e| LabError::input(&a.data, e.to_string()))?;
    if a.json {
        println!(
            "{}",
            serde_json::to_string(&r).map_err(|e| LabError::Io {
                file: None,
                msg: e.to_string()
            })?
        );
    } else {
        println!(
            "lock-in {:.6} deg/s (+-{:.6}), input rate {:.6} deg/s ({}), beat {:.3} Hz, rho {:.6}",
            r.lock_in_dps,
            r.lock_in_std_dps,
            r.input_rate_dps,
            if r.input_rate_given {
                "given"
            } else {
                "estimated"
            },
            r.beat_hz,
            r.harmonic_ratio
        );
        println!(
            "published approximate formula on the same record: {:.6} deg/s",
            r.lock_in_approx_dps
        );
    }
    Ok(())
}

/// `gyro-lab simulate lockin`: writes a fringe file.
#[derive(Args, Debug, Clone)]
pub struct LockinSimArgs {
    /// Input rate Omega_I, deg/s.
    #[arg(long, default_value_t = 1.0, allow_negative_numbers = true)]
    pub rate_dps: f64,
    /// Lock-in rate Omega_L, deg/s.
    #[arg(long, default_value_t = 0.1)]
    pub lock_in_dps: f64,
    #[arg(long, default_value_t = 2000.0)]
    pub pulses_per_deg: f64,
    #[arg(long, default_value_t = 20_000.0)]
    pub sample_hz: f64,
    #[arg(long, default_value_t = 3.0)]
    pub duration_s: f64,
    /// Noise standard deviation relative to the fringe amplitude.
    #[arg(long, default_value_t = 0.0)]
    pub noise: f64,
    /// ADC bits (none: no quantization).
    #[arg(long)]
    pub bits: Option<u32>,
    /// Offset of the photodiode signal, in fringe amplitudes.
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
    pub offset: f64,
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
    pub beta_rad: f64,
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Also write the quadrature channel `signal_q`.
    #[arg(long)]
    pub quadrature: bool,
    #[arg(long)]
    pub out: PathBuf,
    #[arg(long)]
    pub json: bool,
}

pub fn simulate(a: &LockinSimArgs) -> Result<(), LabError> {
    let bad = |name: &str, v: f64| LabError::Usage(format!("--{name} {v}: out of range"));
    if !(a.lock_in_dps.is_finite() && a.lock_in_dps >= 0.0) {
        return Err(bad("lock-in-dps", a.lock_in_dps));
    }
    if !(a.pulses_per_deg.is_finite() && a.pulses_per_deg > 0.0) {
        return Err(bad("pulses-per-deg", a.pulses_per_deg));
    }
    if !(a.sample_hz.is_finite() && a.sample_hz > 0.0) {
        return Err(bad("sample-hz", a.sample_hz));
    }
    let samples = a.duration_s * a.sample_hz;
    if !(samples.is_finite() && (64.0..=1e8).contains(&samples)) {
        return Err(bad("duration-s", a.duration_s));
    }
    if !(a.rate_dps.is_finite() && a.noise.is_finite() && a.noise >= 0.0) {
        return Err(bad("noise", a.noise));
    }
    if matches!(a.bits, Some(b) if !(2..=24).contains(&b)) {
        return Err(bad("bits", a.bits.unwrap_or(0) as f64));
    }
    let p = fringe_sim::FringeParams {
        pulses_per_deg: a.pulses_per_deg,
        input_rate_dps: a.rate_dps,
        lock_in_dps: a.lock_in_dps,
        beta_rad: a.beta_rad,
        sample_hz: a.sample_hz,
        samples: samples.round() as usize,
        offset: a.offset,
        noise_rel: a.noise,
        bits: a.bits,
        seed: a.seed,
        ..Default::default()
    };
    let f = p.simulate();
    let mut w = FringeWriter::create(
        &a.out,
        &format!(
            "gyro-lab simulate lockin: K {} /deg, Omega_I {} deg/s, Omega_L {} deg/s, beat {:.6} Hz",
            p.pulses_per_deg,
            p.input_rate_dps,
            p.lock_in_dps,
            p.beat_hz()
        ),
        a.quadrature,
    )?;
    for k in 0..f.t.len() {
        if a.quadrature {
            w.row(&[f.t[k], f.s[k], f.q[k]])?;
        } else {
            w.row(&[f.t[k], f.s[k]])?;
        }
    }
    w.finish()?;
    if a.json {
        println!(
            "{}",
            serde_json::json!({"samples": f.t.len(), "beat_hz": p.beat_hz(), "out": a.out})
        );
    } else {
        println!(
            "{} samples, beat {:.3} Hz -> {}",
            f.t.len(),
            p.beat_hz(),
            a.out.display()
        );
    }
    Ok(())
}

pub mod bench;

#[derive(Args, Debug, Clone)]
pub struct LockinBenchArgs {
    /// Simulated records per ratio and record kind.
    #[arg(long, default_value_t = 8)]
    pub seeds: u64,
    #[arg(long)]
    pub json: bool,
}

pub fn bench_run(a: &LockinBenchArgs) -> Result<(), LabError> {
    if a.seeds == 0 || a.seeds > 1000 {
        return Err(LabError::Usage(format!("--seeds {}: 1..1000", a.seeds)));
    }
    let mut out = serde_json::Map::new();
    for (key, rec, title) in [
        (
            "noise_1pct_3s",
            bench::Record::Noise1Pct,
            "1 % noise, 3 s at 20 kHz",
        ),
        (
            "adc_8bit_2500",
            bench::Record::EightBit,
            "8-bit ADC, 2 500 points at 20 kHz",
        ),
    ] {
        let rows = bench::table(rec, a.seeds);
        if !a.json {
            println!(
                "lock-in, {title}, K = 2000 /deg, Omega_I = 1 deg/s, {} records each",
                a.seeds
            );
            println!(
                "{:>8} {:>10} | {:>10} {:>10} {:>10} | {:>10} {:>10} {:>10} | {:>12} {:>11}",
                "OI/OL",
                "OL deg/s",
                "S rms%",
                "S max%",
                "S 1sig%",
                "S+Q rms%",
                "S+Q max%",
                "S+Q 1sig%",
                "approx mean%",
                "approx max%"
            );
            for r in &rows {
                println!(
                    "{:>8.0} {:>10.4} | {:>10.3} {:>10.3} {:>10.3} | {:>10.3} {:>10.3} {:>10.3} | {:>12.2} {:>11.2}",
                    r.ratio,
                    r.lock_in_dps,
                    r.exact_rms_pct,
                    r.exact_max_pct,
                    r.exact_std_pct,
                    r.pair_rms_pct,
                    r.pair_max_pct,
                    r.pair_std_pct,
                    r.approx_mean_pct,
                    r.approx_max_pct
                );
            }
        }
        out.insert(
            key.into(),
            serde_json::to_value(&rows).map_err(|e| LabError::Io {
                file: None,
                msg: e.to_string(),
            })?,
        );
    }
    println!("{}", serde_json::Value::Object(out));
    Ok(())
}
