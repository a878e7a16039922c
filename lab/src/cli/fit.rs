//! `gyro-lab fit thermal` and `gyro-lab fit scale-factor`: the
//! calibrations of calibration/ on a test-rig run, written as the
//! coefficient files the firmware loads.

use crate::calibration::scale_factor::diagnostics::diagnostics;
use crate::calibration::scale_factor::fit::fit;
use crate::calibration::scale_factor::multipoint::Plateau;
use crate::calibration::scale_factor::result::SfFit;
use crate::calibration::thermal::summary::{calibrate, FitSummary};
use crate::cli::args::{Json, NoReport, Out, RunRead};
use crate::cli::checks::Checked;
use crate::cli::out_path::{self, FileKind};
use crate::cli::output::write_report;
use crate::cli::reports;
use crate::cli::run_inputs::{scale_factor_run, thermal_run};
use crate::error::LabError;
use clap::Args;
use gyro_coeffs::file::{CoeffFile, FittedRange};
use std::path::PathBuf;

#[derive(Args, Debug, Clone)]
#[command(mut_arg("out", |a| a.help("A file: the coefficient set (TOML, what the firmware loads); its report is written beside it (.html)")))]
pub struct FitThermalArgs {
    /// Chamber run file (t_s, ref_rate_dps, rate_dps, t_mono_a_c, t_mono_b_c, t_case_c).
    #[arg(long)]
    pub data: PathBuf,
    #[command(flatten)]
    pub read: RunRead,
    #[command(flatten)]
    pub out: Out,
    #[command(flatten)]
    pub no_report: NoReport,
    #[command(flatten)]
    pub json: Json,
}

/// JSON of `fit thermal`: the summary and the report's path.
#[derive(serde::Serialize)]
struct ThermalJson<'a> {
    #[serde(flatten)]
    summary: &'a FitSummary,
    report: Option<String>,
}

/// `--out` for a fit: a TOML file of `kind`, its report beside it.
fn check_out(
    command: &str,
    out: &Out,
    kind: &'static str,
    data: &std::path::Path,
    report: bool,
) -> Result<(), LabError> {
    let beside: Vec<_> = match report {
        true => vec![(out_path::report_beside(&out.out), FileKind::Html)],
        false => vec![],
    };
    out_path::file(
        command,
        &out.out,
        FileKind::Toml(kind),
        &beside,
        &[("--data", data)],
        out.force,
    )
}

/// Adds the record checks to a fit's JSON and prints them as text.
fn emit(c: &Checked, json: Option<serde_json::Value>) -> Result<(), LabError> {
    match json {
        Some(mut j) => {
            c.json(&mut j);
            println!("{j}");
        }
        None => c.print(),
    }
    Ok(())
}

