//! `gyro-lab lockin`: the RLG lock-in rate of a fringe record by the exact
//! harmonic relation (calibration/lockin.rs).

use crate::calibration::lockin::lock_in;
use crate::cli::args::Json;
use crate::cli::output::print_json;
use crate::data::fringe_file::FringeFile;
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
    #[command(flatten)]
    pub json: Json,
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
    let r = lock_in(
        &f.t_s,
        &f.signal,
        f.signal_q.as_deref(),
        a.pulses_per_deg,
        a.input_rate_dps,
    )
    .map_err(|e| LabError::input(&a.data, e.to_string()))?;
    if a.json.json {
        print_json(&r)?;
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
