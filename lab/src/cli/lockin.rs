//! `gyro-lab lockin`: the RLG lock-in rate of a fringe record by the exact
//! harmonic relation (calibration/lockin.rs).

use crate::calibration::lockin::{lock_in, LockIn};
use crate::cli::args::{Json, OutOpt, RunRead};
use crate::cli::out_path::{self, FileKind};
use crate::cli::output::write_report;
use crate::cli::reports;
use crate::data::fringe_file::FringeFile;
use crate::error::LabError;
use clap::Args;
use std::path::PathBuf;

#[derive(Args, Debug, Clone)]
#[command(mut_arg("out", |a| a.help("A folder: report.html is written in it")))]
pub struct LockinArgs {
    /// Fringe file: `t_s`, `signal`, optional `signal_q`.
    #[arg(long)]
    pub data: PathBuf,
    #[command(flatten)]
    pub read: RunRead,
    /// Scale factor K, pulses (fringes) per degree.
    #[arg(long)]
    pub pulses_per_deg: f64,
    /// Input rate, deg/s (estimated from the record when not given).
    #[arg(long, allow_negative_numbers = true)]
    pub input_rate_dps: Option<f64>,
    #[command(flatten)]
    pub out: OutOpt,
    #[command(flatten)]
    pub json: Json,
}

/// JSON of `lockin`: the estimate and the report's path.
#[derive(serde::Serialize)]
struct LockinJson<'a> {
    #[serde(flatten)]
    r: &'a LockIn,
    report: Option<String>,
}

/// The least lock-in rate a ring laser gyro has, deg/s (physics.md 2.1
/// gives 0.01 .. 0.5 for the reference gyros).
pub const LOCK_IN_MIN_DPS: f64 = 0.002;

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
    let spec = a.read.spec()?;
    if let Some(dir) = &a.out.out {
        out_path::folder(
            "lockin",
            dir,
            &[("report.html", FileKind::Html)],
            &[("--data", &a.data)],
            a.out.force,
        )?;
    }
    let mut f = FringeFile::read(&a.data, &spec, 64)?;
    let sampling = crate::record::sampling::regularise(&mut f.t_s);
    let mut r = lock_in(
        &f.t_s,
        &f.signal,
        f.signal_q.as_deref(),
        a.pulses_per_deg,
        a.input_rate_dps,
    )
    .map_err(|e| LabError::input(&a.data, e.to_string()))?;
    // Lock-in rates of real RLGs are 0.01 .. 1 deg/s (physics.md 2.1): far
    // below, the record's time or K is likely in another unit.
    if r.lock_in_dps < LOCK_IN_MIN_DPS {
        r.warnings.push(crate::calibration::warning::Warning::new(
            "unit",
            format!(
                "a lock-in of {} deg/s is below any RLG's ({LOCK_IN_MIN_DPS} deg/s at least): is the time column in ms (--time-unit ms, a factor of 1000) or K in another unit?",
                crate::report::text::sig(r.lock_in_dps)
            ),
        ));
    }
    let report = match &a.out.out {
        Some(dir) => {
            out_path::make(dir)?;
            let path = dir.join("report.html");
            let name = a.data.display().to_string();
            write_report(
                &reports::lockin::report(&name, &f.t_s, &f.signal, &r),
                &path,
            )?;
            Some(path)
        }
        None => None,
    };
    if a.json.json {
        let mut j = serde_json::to_value(LockinJson {
            r: &r,
            report: report.map(|p| p.display().to_string()),
        })
        .unwrap_or_default();
        j["sampling"] = serde_json::to_value(&sampling).unwrap_or_default();
        if let Some(w) = sampling.warning() {
            let mut list = j["warnings"].as_array().cloned().unwrap_or_default();
            list.push(serde_json::to_value(w).unwrap_or_default());
            j["warnings"] = list.into();
        }
        println!("{j}");
    } else {
        if let Some(w) = sampling.warning() {
            println!("WARNING ({}): {}", w.code, w.message);
        }
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
        println!(
            "relative one-sigma {:.4} % against the Cramer-Rao bound {:.4} % (Omega_I/Omega_L {:.1})",
            100.0 * r.lock_in_rel_std,
            100.0 * r.cramer_rao_rel,
            r.rate_ratio
        );
        for w in &r.warnings {
            println!("warning: {}", w.message);
        }
        if let Some(p) = report {
            println!("report: {}", p.display());
        }
    }
    Ok(())
}
