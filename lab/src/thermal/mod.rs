//! RLG thermal calibration: chamber simulator, `fit thermal`, `compensate`.

pub mod chamber;
pub mod fit;

use crate::data::run_file::{Column, RunFile, RunText};
use crate::error::LabError;
use clap::Args;
use fit::{
    coefficient_se, fit_thermal, noise_floor_100s, std_of_means, std_se, CubicModel, ThermalData,
};
use gyro_coeffs::file::CoeffFile;
use gyro_sp::rlg::thermal::{Temperatures, ThermalComp, ThermalConfig};
use gyro_sp::rlg::{compensate_rate_ndps, ThermalCoeffs};
use std::path::{Path, PathBuf};

/// A chamber run read from a run file.
pub fn read_run(path: &Path) -> Result<(RunText, ThermalData), LabError> {
    let (text, [a, b, case]) =
        RunFile::read(path, 200, [Column::MonoA, Column::MonoB, Column::Case])?;
    let r = &text.run;
    let drift_dph = r
        .rate_dps
        .iter()
        .zip(&r.ref_rate_dps)
        .map(|(r, w)| (r - w) * 3600.0)
        .collect();
    let d = ThermalData {
        t: r.t_s.clone(),
        a,
        b,
        case,
        drift_dph,
    };
    Ok((text, d))
}

/// B_TC per row by the firmware's own fixed-point compensation (thermal.rs),
/// one sensor update per row (the period from `t_s`), F(tau) preset to the
/// operating time before the first row. Returns B_TC, Q16 deg/h, and flags.
pub fn firmware_bias(c: &ThermalCoeffs, d: &ThermalData) -> (Vec<i64>, Vec<u8>) {
    let n = d.t.len();
    let mut comp = ThermalComp::default();
    let first_dt = if n > 1 { d.t[1] - d.t[0] } else { 1.0 };
    comp.preset_operating_time(c, d.t[0] - first_dt);
    let q8 = |x: f64| Some((x * 256.0).round() as i32);
    let mut cfg = ThermalConfig::new(c, first_dt);
    let mut cfg_dt = first_dt;
    let (mut bias, mut flags) = (Vec::with_capacity(n), Vec::with_capacity(n));
    for k in 0..n {
        let h = if k > 0 { d.t[k] - d.t[k - 1] } else { first_dt };
        if (h - cfg_dt).abs() > 1e-9 * cfg_dt {
            cfg = ThermalConfig::new(c, h);
            cfg_dt = h;
        }
        let b = comp.update(
            &cfg,
            &Temperatures {
                mono_a_q8: q8(d.a[k]),
                mono_b_q8: q8(d.b[k]),
                case_q8: q8(d.case[k]),
            },
        );
        bias.push(b);
        flags.push(comp.flags());
    }
    (bias, flags)
}

#[derive(Args, Debug, Clone)]
pub struct FitThermalArgs {
    /// Chamber run file (t_s, ref_rate_dps, rate_dps, t_mono_a_c, t_mono_b_c, t_case_c).
    #[arg(long)]
    pub data: PathBuf,
    #[arg(long)]
    pub out: PathBuf,
    #[arg(long)]
    pub json: bool,
}

#[derive(Debug, serde::Serialize)]
pub struct FitSummary {
    pub coefficients: ThermalCoeffs,
    /// Their standard errors (residual correlation included; see fit.rs).
    pub coefficient_se: Option<ThermalCoeffs>,
    /// Standard deviation of 100 s means, deg/h: raw drift, after the
    /// improved model (float fit), after the classic one-sensor cubic.
    pub raw_std_100s_dph: f64,
    pub residual_std_100s_dph: f64,
    pub cubic_std_100s_dph: f64,
    pub noise_floor_100s_dph: f64,
    /// Standard error of each standard deviation above (same order).
    pub std_100s_se_dph: [f64; 4],
    pub cubic: CubicModel,
}

pub fn fit_run(a: &FitThermalArgs) -> Result<(), LabError> {
    let (_, d) = read_run(&a.data)?;
    let (c, resid) = fit_thermal(&d).ok_or_else(|| {
        LabError::input(
            &a.data,
            "the thermal model could not be fitted (singular data)",
        )
    })?;
    c.check().map_err(|e| {
        LabError::input(
            &a.data,
            format!("fitted coefficients out of the firmware's range ({e:?}): {c:?}"),
        )
    })?;
    let cubic = CubicModel::fit(&d.a, &d.drift_dph)
        .ok_or_else(|| LabError::input(&a.data, "cubic fit failed"))?;
    let cubic_res: Vec<f64> = d
        .drift_dph
        .iter()
        .zip(&d.a)
        .map(|(y, t)| y - cubic.eval(*t))
        .collect();
    let coefficients = c;
    let stds = [
        std_of_means(&d.t, &d.drift_dph, 100.0),
        std_of_means(&d.t, &resid, 100.0),
        std_of_means(&d.t, &cubic_res, 100.0),
        noise_floor_100s(&d.t, &d.drift_dph),
    ];
    let s = FitSummary {
        coefficients,
        coefficient_se: coefficient_se(&d, &c),
        raw_std_100s_dph: stds[0],
        residual_std_100s_dph: stds[1],
        cubic_std_100s_dph: stds[2],
        noise_floor_100s_dph: stds[3],
        std_100s_se_dph: stds.map(|x| std_se(x, &d.t, 100.0)),
        cubic: cubic.clone(),
    };
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
    info.insert(
        "record_crc32".into(),
        format!("0x{:08x}", gyro_coeffs::record::crc_of(&c.to_record())).into(),
    );
    let file = CoeffFile::rlg_thermal(coefficients, info);
    gyro_coeffs::file::write(
        &a.out,
        &file,
        "RLG thermal bias model (docs/rlg.md), written by gyro-lab fit thermal.\n\
         B = bias0 + k1*dT + k2*grad(dT) + k3*dT^2 + k4*T_K + k5*(1 - exp(-t/tau_warm)), deg/h;\n\
         dT = t_mono_a - t_mono_b. Load with `gyro-lab compensate` or build the firmware with RLG_COEFFS=<this file>.",
    )
    .map_err(|e| LabError::coeffs_io(&a.out, &e))?;
    if a.json {
        println!(
            "{}",
            serde_json::to_string(&s).map_err(|e| LabError::Io {
                file: None,
                msg: e.to_string()
            })?
        );
    } else {
        let v = s.coefficients.values();
        let e = s.coefficient_se.map(|c| c.values());
        let names = [
            "bias0_dph",
            "k1_dph_per_c",
            "k2_dph_per_c_per_s",
            "k3_dph_per_c2",
            "k4_dph_per_c",
            "k5_dph",
            "tau_warm_s",
        ];
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
        println!("written: {}", a.out.display());
    }
    Ok(())
}