pub fn thermal(a: &FitThermalArgs) -> Result<(), LabError> {
    let spec = a.read.spec()?;
    check_out(
        "fit thermal",
        &a.out,
        "rlg_thermal",
        &a.data,
        !a.no_report.no_report,
    )?;
    let (_, d, checked) = thermal_run(&a.data, &spec)?;
    let mut s = calibrate(&d).map_err(|e| LabError::input(&a.data, e.to_string()))?;
    s.warnings.splice(0..0, checked.calibration_warnings());
    let c = s.coefficients;
    let mut info = toml::Table::new();
    info.insert("data".into(), a.data.display().to_string().into());
    info.insert("rows".into(), (d.t.len() as i64).into());
    for (k, v) in [
        ("raw_std_100s_dph", s.raw_std_100s_dph),
        ("residual_std_100s_dph", s.residual_std_100s_dph),
        ("cubic_std_100s_dph", s.cubic_std_100s_dph),
        ("noise_floor_100s_dph", s.noise_floor_100s_dph),
    ] {
        info.insert(k.into(), v.into());
    }
    for (k, [lo, hi]) in [
        ("mono_a_range_c", s.mono_a_range_c),
        ("case_range_c", s.case_range_c),
    ] {
        info.insert(k.into(), toml::Value::Array(vec![lo.into(), hi.into()]));
    }
    info.insert(
        "record_crc32".into(),
        format!("0x{:08x}", gyro_coeffs::record::crc_of(&c.to_record())).into(),
    );
    let mut file = CoeffFile::rlg_thermal(c, info);
    let lo = s.mono_a_range_c[0].min(s.case_range_c[0]);
    let hi = s.mono_a_range_c[1].max(s.case_range_c[1]);
    file.range = Some(FittedRange { temp_c: [lo, hi] });
    gyro_coeffs::file::write(
        &a.out.out,
        &file,
        "RLG thermal bias model (docs/rlg.md), written by gyro-lab fit thermal.\n\
         B = bias0 + k1*dT + k2*grad(dT) + k3*dT^2 + k4*T_K + k5*(1 - exp(-t/tau_warm)), deg/h;\n\
         dT = t_mono_a - t_mono_b. Load with `gyro-lab compensate` or build the firmware with RLG_COEFFS=<this file>.",
    )
    .map_err(|e| LabError::coeffs_io(&a.out.out, &e))?;
    let report = (!a.no_report.no_report).then(|| reports::beside(&a.out.out));
    if let Some(path) = &report {
        let name = a.data.display().to_string();
        write_report(&reports::thermal::report(&name, &d, &s), path)?;
    }
    if a.json.json {
        let j = serde_json::to_value(ThermalJson {
            summary: &s,
            report: report.map(|p| p.display().to_string()),
        })
        .unwrap_or_default();
        emit(&checked, Some(j))?;
    } else {
        let v = s.coefficients.values();
        let e = s.coefficient_se.map(|c| c.values());
        let names = gyro_sp::rlg::ThermalCoeffs::NAMES;
        for (k, n) in names.iter().enumerate() {
            match e {
                Some(e) => println!("  {n:<20} {:>12.6} +- {:.6}", v[k], e[k]),
                None => println!("  {n:<20} {:>12.6} (standard error not available)", v[k]),
            }
        }
        let se = s.std_100s_se_dph;
        println!(
            "std of 100 s means (+- standard error): raw {:.4} +- {:.4} deg/h, classic cubic {:.4} +- {:.4}, \
             improved model {:.4} +- {:.4}, noise floor {:.4} +- {:.4}",
            s.raw_std_100s_dph,
            se[0],
            s.cubic_std_100s_dph,
            se[2],
            s.residual_std_100s_dph,
            se[1],
            s.noise_floor_100s_dph,
            se[3]
        );
        for w in &s.warnings {
            println!("warning: {}", w.message);
        }
        println!("written: {}", a.out.out.display());
        if let Some(p) = report {
            println!("report: {}", p.display());
        }
    }
    Ok(())
}

#[derive(Args, Debug, Clone)]
#[command(mut_arg("out", |a| a.help("A file: the coefficient set (TOML, what the firmware loads); its report is written beside it (.html)")))]
pub struct FitScaleFactorArgs {
    /// Run file: continuous-rotation or multi-point (t_s, ref_rate_dps, rate_dps, temp_c).
    #[arg(long)]
    pub data: PathBuf,
    #[command(flatten)]
    pub read: RunRead,
    #[command(flatten)]
    pub out: Out,
    #[command(flatten)]
    pub no_report: NoReport,
    #[command(flatten)]
    pub json: Json,
}

/// JSON of `fit scale-factor` (docs/interfaces.md keys first).
#[derive(serde::Serialize)]
struct FitJson<'a> {
    knees_c: Vec<f64>,
    knees_ci_c: Vec<[f64; 2]>,
    residual_ppm: f64,
    residual_ppm_se: f64,
    /// The fit itself, `segments`, `model` and `degree` among its keys.
    #[serde(flatten)]
    fit: &'a SfFit,
    #[serde(skip_serializing_if = "Option::is_none")]
    plateaus: Option<&'a [Plateau]>,
    table: TableJson,
    out: String,
    /// The report written beside `out` (null with --no-report).
    report: Option<String>,
}

#[derive(serde::Serialize)]
struct TableJson {
    temps_c: Vec<f64>,
    sf_ppm: Vec<f64>,
    bias_dph: Vec<f64>,
    sensor_lag_s: f64,
    record_crc32: String,
}

