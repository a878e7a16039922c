//! `gyro-lab simulate fog`: the firmware's FOG core closed around the simulated
//! interferometer and photodetector, sample by sample.

use crate::data::csv_writer::CellFormat::{Exp, Fixed, Shortest};
use crate::data::run_file::{Column, RunWriter};
use crate::error::LabError;
use clap::{Args, Subcommand};
use gyro_sim::{FogRig, OpticsParams, Profile, Segment};
use gyro_sp::fog::{FogConfig, FogParams};
use indicatif::{ProgressBar, ProgressStyle};

const DEG: f64 = std::f64::consts::PI / 180.0;
const DPH_PER_RAD_S: f64 = 3600.0 / DEG;

#[derive(Subcommand)]
pub enum SimulateCmd {
    /// Closed-loop fiber-optic gyro.
    Fog(FogArgs),
    /// RLG fringe signal near lock-in (writes a fringe file).
    Lockin(crate::lockin::LockinSimArgs),
    /// RLG in a thermal chamber (writes a run file).
    Chamber(crate::thermal::chamber::ChamberArgs),
    /// FOG scale-factor calibration run over temperature (continuous rotation or multi-point; writes a run file).
    ScaleFactor(crate::scale_factor::SimulateArgs),
    /// A gyro model (model.toml) on a test profile with the project's noise: a run with known effects.
    Run(crate::discover::trials::SimulateRunArgs),
}

#[derive(Args, Debug, Clone)]
pub struct FogArgs {
    /// Bias modulation depth phi0, rad.
    #[arg(long, default_value_t = 0.75 * std::f64::consts::PI)]
    pub phi0_rad: f64,
    /// Closure rate, Hz (a whole, even number of 5 us half periods).
    #[arg(long, default_value_t = 12_500.0)]
    pub closure_hz: f64,
    /// Constant input rate, deg/s.
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
    pub rate_dps: f64,
    /// Peak angular acceleration of a sinusoidal oscillation, deg/s^2.
    #[arg(long, requires = "vibration_hz")]
    pub vibration_dps2: Option<f64>,
    /// Frequency of the oscillation, Hz.
    #[arg(long, requires = "vibration_dps2")]
    pub vibration_hz: Option<f64>,
    /// Vibration levels as fractions of the peak, played one after another
    /// for equal parts of the run (e.g. 0,0.5,1: at rest, half, full); at
    /// most 8. Default: the full level throughout.
    #[arg(long, value_delimiter = ',', requires = "vibration_dps2")]
    pub vibration_levels: Vec<f64>,
    /// Simulated time, s.
    #[arg(long, default_value_t = 1.0)]
    pub duration_s: f64,
    /// Turn the online epsilon-squared correction off.
    #[arg(long)]
    pub no_vibration_correction: bool,
    /// Shot and intensity noise on.
    #[arg(long)]
    pub noise: bool,
    /// Noise seed.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// Main-loop gain (fraction of the residual corrected per step).
    #[arg(long, default_value_t = 1.0)]
    pub loop_gain: f64,
    /// 2*pi gain-loop gain (0 holds the digital gain at nominal).
    #[arg(long, default_value_t = 0.05)]
    pub gain_loop_gain: f64,
    /// Modulator gain error (V_pi off nominal), relative.
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
    pub vpi_error: f64,
    /// ADC resolution, bits.
    #[arg(long, default_value_t = 12)]
    pub adc_bits: u32,
    /// Modulation-depth dither, half width in ADC codes of the detector level (0 = off).
    #[arg(long, default_value_t = 60.0)]
    pub dither_codes: f64,
    /// Start-up time left out of the mean error, s.
    #[arg(long, default_value_t = 0.02)]
    pub settle_s: f64,
    /// Write a run file (CSV, means over 25 closure steps).
    #[arg(long)]
    pub out: Option<std::path::PathBuf>,
    #[arg(long)]
    pub json: bool,
}

