//! `gyro-lab simulate lockin`: an RLG fringe record near lock-in
//! (sim/fringe.rs), written as a fringe file.

use crate::cli::args::{Json, Out, Seed};
use clap::Args;
use gyro_lab_core::data::fringe_file::FringeWriter;
use gyro_lab_core::error::LabError;
use gyro_lab_core::sim::fringe::FringeParams;

/// `gyro-lab simulate lockin`: writes a fringe file.
#[derive(Args, Debug, Clone)]
#[command(mut_arg("out", |a| a.help("A file: the fringe file to write (CSV)")))]
pub struct LockinSimArgs {
    /// Input rate Omega_I, deg/s.
    #[arg(long, default_value_t = 1.0, allow_negative_numbers = true)]
    pub rate_dps: f64,
    /// Lock-in rate Omega_L, deg/s.
    #[arg(long, default_value_t = 0.1)]
    pub lock_in_dps: f64,
    /// Scale factor K, pulses (fringes) per degree.
    #[arg(long, default_value_t = 2000.0)]
    pub pulses_per_deg: f64,
    /// Sampling rate of the photodiode record, Hz.
    #[arg(long, default_value_t = 20_000.0)]
    pub sample_hz: f64,
    /// Record length, s.
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
    /// Phase beta of the lock-in term (backscatter phase), rad.
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
    pub beta_rad: f64,
    #[command(flatten)]
    pub seed: Seed,
    /// Also write the quadrature channel `signal_q`.
    #[arg(long)]
    pub quadrature: bool,
    #[command(flatten)]
    pub out: Out,
    #[command(flatten)]
    pub json: Json,
}

pub fn run(a: &LockinSimArgs) -> Result<(), LabError> {
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
    let p = FringeParams {
        pulses_per_deg: a.pulses_per_deg,
        input_rate_dps: a.rate_dps,
        lock_in_dps: a.lock_in_dps,
        beta_rad: a.beta_rad,
        sample_hz: a.sample_hz,
        samples: samples.round() as usize,
        offset: a.offset,
        noise_rel: a.noise,
        bits: a.bits,
        seed: a.seed.seed,
        ..Default::default()
    };
    let f = p.simulate();
    let mut w = FringeWriter::create(
        &a.out.out,
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
    if a.json.json {
        println!(
            "{}",
            serde_json::json!({"samples": f.t.len(), "beat_hz": p.beat_hz(), "out": a.out.out})
        );
    } else {
        println!(
            "{} samples, beat {:.3} Hz -> {}",
            f.t.len(),
            p.beat_hz(),
            a.out.out.display()
        );
    }
    Ok(())
}
