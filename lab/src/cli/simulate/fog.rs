//! `gyro-lab simulate fog`: the firmware's FOG core closed around the
//! simulated interferometer and photodetector (sim/fog_run.rs).

use crate::cli::args::{Json, OutOpt, Seed};
use crate::cli::output::{print_json, progress_bar};
use clap::Args;
use gyro_lab_core::data::csv_writer::CellFormat::{Exp, Fixed, Shortest};
use gyro_lab_core::data::run_file::{Column, RunWriter};
use gyro_lab_core::error::LabError;
use gyro_lab_core::sim::fog_run::{
    FogRow, FogRun, FogRunError, FogRunParam, FogRunParams, Vibration,
};

#[derive(Args, Debug, Clone)]
#[command(
    mut_arg("seed", |a| a.help("Noise seed")),
    mut_arg("out", |a| a.help("A file: a run file to write (CSV, means over 25 closure steps)"))
)]
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
    /// Simulated time, s (the mean error is taken after the start-up, see
    /// --settle-s).
    #[arg(long, default_value_t = 4.0)]
    pub duration_s: f64,
    /// Turn the online epsilon-squared correction off.
    #[arg(long)]
    pub no_vibration_correction: bool,
    /// Shot and intensity noise on.
    #[arg(long)]
    pub noise: bool,
    #[command(flatten)]
    pub seed: Seed,
    /// Main-loop gain (fraction of the residual corrected per step).
    #[arg(long, default_value_t = 1.0)]
    pub loop_gain: f64,
    /// 2*pi gain-loop gain while it acquires (0, with
    /// --gain-loop-track-gain 0, holds the digital gain at nominal).
    #[arg(long, default_value_t = 0.05)]
    pub gain_loop_gain: f64,
    /// 2*pi gain-loop gain once in lock for 0.25 s (the gear shift).
    #[arg(long, default_value_t = 1e-4)]
    pub gain_loop_track_gain: f64,
    /// Modulator gain error (V_pi off nominal), relative.
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
    pub vpi_error: f64,
    /// ADC resolution, bits.
    #[arg(long, default_value_t = 12)]
    pub adc_bits: u32,
    /// Modulation-depth dither, half width in ADC codes of the detector level (0 = off).
    #[arg(long, default_value_t = 60.0)]
    pub dither_codes: f64,
    /// Start-up time left out of the mean error, s (default: five time
    /// constants of the AGC's DC filter, 1.64 s at 12.5 kHz; at most half
    /// the run).
    #[arg(long)]
    pub settle_s: Option<f64>,
    /// DAC latency, closures: 1 simulates the hw board's DMA ping-pong (the
    /// words computed in one closure drive the modulator in the next), as
    /// the rig does; 0 (QEMU, the host rigs) applies them at once.
    #[arg(long, default_value_t = 0, value_name = "CLOSURES")]
    pub dac_latency: u32,
    #[command(flatten)]
    pub out: OutOpt,
    #[command(flatten)]
    pub json: Json,
}

impl FogArgs {
    fn params(&self) -> FogRunParams {
        FogRunParams {
            phi0_rad: self.phi0_rad,
            closure_hz: self.closure_hz,
            rate_dps: self.rate_dps,
            vibration: match (self.vibration_dps2, self.vibration_hz) {
                (Some(dps2), Some(hz)) => Some(Vibration { dps2, hz }),
                _ => None,
            },
            levels: self.vibration_levels.clone(),
            duration_s: self.duration_s,
            vibration_correction: !self.no_vibration_correction,
            noise: self.noise,
            seed: self.seed.seed,
            loop_gain: self.loop_gain,
            gain_loop_gain: self.gain_loop_gain,
            gain_loop_track_gain: self.gain_loop_track_gain,
            vpi_error: self.vpi_error,
            adc_bits: self.adc_bits,
            dither_codes: self.dither_codes,
            settle_s: self.settle_s,
            dac_latency: self.dac_latency,
        }
    }
}

fn usage(e: FogRunError) -> LabError {
    LabError::Usage(match e {
        FogRunError::OutOfRange(p, v) => {
            let name = match p {
                FogRunParam::Duration => "duration-s",
                FogRunParam::Rate => "rate-dps",
                FogRunParam::AdcBits => "adc-bits",
                FogRunParam::VibrationLevels => "vibration-levels",
                FogRunParam::VibrationDps2 => "vibration-dps2",
                FogRunParam::VibrationHz => "vibration-hz",
                FogRunParam::DacLatency => "dac-latency",
            };
            format!("--{name} {v}: out of range")
        }
        FogRunError::Loop(why) => format!("invalid loop parameters: {why}"),
        FogRunError::TooManyLevels => "--vibration-levels: at most 8".into(),
        FogRunError::ShorterThanPeriod => {
            "--duration-s is shorter than one oscillation period".into()
        }
    })
}

pub fn run(a: &FogArgs) -> Result<(), LabError> {
    let fog = FogRun::new(&a.params()).map_err(usage)?;
    let steps = fog.steps();
    let bar = progress_bar(
        steps,
        "{bar:40} {percent}% {eta}",
        steps <= 200_000 || a.json.json,
    );
    let mut writer = match &a.out.out {
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
    let progress = |k| bar.set_position(k);
    let s = match writer.as_mut() {
        Some(w) => fog.run(Some(&mut |r: &FogRow| w.row(r)), progress)?,
        None => fog.run::<LabError>(None, progress)?,
    };
    bar.finish_and_clear();
    if let Some(w) = writer {
        w.finish()?;
    }
    if !s.settled {
        eprintln!(
            "warning: --duration-s {} is too short to leave out the whole start-up: the mean is taken \
             after {:.3} s and still holds some of the loops' settling (give --duration-s of at least \
             twice the settling time, or --settle-s)",
            a.duration_s, s.settle_s
        );
    }
    if a.json.json {
        return print_json(&s);
    }
    let pm = |v: f64, se: Option<f64>| match se {
        Some(se) => format!("{v:+.6} +- {se:.6}"),
        None => format!("{v:+.6} (standard error unknown: under 2 batches)"),
    };
    println!(
        "mean error over {:.3} s after a start-up of {:.3} s: {} deg/h corrected, {} deg/h raw \
         (formula drift {:+.6} deg/h)",
        s.averaged_s,
        s.settle_s,
        pm(s.mean_error_dph, s.mean_error_stderr_dph),
        pm(s.mean_error_raw_dph, s.mean_error_raw_stderr_dph),
        s.predicted_drift_dph
    );
    for (what, v, se) in [
        ("corrected", s.mean_error_dph, s.mean_error_stderr_dph),
        ("raw", s.mean_error_raw_dph, s.mean_error_raw_stderr_dph),
    ] {
        if let Some(se) = se {
            if v.abs() < 2.0 * se {
                println!(
                    "note: the {what} mean is consistent with zero (within two standard errors)"
                );
            } else if se > 0.1 * v.abs() {
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
    Ok(())
}