/// Result of a FOG simulation.
#[derive(Debug, Clone, serde::Serialize)]
pub struct FogSummary {
    pub mean_error_dph: f64,
    /// Standard error of `mean_error_dph` from the output's own noise: the
    /// Allan deviation, at the averaging time, of the noise model fitted to
    /// the error's batch means (whole oscillation periods each), which holds
    /// for correlated noise (the slow AGC); null under 3 batches.
    pub mean_error_stderr_dph: Option<f64>,
    pub mean_error_raw_dph: f64,
    pub mean_error_raw_stderr_dph: Option<f64>,
    pub predicted_drift_dph: f64,
    pub duration_s: f64,
    pub averaged_s: f64,
    pub steps: u64,
    pub wall_s: f64,
    pub realtime_factor: f64,
    pub final_codes_per_turn: f64,
    pub faults_seen: u16,
}

pub fn run(cmd: SimulateCmd) -> Result<(), LabError> {
    match cmd {
        SimulateCmd::Lockin(a) => crate::lockin::simulate(&a),
        SimulateCmd::Chamber(a) => crate::thermal::chamber::simulate(&a),
        SimulateCmd::ScaleFactor(a) => crate::scale_factor::simulate(&a),
        SimulateCmd::Run(a) => crate::discover::trials::simulate(&a),
        SimulateCmd::Fog(a) => {
            let s = simulate_fog(&a)?;
            if a.json {
                println!(
                    "{}",
                    serde_json::to_string(&s).map_err(|e| LabError::Io {
                        file: None,
                        msg: e.to_string()
                    })?
                );
            } else {
                let pm = |v: f64, se: Option<f64>| match se {
                    Some(se) => format!("{v:+.6} +- {se:.6}"),
                    None => format!("{v:+.6} (standard error unknown: under 2 batches)"),
                };
                println!(
                    "mean error: {} deg/h corrected, {} deg/h raw (formula drift {:+.6} deg/h)",
                    pm(s.mean_error_dph, s.mean_error_stderr_dph),
                    pm(s.mean_error_raw_dph, s.mean_error_raw_stderr_dph),
                    s.predicted_drift_dph
                );
                for (what, v, se) in [
                    ("corrected", s.mean_error_dph, s.mean_error_stderr_dph),
                    ("raw", s.mean_error_raw_dph, s.mean_error_raw_stderr_dph),
                ] {
                    if let Some(se) = se {
                        if se > 0.1 * v.abs() && v != 0.0 {
                            // The standard error falls as 1/sqrt(T).
                            let need = s.averaged_s * (se / (0.1 * v.abs())).powi(2);
                            println!(
                                "note: the {what} mean is still uncertain (standard error {:.0} % of it); \
                                 about --duration-s {:.0} brings it to 10 %",
                                100.0 * se / v.abs(),
                                need.ceil() + (s.duration_s - s.averaged_s)
                            );
                        }
                    }
                }
                println!(
                    "{} steps, {:.3} s simulated in {:.2} s ({:.0}x real time)",
                    s.steps, s.duration_s, s.wall_s, s.realtime_factor
                );
            }
            Ok(())
        }
    }
}

fn check(name: &str, v: f64, ok: bool) -> Result<(), LabError> {
    if v.is_finite() && ok {
        Ok(())
    } else {
        Err(LabError::Usage(format!("--{name} {v}: out of range")))
    }
}