pub fn scale_factor(a: &FitScaleFactorArgs) -> Result<(), LabError> {
    let spec = a.read.spec()?;
    check_out(
        "fit scale-factor",
        &a.out,
        "fog_scale_factor",
        &a.data,
        !a.no_report.no_report,
    )?;
    let (inp, checked) = scale_factor_run(&a.data, &spec)?;
    let (mut f, plateaus) = fit(&inp).map_err(|e| LabError::input(&a.data, e.to_string()))?;
    f.warnings.splice(0..0, checked.calibration_warnings());
    f.table.check().map_err(|_| {
        LabError::input(
            &a.data,
            format!(
                "the fitted table is outside what the firmware holds ({}): this run does not \
                 determine the scale factor over temperature; fit on a continuous-rotation run at \
                 50 deg/s or more through the chamber's range (e.g. `gyro-lab simulate scale-factor`)",
                table_problem(&f.table)
            ),
        )
    })?;
    let crc = write_table(a, &f)?;
    let report = (!a.no_report.no_report).then(|| reports::beside(&a.out.out));
    if let Some(path) = &report {
        let d = diagnostics(&inp, &f);
        let name = a.data.display().to_string();
        let r = reports::scale_factor::report(&name, &f, &d, plateaus.as_deref());
        write_report(&r, path)?;
    }
    let n = f.table.n;
    if a.json.json {
        let j = serde_json::to_value(FitJson {
            knees_c: f.knees.iter().map(|k| k.value).collect(),
            knees_ci_c: f.knees.iter().map(|k| [k.lo, k.hi]).collect(),
            residual_ppm: f.residual_ppm.value,
            residual_ppm_se: f.residual_ppm.se,
            fit: &f,
            plateaus: plateaus.as_deref(),
            table: TableJson {
                temps_c: f.table.temps_c[..n].to_vec(),
                sf_ppm: f.table.sf_ppm[..n].to_vec(),
                bias_dph: f.table.bias_dph[..n].to_vec(),
                sensor_lag_s: f.table.sensor_lag_s,
                record_crc32: crc,
            },
            out: a.out.out.display().to_string(),
            report: report.map(|p| p.display().to_string()),
        })
        .unwrap_or_default();
        return emit(&checked, Some(j));
    }
    print_text(&f, &crc, &a.out.out);
    if let Some(p) = report {
        println!("report: {}", p.display());
    }
    Ok(())
}

/// Writes the coefficient file of the fit; its record's CRC.
fn write_table(a: &FitScaleFactorArgs, f: &SfFit) -> Result<String, LabError> {
    let record = f.table.to_record();
    let crc = format!("0x{:08x}", gyro_coeffs::record::crc_of(&record));
    let mut info = toml::Table::new();
    info.insert("data".into(), a.data.display().to_string().into());
    info.insert("method".into(), f.method.name().into());
    info.insert(
        "knees_c".into(),
        toml::Value::Array(f.knees.iter().map(|k| k.value.into()).collect()),
    );
    info.insert("residual_ppm".into(), f.residual_ppm.value.into());
    info.insert("record_crc32".into(), crc.clone().into());
    let mut file = CoeffFile::fog_scale_factor(&f.table, info);
    file.range = Some(FittedRange { temp_c: f.range_c });
    gyro_coeffs::file::write(
        &a.out.out,
        &file,
        "FOG scale factor and bias over coil temperature (docs/fog.md), written by gyro-lab fit scale-factor.\n\
         output = (1 + sf_ppm*1e-6)*rate + bias_dph, linear in the coil temperature between the nodes, held outside;\n\
         coil temperature = sensor + sensor_lag_s * d(sensor)/dt. Load with `gyro-lab compensate` or build the\n\
         firmware with FOG_SF_COEFFS=<this file>.",
    )
    .map_err(|e| LabError::coeffs_io(&a.out.out, &e))?;
    Ok(crc)
}

