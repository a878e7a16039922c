//! `gyro-lab compensate`: a coefficient file (by its `kind`) applied to a
//! run as the firmware applies it (the same code, the same fixed-point
//! arithmetic), or a model from `discover` (`gyro_model`: what the model
//! adds to the reference rate taken off the output,
//! compensate_model.rs); the run written back with `rate_comp_dps`.

use crate::calibration::scale_factor::validation::{validate, Validation};
use crate::calibration::thermal::compensation::compensate;
use crate::calibration::thermal::fit::CubicModel;
use crate::calibration::thermal::summary::{
    compensation_summary, CalibratedRange, CompensateSummary,
};
use crate::cli::args::{Json, NoReport, Out, RunRead};
use crate::cli::checks::Checked;
use crate::cli::compensate_model::{self, Target};
use crate::cli::out_path::{self, FileKind};
use crate::cli::output::write_report;
use crate::cli::reports;
use crate::cli::run_inputs::thermal_run;
use crate::data::run_file::{Column, Reference, RunFile};
use crate::error::LabError;
use clap::Args;
use gyro_coeffs::file::Coeffs;
use gyro_coeffs::ScaleFactorTable;
use gyro_sp::rlg::ThermalCoeffs;
use std::path::PathBuf;

#[derive(Args, Debug, Clone)]
#[command(mut_arg("out", |a| a.help("A file: the run written back with the compensated rate added (CSV); its report is written beside it (.html)")))]
pub struct CompensateArgs {
    /// Coefficient file: `rlg_thermal` or `fog_scale_factor` (from `gyro-lab
    /// fit`), or a `gyro_model` (from `gyro-lab discover`).
    #[arg(long)]
    pub coeffs: PathBuf,
    /// Run file to compensate (t_s, rate_dps, and the temperature columns the
    /// coefficients need).
    #[arg(long)]
    pub data: PathBuf,
    #[command(flatten)]
    pub read: RunRead,
    #[command(flatten)]
    pub out: Out,
    /// Also fit the classic cubic on this file and report it (comparison only).
    #[arg(long)]
    pub cubic_from: Option<PathBuf>,
    #[command(flatten)]
    pub no_report: NoReport,
    #[command(flatten)]
    pub json: Json,
}

/// JSON of `compensate` with RLG thermal coefficients.
#[derive(serde::Serialize)]
struct ThermalJson<'a> {
    #[serde(flatten)]
    s: &'a CompensateSummary,
    report: Option<String>,
}

/// The kinds of file `compensate` applies.
pub const KINDS: &str =
    "rlg_thermal or fog_scale_factor (from gyro-lab fit), gyro_model (from gyro-lab discover)";

pub fn run(a: &CompensateArgs) -> Result<(), LabError> {
    let spec = a.read.spec()?;
    let beside: Vec<_> = match a.no_report.no_report {
        false => vec![(out_path::report_beside(&a.out.out), FileKind::Html)],
        true => vec![],
    };
    let mut inputs = vec![
        ("--data", a.data.as_path()),
        ("--coeffs", a.coeffs.as_path()),
    ];
    if let Some(c) = &a.cubic_from {
        inputs.push(("--cubic-from", c.as_path()));
    }
    out_path::file(
        "compensate",
        &a.out.out,
        FileKind::Csv,
        &beside,
        &inputs,
        a.out.force,
    )?;
    let text = std::fs::read_to_string(&a.coeffs)
        .map_err(|e| LabError::input(&a.coeffs, format!("cannot read: {e}")))?;
    if kind_of(&text).as_deref() == Some("gyro_model") {
        let target = Target {
            coeffs: &a.coeffs,
            data: &a.data,
            out: &a.out.out,
            report: !a.no_report.no_report,
            json: a.json.json,
        };
        return compensate_model::run(&target, &spec);
    }
    let (file, coeffs) = gyro_coeffs::file::read(&a.coeffs).map_err(|e| {
        let e = if e.contains("unknown coefficient kind") {
            format!("{e}: compensate applies {KINDS}")
        } else {
            e
        };
        LabError::coeffs_input(&a.coeffs, &e)
    })?;
    match coeffs {
        Coeffs::RlgThermal(c) => {
            rlg_thermal(a, &spec, &c, file.fit.as_ref().and_then(thermal_range))
        }
        Coeffs::FogScaleFactor(t) => fog_scale_factor(a, &spec, &t),
    }
}

/// The `kind` a TOML file declares, if it reads as TOML and has one.
fn kind_of(text: &str) -> Option<String> {
    let t: toml::Table = toml::from_str(text).ok()?;
    t.get("kind")?.as_str().map(str::to_owned)
}

/// Prints the JSON with the record checks added.
fn emit<T: serde::Serialize>(v: &T, c: &Checked) -> Result<(), LabError> {
    let mut j = serde_json::to_value(v).unwrap_or_default();
    c.json(&mut j);
    println!("{j}");
    Ok(())
}