pub fn simulate_fog(a: &FogArgs) -> Result<FogSummary, LabError> {
    check(
        "duration-s",
        a.duration_s,
        a.duration_s > 0.0 && a.duration_s <= 1e5,
    )?;
    check("rate-dps", a.rate_dps, a.rate_dps.abs() <= 2000.0)?;
    check(
        "adc-bits",
        a.adc_bits as f64,
        (8..=16).contains(&a.adc_bits),
    )?;
    let params = FogParams {
        phi0_rad: a.phi0_rad,
        closure_hz: a.closure_hz,
        loop_gain: a.loop_gain,
        gain_loop_gain: a.gain_loop_gain,
        dither_adc_codes: a.dither_codes,
        vibration_correction: !a.no_vibration_correction,
        ..FogParams::default()
    };
    let mut optics = OpticsParams::<f64>::nominal(
        params.tau_s,
        params.samples_per_half,
        params.dac_codes_per_turn,
    );
    optics.noise = a.noise;
    optics.seed = a.seed;
    optics.adc_bits = a.adc_bits;
    optics.vpi_gain_error = a.vpi_error;
    let params = optics.matched(params);
    let cfg = FogConfig::new(params)
        .map_err(|e| LabError::Usage(format!("invalid loop parameters: {e:?}")))?;

    let rate = a.rate_dps * DEG;
    let mut period = None;
    let levels: Vec<f64> = if a.vibration_levels.is_empty() {
        vec![1.0]
    } else {
        a.vibration_levels.clone()
    };
    if levels.len() > 8 {
        return Err(LabError::Usage("--vibration-levels: at most 8".into()));
    }
    for &l in &levels {
        check("vibration-levels", l, (0.0..=1.0).contains(&l))?;
    }
    let profile = match (a.vibration_dps2, a.vibration_hz) {
        (Some(eps), Some(f)) => {
            check("vibration-dps2", eps, eps >= 0.0)?;
            check("vibration-hz", f, f > 0.0 && f < a.closure_hz / 4.0)?;
            period = Some(1.0 / f);
            // Equal parts of whole periods (the rate continuous at each
            // change: every segment starts at a zero crossing).
            let part = if levels.len() > 1 {
                (a.duration_s / levels.len() as f64 * f).floor().max(1.0) / f
            } else {
                f64::INFINITY
            };
            let segs: Vec<Segment<f64>> = levels
                .iter()
                .enumerate()
                .map(|(i, &l)| Segment::Oscillation {
                    offset: rate,
                    eps_peak: eps * DEG * l,
                    freq_hz: f,
                    duration: if i + 1 == levels.len() {
                        f64::INFINITY
                    } else {
                        part
                    },
                })
                .collect();
            Profile::new(&segs)
        }
        _ => Profile::constant(rate),
    };
    let mean_level_sq = levels.iter().map(|l| l * l).sum::<f64>() / levels.len() as f64;
    let mean_eps_sq = a
        .vibration_dps2
        .map_or(0.0, |e| (e * DEG).powi(2) / 2.0 * mean_level_sq);
    let predicted = cfg.predicted_vibration_drift(mean_eps_sq) * DPH_PER_RAD_S;

    let dt = cfg.closure_period_s();
    let steps = (a.duration_s / dt).round() as u64;
    // Average over whole oscillation periods after the settling time.
    let settle_steps = ((a.settle_s / dt).ceil() as u64).min(steps / 2);
    let avg_steps = match period {
        Some(p) => {
            let per = p / dt;
            let whole = ((steps - settle_steps) as f64 / per).floor();
            if whole < 1.0 {
                return Err(LabError::Usage(
                    "--duration-s is shorter than one oscillation period".into(),
                ));
            }
            (whole * per).round() as u64
        }
        None => steps - settle_steps,
    };
    let start_avg = steps - avg_steps;
    // Batches for the standard error: whole oscillation periods (else 25
    // steps, a frame), at most about 10^6 of them.
    let batch_steps = {
        let per = period.map_or(25.0, |p| p / dt);
        let whole = (avg_steps as f64 / 1e6 / per).ceil().max(1.0);
        (whole * per).round().max(1.0) as u64
    };
    let mut batches: Vec<(f64, f64)> = Vec::new();
    let (mut b_err, mut b_raw, mut b_n) = (0.0f64, 0.0f64, 0u64);

    let mut rig = FogRig::new(cfg, optics, profile);
    let lsb_rate = cfg.rad_s_per_phase_lsb();
    let bar = if steps > 200_000 && !a.json {
        let b = ProgressBar::new(steps);
        b.set_style(
            ProgressStyle::with_template("{bar:40} {percent}% {eta}")
                .unwrap_or(ProgressStyle::default_bar()),
        );
        b
    } else {
        ProgressBar::hidden()
    };
    let mut writer = match &a.out {
        Some(p) => Some(RunWriter::create(
            p,
            "gyro-lab simulate fog: means over 25 closure steps",
            &[
                (Column::Time, Fixed(6)),
                (Column::RefRate, Fixed(9)),
                (Column::Rate, Fixed(9)),
                (Column::RawRate, Fixed(9)),
                (Column::RefAcc, Fixed(6)),
                (Column::LoopResidual, Exp(6)),
                (Column::CodesPerTurn, Fixed(3)),
                (Column::Faults, Shortest),
            ],
        )?),
        None => None,
    };
    let (mut err_sum, mut raw_sum) = (0.0f64, 0.0f64);
    let mut faults_seen = 0u16;
    let mut last_cpt = 0u32;
    let mut acc = [0.0f64; 4];
    let mut acc_n = 0u32;
    let t0 = std::time::Instant::now();
    for k in 0..steps {
        let r = rig.run_closure();
        let out = r.out.sagnac_phase_corrected as f64 * lsb_rate;
        let raw = r.out.sagnac_phase as f64 * lsb_rate;
        if k >= start_avg {
            err_sum += out - r.true_rate;
            raw_sum += raw - r.true_rate;
            b_err += out - r.true_rate;
            b_raw += raw - r.true_rate;
            b_n += 1;
            if b_n == batch_steps {
                batches.push((b_err / b_n as f64, b_raw / b_n as f64));
                (b_err, b_raw, b_n) = (0.0, 0.0, 0);
            }
        }
        faults_seen |= r.out.faults.0;
        last_cpt = r.out.codes_per_turn_q8;
        if let Some(w) = writer.as_mut() {
            acc[0] += r.true_rate;
            acc[1] += out;
            acc[2] += raw;
            acc[3] += r.out.residual as f64 * gyro_sp::RAD_PER_PHASE_LSB;
            acc_n += 1;
            if acc_n == 25 {
                let n = acc_n as f64;
                // Acceleration at the row's middle: its square samples the
                // oscillation's phases evenly (the rectification's mean).
                let t_mid = r.t_end - 12.5 * dt;
                w.row(&[
                    t_mid,
                    acc[0] / n / DEG,
                    acc[1] / n / DEG,
                    acc[2] / n / DEG,
                    rig.profile.accel_at(t_mid) / DEG,
                    acc[3] / n,
                    r.out.codes_per_turn_q8 as f64 / 256.0,
                    r.out.faults.0 as f64,
                ])?;
                acc = [0.0; 4];
                acc_n = 0;
            }
        }
        if k % 65_536 == 0 {
            bar.set_position(k);
        }
    }
    bar.finish_and_clear();
    let wall = t0.elapsed().as_secs_f64();
    if let Some(w) = writer {
        w.finish()?;
    }
    let n = avg_steps.max(1) as f64;
    let batch_s = batch_steps as f64 * dt;
    let se = |f: fn(&(f64, f64)) -> f64| {
        let v: Vec<f64> = batches.iter().map(f).collect();
        crate::allan::analyse(&v, batch_s)
            .ok()
            .map(|a| a.mean_se_dps * DPH_PER_RAD_S)
    };
    Ok(FogSummary {
        mean_error_dph: err_sum / n * DPH_PER_RAD_S,
        mean_error_stderr_dph: se(|b| b.0),
        mean_error_raw_dph: raw_sum / n * DPH_PER_RAD_S,
        mean_error_raw_stderr_dph: se(|b| b.1),
        predicted_drift_dph: predicted,
        duration_s: steps as f64 * dt,
        averaged_s: avg_steps as f64 * dt,
        steps,
        wall_s: wall,
        realtime_factor: steps as f64 * dt / wall.max(1e-9),
        final_codes_per_turn: last_cpt as f64 / 256.0,
        faults_seen,
    })
}