fn print_text(f: &SfFit, crc: &str, out: &std::path::Path) {
    println!(
        "{} fit, {} rows, coil {:.2} .. {:.2} degC",
        f.method, f.rows_used, f.range_c[0], f.range_c[1]
    );
    println!(
        "model: {} ({}), degree {}, {} knee(s); BIC margin over the next family {:.1}",
        f.model,
        f.model.describe(),
        f.degree,
        f.knees.len(),
        f.criterion_margin
    );
    for b in &f.families {
        println!(
            "  best {:<22} degree {} knees {}: BIC {:.1} ({:+.1})",
            b.model.name(),
            b.degree,
            b.knees,
            b.bic,
            b.delta_bic
        );
    }
    if f.knees.is_empty() {
        println!("knees: none (BIC by knee count: {:?})", rounded(&f.bic));
    }
    for k in &f.knees {
        println!(
            "knee at {:.2} degC (95 % interval {:.2} .. {:.2}); BIC by knee count {:?}",
            k.value,
            k.lo,
            k.hi,
            rounded(&f.bic)
        );
    }
    if let Some(p) = &f.polynomial {
        let terms: Vec<String> = p
            .coef_ppm
            .iter()
            .enumerate()
            .map(|(k, c)| format!("{:+.6} ({:.6}) x^{k}", c.value, c.se))
            .collect();
        println!(
            "polynomial, x = T - {} degC, ppm: {}",
            p.t_ref_c,
            terms.join(" ")
        );
    }
    let t = &f.tabulation;
    println!(
        "table: {} nodes, spacing {:?} degC, firmware lookup within {:.4} ppm of the model",
        t.nodes,
        t.spacing_c
            .iter()
            .map(|h| (h * 1000.0).round() / 1000.0)
            .collect::<Vec<_>>(),
        t.max_error_ppm
    );
    if f.segments.len() > 12 {
        println!(
            "  {} table segments (the polynomial tabulated): see the JSON's segments",
            f.segments.len()
        );
    }
    for s in f.segments.iter().filter(|_| f.segments.len() <= 12) {
        println!(
            "  {:7.2} .. {:7.2} degC: K_SF = 1 {:+.2} ppm ({:.2}) {:+.4} ppm/degC ({:.4}) x T",
            s.from_c,
            s.to_c,
            s.k0_ppm,
            s.k0_se * 1e6,
            s.k_t_ppm_per_c,
            s.k_t_se * 1e6
        );
    }
    if let Some(l) = f.sensor_lag_s {
        println!(
            "coil sensor lag {:.1} s (95 % interval {:.1} .. {:.1})",
            l.value, l.lo, l.hi
        );
    }
    if let Some(b) = f.bias {
        println!(
            "bias {:.4} +- {:.4} deg/h at 20 degC, {:+.5} +- {:.5} deg/h/degC",
            b.at_20c_dph.value, b.at_20c_dph.se, b.slope_dph_per_c.value, b.slope_dph_per_c.se
        );
    }
    for (name, e) in [
        ("asymmetry", f.asymmetry_ppm),
        ("nonlinearity", f.nonlinearity_ppm),
    ] {
        match e {
            Some(e) => println!("{name} {:.3} +- {:.3} ppm", e.value, e.se),
            None => println!("{name}: not measurable on this run"),
        }
    }
    println!(
        "residual {:.3} +- {:.3} ppm RMS of 60 s means (noise floor {:.3} +- {:.3})",
        f.residual_ppm.value, f.residual_ppm.se, f.noise_floor_ppm.value, f.noise_floor_ppm.se
    );
    for n in &f.notes {
        println!("note: {n}");
    }
    for w in &f.warnings {
        println!("warning: {}", w.message);
    }
    println!("written: {} (record CRC {crc})", out.display());
}

fn rounded(v: &[f64]) -> Vec<f64> {
    v.iter().map(|x| (x * 10.0).round() / 10.0).collect()
}

/// The first value of a fitted scale-factor table outside the firmware's
/// ranges, in words (gyro-coeffs' `check` says only that one is).
fn table_problem(t: &gyro_coeffs::ScaleFactorTable) -> String {
    use gyro_coeffs::fog_scale_factor::{
        BIAS_LIMIT_DPH, LAG_LIMIT_S, MAX_NODES, MIN_NODE_GAP_C, SF_LIMIT_PPM, T_MAX_C, T_MIN_C,
    };
    let n = t.n;
    if !(1..=MAX_NODES).contains(&n) {
        return format!("{n} nodes, 1 to {MAX_NODES} allowed");
    }
    for k in 0..n {
        let tc = t.temps_c[k];
        if !(tc.is_finite() && (T_MIN_C..=T_MAX_C).contains(&tc)) {
            return format!("node {k} at {tc:.2} degC, outside {T_MIN_C} .. {T_MAX_C}");
        }
        if k > 0 && tc - t.temps_c[k - 1] < MIN_NODE_GAP_C {
            return format!("nodes {} and {k} closer than {MIN_NODE_GAP_C} degC", k - 1);
        }
        let sf = t.sf_ppm[k];
        if !(sf.is_finite() && sf.abs() <= SF_LIMIT_PPM) {
            return format!("scale-factor error {sf:.4e} ppm at node {k}, limit +-{SF_LIMIT_PPM}");
        }
        let b = t.bias_dph[k];
        if !(b.is_finite() && b.abs() <= BIAS_LIMIT_DPH) {
            return format!("bias {b:.4e} deg/h at node {k}, limit +-{BIAS_LIMIT_DPH}");
        }
    }
    format!(
        "coil-sensor lag {:.4e} s, limit 0 .. {LAG_LIMIT_S}",
        t.sensor_lag_s
    )
}