/// The temperatures a thermal fit saw, from its file's `[fit]` table
/// (files written before they were kept there have none).
fn thermal_range(fit: &toml::Table) -> Option<CalibratedRange> {
    let pair = |k: &str| -> Option<[f64; 2]> {
        let v = fit.get(k)?.as_array()?;
        let f = |i: usize| {
            v.get(i)
                .and_then(|x| x.as_float().or(x.as_integer().map(|n| n as f64)))
        };
        Some([f(0)?, f(1)?])
    };
    Some(CalibratedRange {
        mono_a_c: pair("mono_a_range_c")?,
        case_c: pair("case_range_c")?,
    })
}

fn rlg_thermal(
    a: &CompensateArgs,
    spec: &crate::data::read_spec::ReadSpec,
    c: &ThermalCoeffs,
    range: Option<CalibratedRange>,
) -> Result<(), LabError> {
    let (text, d, checked) = thermal_run(&a.data, spec)?;
    let (comp, flags) = compensate(c, &d, &text.run.rate_dps);
    compensate_model::write_back(&a.coeffs, &a.data, &a.out.out, &text, &comp)?;
    let cubic = match &a.cubic_from {
        Some(p) => {
            let (_, dc, _) = thermal_run(p, spec)?;
            Some(
                CubicModel::fit(&dc.a, &dc.drift_dph)
                    .ok_or_else(|| LabError::input(p, "cubic fit failed"))?,
            )
        }
        None => None,
    };
    let mut s = compensation_summary(
        c,
        &d,
        &text.run.ref_rate_dps,
        (&comp, &flags),
        cubic.as_ref(),
        range,
    );
    s.warnings.splice(0..0, checked.calibration_warnings());
    let report = (!a.no_report.no_report).then(|| reports::beside(&a.out.out));
    if let Some(path) = &report {
        let names = (a.coeffs.display().to_string(), a.data.display().to_string());
        write_report(&reports::compensate::thermal(&names, &d, &s), path)?;
    }
    if a.json.json {
        return emit(
            &ThermalJson {
                s: &s,
                report: report.map(|p| p.display().to_string()),
            },
            &checked,
        );
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
    for w in &s.warnings {
        println!("warning: {}", w.message);
    }
    println!("written: {}", a.out.out.display());
    if let Some(p) = report {
        println!("report: {}", p.display());
    }
    Ok(())
}

/// JSON of `compensate` with a scale-factor table.
#[derive(serde::Serialize)]
struct ScaleFactorJson<'a> {
    /// RMS of the scale-factor error over 60 s means of the rotating rows,
    /// ppm, before and after, with standard errors.
    raw_ppm: f64,
    raw_ppm_se: f64,
    comp_ppm: f64,
    comp_ppm_se: f64,
    windows: usize,
    flags_seen: u8,
    out: String,
    #[serde(flatten)]
    v: &'a Validation,
    report: Option<String>,
}

fn fog_scale_factor(
    a: &CompensateArgs,
    spec: &crate::data::read_spec::ReadSpec,
    table: &ScaleFactorTable,
) -> Result<(), LabError> {
    let (mut text, [temp]) =
        RunFile::read(&a.data, spec, Reference::ZeroIfAbsent, 2, [Column::Temp])?;
    let checked = crate::cli::checks::run(&mut text.run, spec)?;
    let (t, w, y) = (&text.run.t_s, &text.run.ref_rate_dps, &text.run.rate_dps);
    let mut v = validate(table, t, w, y, &temp);
    v.warnings.splice(0..0, checked.calibration_warnings());
    compensate_model::write_back(&a.coeffs, &a.data, &a.out.out, &text, &v.comp_dps)?;
    let report = (!a.no_report.no_report).then(|| reports::beside(&a.out.out));
    if let Some(path) = &report {
        let names = (a.coeffs.display().to_string(), a.data.display().to_string());
        write_report(&reports::compensate::scale_factor(&names, &v), path)?;
    }
    let (raw, raw_se, c, c_se, m) = (
        v.raw_ppm.value,
        v.raw_ppm.se,
        v.comp_ppm.value,
        v.comp_ppm.se,
        v.windows,
    );
    if a.json.json {
        return emit(
            &ScaleFactorJson {
                raw_ppm: raw,
                raw_ppm_se: raw_se,
                comp_ppm: c,
                comp_ppm_se: c_se,
                windows: m,
                flags_seen: v.flags_seen,
                out: a.out.out.display().to_string(),
                v: &v,
                report: report.map(|p| p.display().to_string()),
            },
            &checked,
        );
    }
    if m == 0 {
        println!("no 60 s stretch at a constant nonzero rate: no scale-factor figure");
    } else {
        println!(
            "scale-factor error, RMS of {m} 60 s means: raw {raw:.2} +- {raw_se:.2} ppm, compensated {c:.3} +- {c_se:.3} ppm (noise floor {:.3})",
            v.noise_floor_ppm.value
        );
    }
    if v.flags_seen != 0 {
        println!(
            "flags seen {:#04x} (1 coil sensor bad, 2 outside the calibrated range, 4 table refused)",
            v.flags_seen
        );
    }
    for w in &v.warnings {
        println!("warning: {}", w.message);
    }
    println!("written: {}", a.out.out.display());
    if let Some(p) = report {
        println!("report: {}", p.display());
    }
    Ok(())
}