#[derive(Args, Debug, Clone)]
pub struct CompensateArgs {
    /// Coefficient file (from `gyro-lab fit`).
    #[arg(long)]
    pub coeffs: PathBuf,
    #[arg(long)]
    pub data: PathBuf,
    #[arg(long)]
    pub out: PathBuf,
    /// Also fit the classic cubic on this file and report it (comparison only).
    #[arg(long)]
    pub cubic_from: Option<PathBuf>,
    #[arg(long)]
    pub json: bool,
}

#[derive(Debug, serde::Serialize)]
pub struct CompensateSummary {
    pub raw_std_100s_dph: f64,
    pub comp_std_100s_dph: f64,
    pub noise_floor_100s_dph: f64,
    /// Standard errors of the three figures above.
    pub raw_std_100s_se_dph: f64,
    pub comp_std_100s_se_dph: f64,
    pub noise_floor_100s_se_dph: f64,
    /// comp / noise floor.
    pub comp_over_floor: f64,
    #[serde(skip_serializing_if = "Option::is_none")]
    pub cubic_std_100s_dph: Option<f64>,
    pub coeffs_refused: bool,
    pub sensor_flags_seen: u8,
}

/// `gyro-lab compensate`: either kind of coefficient file, by its `kind`.
pub fn compensate_run(a: &CompensateArgs) -> Result<(), LabError> {
    let (_, coeffs) =
        gyro_coeffs::file::read(&a.coeffs).map_err(|e| LabError::coeffs_input(&a.coeffs, &e))?;
    match coeffs {
        gyro_coeffs::file::Coeffs::RlgThermal(c) => compensate_rlg(a, &c),
        gyro_coeffs::file::Coeffs::FogScaleFactor(t) => crate::scale_factor::compensate_run(a, &t),
    }
}

fn compensate_rlg(a: &CompensateArgs, c: &ThermalCoeffs) -> Result<(), LabError> {
    let c = *c;
    let (text, d) = read_run(&a.data)?;
    let (bias, flags) = firmware_bias(&c, &d);
    let comp: Vec<f64> = text
        .run
        .rate_dps
        .iter()
        .zip(&bias)
        .map(|(r, b)| compensate_rate_ndps((r * 1e9).round() as i64, *b) as f64 * 1e-9)
        .collect();
    let comp_drift: Vec<f64> = comp
        .iter()
        .zip(&text.run.ref_rate_dps)
        .map(|(r, w)| (r - w) * 3600.0)
        .collect();
    text.write_back(&a.out, &[(Column::CompensatedRate, &comp)])?;
    let floor = noise_floor_100s(&d.t, &d.drift_dph);
    let comp_std = std_of_means(&d.t, &comp_drift, 100.0);
    let cubic_std = match &a.cubic_from {
        Some(p) => {
            let (_, dc) = read_run(p)?;
            let m = CubicModel::fit(&dc.a, &dc.drift_dph)
                .ok_or_else(|| LabError::input(p, "cubic fit failed"))?;
            let r: Vec<f64> = d
                .drift_dph
                .iter()
                .zip(&d.a)
                .map(|(y, t)| y - m.eval(*t))
                .collect();
            Some(std_of_means(&d.t, &r, 100.0))
        }
        None => None,
    };
    let raw_std = std_of_means(&d.t, &d.drift_dph, 100.0);
    let s = CompensateSummary {
        raw_std_100s_dph: raw_std,
        comp_std_100s_dph: comp_std,
        noise_floor_100s_dph: floor,
        raw_std_100s_se_dph: std_se(raw_std, &d.t, 100.0),
        comp_std_100s_se_dph: std_se(comp_std, &d.t, 100.0),
        noise_floor_100s_se_dph: std_se(floor, &d.t, 100.0),
        comp_over_floor: comp_std / floor,
        cubic_std_100s_dph: cubic_std,
        coeffs_refused: c.check().is_err(),
        sensor_flags_seen: flags.iter().fold(0, |x, f| x | f),
    };
    if a.json {
        println!(
            "{}",
            serde_json::to_string(&s).map_err(|e| LabError::Io {
                file: None,
                msg: e.to_string()
            })?
        );
    } else {
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
        println!("written: {}", a.out.display());
    }
    Ok(())
}
