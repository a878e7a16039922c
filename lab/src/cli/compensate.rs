//! `gyro-lab compensate`: either kind of coefficient file (by its `kind`)
//! applied to a run as the firmware applies it (the same code, the same
//! fixed-point arithmetic); the run written back with `rate_comp_dps`.

use crate::calibration::scale_factor::compensation::compensate_rows;
use crate::calibration::scale_factor::residual::{window_rms_ppm, RESIDUAL_WINDOW_S};
use crate::calibration::thermal::compensation::compensate;
use crate::calibration::thermal::fit::CubicModel;
use crate::calibration::thermal::summary::compensation_summary;
use crate::cli::args::{Json, Out};
use crate::cli::output::print_json;
use crate::cli::run_inputs::thermal_run;
use crate::data::run_file::{Column, RunFile};
use crate::error::LabError;
use clap::Args;
use gyro_coeffs::file::Coeffs;
use gyro_coeffs::ScaleFactorTable;
use gyro_sp::rlg::ThermalCoeffs;
use std::path::PathBuf;

#[derive(Args, Debug, Clone)]
pub struct CompensateArgs {
    /// Coefficient file (from `gyro-lab fit`).
    #[arg(long)]
    pub coeffs: PathBuf,
    #[arg(long)]
    pub data: PathBuf,
    #[command(flatten)]
    pub out: Out,
    /// Also fit the classic cubic on this file and report it (comparison only).
    #[arg(long)]
    pub cubic_from: Option<PathBuf>,
    #[command(flatten)]
    pub json: Json,
}

pub fn run(a: &CompensateArgs) -> Result<(), LabError> {
    let (_, coeffs) =
        gyro_coeffs::file::read(&a.coeffs).map_err(|e| LabError::coeffs_input(&a.coeffs, &e))?;
    match coeffs {
        Coeffs::RlgThermal(c) => rlg_thermal(a, &c),
        Coeffs::FogScaleFactor(t) => fog_scale_factor(a, &t),
    }
}

fn rlg_thermal(a: &CompensateArgs, c: &ThermalCoeffs) -> Result<(), LabError> {
    let (text, d) = thermal_run(&a.data)?;
    let (comp, flags) = compensate(c, &d, &text.run.rate_dps);
    text.write_back(&a.out.out, &[(Column::CompensatedRate, &comp)])?;
    let cubic = match &a.cubic_from {
        Some(p) => {
            let (_, dc) = thermal_run(p)?;
            Some(
                CubicModel::fit(&dc.a, &dc.drift_dph)
                    .ok_or_else(|| LabError::input(p, "cubic fit failed"))?,
            )
        }
        None => None,
    };
    let s = compensation_summary(
        c,
        &d,
        &text.run.ref_rate_dps,
        (&comp, &flags),
        cubic.as_ref(),
    );
    if a.json.json {
        return print_json(&s);
    }
    println!(
        "std of 100 s means: raw {:.4} +- {:.4} deg/h, compensated {:.4} +- {:.4} deg/h ({:.2}x the noise floor {:.4} +- {:.4}){}",
        s.raw_std_100s_dph,
        s.raw_std_100s_se_dph,
        s.comp_std_100s_dph,
        s.comp_std_100s_se_dph,
        s.comp_over_floor,
        s.noise_floor_100s_dph,
        s.noise_floor_100s_se_dph,
        s.cubic_std_100s_dph
            .map_or(String::new(), |v| format!(", classic cubic {v:.4}"))
    );
    if s.coeffs_refused {
        println!(
            "coefficients refused by the firmware check: ran on the safe set (no compensation)"
        );
    }
    println!("written: {}", a.out.out.display());
    Ok(())
}

/// JSON of `compensate` with a scale-factor table.
#[derive(serde::Serialize)]
struct ScaleFactorJson {
    /// RMS of the scale-factor error over 60 s means of the rotating rows,
    /// ppm, before and after, with standard errors.
    raw_ppm: f64,
    raw_ppm_se: f64,
    comp_ppm: f64,
    comp_ppm_se: f64,
    windows: usize,
    flags_seen: u8,
    out: String,
}

fn fog_scale_factor(a: &CompensateArgs, table: &ScaleFactorTable) -> Result<(), LabError> {
    let (text, [temp]) = RunFile::read(&a.data, 2, [Column::Temp])?;
    let (t, w, y) = (&text.run.t_s, &text.run.ref_rate_dps, &text.run.rate_dps);
    let (comp, flags) = compensate_rows(table, t, y, &temp);
    text.write_back(&a.out.out, &[(Column::CompensatedRate, &comp)])?;
    let err = |v: &[f64]| -> Vec<f64> { v.iter().zip(w).map(|(a, b)| a - b).collect() };
    let (raw, raw_se, _) = window_rms_ppm(t, w, &err(y), RESIDUAL_WINDOW_S);
    let (c, c_se, m) = window_rms_ppm(t, w, &err(&comp), RESIDUAL_WINDOW_S);
    let s = ScaleFactorJson {
        raw_ppm: raw,
        raw_ppm_se: raw_se,
        comp_ppm: c,
        comp_ppm_se: c_se,
        windows: m,
        flags_seen: flags.iter().fold(0, |x, f| x | f),
        out: a.out.out.display().to_string(),
    };
    if a.json.json {
        return print_json(&s);
    }
    if m == 0 {
        println!("no 60 s stretch at a constant nonzero rate: no scale-factor figure");
    } else {
        println!(
            "scale-factor error, RMS of {m} 60 s means: raw {raw:.2} +- {raw_se:.2} ppm, compensated {c:.3} +- {c_se:.3} ppm"
        );
    }
    if s.flags_seen != 0 {
        println!(
            "flags seen {:#04x} (1 coil sensor bad, 2 outside the calibrated range, 4 table refused)",
            s.flags_seen
        );
    }
    println!("written: {}", a.out.out.display());
    Ok(())
}
