//! FOG scale factor over temperature: `simulate scale-factor`, `fit
//! scale-factor`, `compensate` with a `fog_scale_factor` file and `bench
//! scale-factor`.

pub mod bench;
pub mod fit;
pub mod sim;

use crate::data::csv_writer::CellFormat::Fixed;
use crate::data::run_file::{Column, RunFile, RunWriter};
use crate::error::LabError;
use clap::Args;
use fit::{SfFit, SfFitError, SfInput};
use gyro_coeffs::file::CoeffFile;
use gyro_coeffs::ScaleFactorTable;
use gyro_sp::fog::scale_factor::ScaleFactorComp;
use gyro_sp::fog::{FogConfig, FogParams};
use sim::{Direction, RigParams, SweepProfile, Test};
use std::path::PathBuf;

const DEG: f64 = std::f64::consts::PI / 180.0;

fn json_line<T: serde::Serialize>(v: &T) -> Result<(), LabError> {
    println!(
        "{}",
        serde_json::to_string(v).map_err(|e| LabError::Io {
            file: None,
            msg: e.to_string()
        })?
    );
    Ok(())
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum TestKind {
    /// Constant table rate while the chamber sweeps.
    Continuous,
    /// Temperature plateaus, each with a rate sequence in both directions.
    Multipoint,
}

#[derive(Args, Debug, Clone)]
pub struct SimulateArgs {
    #[arg(long, value_enum, default_value_t = TestKind::Continuous)]
    pub test: TestKind,
    /// Chamber profile of the continuous test.
    #[arg(long, value_enum, default_value_t = SweepProfile::Cycle)]
    pub profile: SweepProfile,
    /// Table rate of the continuous test, deg/s (50 or more).
    #[arg(long, default_value_t = 50.0)]
    pub rate_dps: f64,
    #[arg(long, value_enum, default_value_t = Direction::Both)]
    pub direction: Direction,
    /// With `--direction both`: reverse every this many seconds.
    #[arg(long, default_value_t = 300.0)]
    pub reverse_every_s: f64,
    /// Plateau temperatures of the multi-point test, degC.
    #[arg(long, value_delimiter = ',', default_values_t = [-40.0, -15.0, 10.0, 35.0, 60.0], allow_negative_numbers = true)]
    pub plateaus_c: Vec<f64>,
    /// Rate magnitudes of each plateau's sequence (each both ways), deg/s.
    #[arg(long, value_delimiter = ',', default_values_t = [10.0, 20.0, 50.0, 100.0, 200.0])]
    pub rates_dps: Vec<f64>,
    /// Soak at rest before each plateau's sequence, s; dwell per rate, s.
    #[arg(long, default_value_t = 3600.0)]
    pub soak_s: f64,
    #[arg(long, default_value_t = 60.0)]
    pub dwell_s: f64,
    /// The same gyro without its knee.
    #[arg(long)]
    pub no_knee: bool,
    /// Angle random walk, deg/sqrt(h); bias instability, deg/h.
    #[arg(long, default_value_t = 0.005)]
    pub arw_dpsh: f64,
    #[arg(long, default_value_t = 0.01)]
    pub bias_instability_dph: f64,
    /// Coil sensor lag behind the coil, s.
    #[arg(long, default_value_t = 30.0)]
    pub sensor_lag_s: f64,
    /// Coil sensor noise, degC rms (read at 1/128 degC).
    #[arg(long, default_value_t = 0.005)]
    pub sensor_noise_c: f64,
    /// Row period, s.
    #[arg(long, default_value_t = 1.0)]
    pub dt_s: f64,
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    #[arg(long)]
    pub out: PathBuf,
    #[arg(long)]
    pub json: bool,
}

impl SimulateArgs {
    pub fn test(&self) -> Test {
        match self.test {
            TestKind::Continuous => Test::Continuous {
                profile: self.profile,
                rate_dps: self.rate_dps,
                direction: self.direction,
                reverse_every_s: self.reverse_every_s,
            },
            TestKind::Multipoint => Test::MultiPoint {
                plateaus_c: self.plateaus_c.clone(),
                rates_dps: self.rates_dps.clone(),
                soak_s: self.soak_s,
                dwell_s: self.dwell_s,
            },
        }
    }

    pub fn rig(&self) -> RigParams {
        let d = RigParams::default();
        RigParams {
            truth: if self.no_knee {
                d.truth.without_knees()
            } else {
                d.truth
            },
            arw_dpsh: self.arw_dpsh,
            bias_instability_dph: self.bias_instability_dph,
            tau_sensor_s: self.sensor_lag_s,
            sensor_noise_c: self.sensor_noise_c,
            dt_s: self.dt_s,
            seed: self.seed,
            ..d
        }
    }
}

pub fn simulate(a: &SimulateArgs) -> Result<(), LabError> {
    let bad = |n: &str, v: f64| LabError::Usage(format!("--{n} {v}: out of range"));
    let pos = |n: &str, v: f64, lo: f64, hi: f64| {
        if v.is_finite() && v >= lo && v <= hi {
            Ok(())
        } else {
            Err(bad(n, v))
        }
    };
    pos("rate-dps", a.rate_dps.abs(), 0.0, 1000.0)?;
    pos("dt-s", a.dt_s, 0.01, 60.0)?;
    pos("reverse-every-s", a.reverse_every_s, 1.0, 1e5)?;
    pos("soak-s", a.soak_s, 0.0, 1e5)?;
    pos("dwell-s", a.dwell_s, a.dt_s, 1e4)?;
    pos("arw-dpsh", a.arw_dpsh, 0.0, 10.0)?;
    pos("bias-instability-dph", a.bias_instability_dph, 0.0, 100.0)?;
    pos("sensor-lag-s", a.sensor_lag_s, 0.0, 1000.0)?;
    pos("sensor-noise-c", a.sensor_noise_c, 0.0, 10.0)?;
    for &t in &a.plateaus_c {
        pos("plateaus-c", t, -55.0, 125.0)?;
    }
    for &r in &a.rates_dps {
        pos("rates-dps", r, 0.0, 1000.0)?;
    }
    let run = sim::simulate(&a.test(), &a.rig());
    let truth = a.rig().truth;
    let knees: Vec<f64> = truth.knees[..truth.n_knees].iter().map(|k| k.0).collect();
    let mut w = RunWriter::create(
        &a.out,
        &format!(
            "gyro-lab simulate scale-factor: {:?} test, seed {}; truth: knees at {:?} degC, sensor lag {} s\n\
             {} is the coil sensor; {} and {} are the truth (not used by the fit)",
            a.test,
            a.seed,
            knees,
            a.sensor_lag_s,
            Column::Temp.name(),
            Column::TrueCoilTemp.name(),
            Column::TrueScaleFactor.name()
        ),
        &[
            (Column::Time, Fixed(3)),
            (Column::RefRate, Fixed(6)),
            (Column::Rate, Fixed(10)),
            (Column::Temp, Fixed(4)),
            (Column::AirTemp, Fixed(3)),
            (Column::TrueCoilTemp, Fixed(4)),
            (Column::TrueScaleFactor, Fixed(4)),
        ],
    )?;
    for k in 0..run.t_s.len() {
        w.row(&[
            run.t_s[k],
            run.ref_rate_dps[k],
            run.rate_dps[k],
            run.temp_c[k],
            run.air_c[k],
            run.coil_true_c[k],
            run.sf_true_ppm[k],
        ])?;
    }
    w.finish()?;
    let hours = run.t_s.last().copied().unwrap_or(0.0) / 3600.0;
    if a.json {
        json_line(&serde_json::json!({
            "rows": run.t_s.len(), "duration_h": hours, "knees_true_c": knees, "out": a.out
        }))
    } else {
        println!(
            "{} rows, {hours:.1} h, true knees {knees:?} degC -> {}",
            run.t_s.len(),
            a.out.display()
        );
        Ok(())
    }
}

/// A run file read for the scale-factor tools, checked: `t_s`,
/// `ref_rate_dps`, `rate_dps`, `temp_c`; rotation present; a temperature
/// span the model can use.
pub fn read_run(path: &std::path::Path) -> Result<SfInput, LabError> {
    let (text, [temp]) = RunFile::read(path, 30, [Column::Temp])?;
    let (t, w, y) = (&text.run.t_s, &text.run.ref_rate_dps, &text.run.rate_dps);
    let rot = fit::rotating(w);
    if rot.len() < 30 {
        return Err(text.column_error(
            Column::RefRate,
            format!(
                "no rotation: {} rows with |{}| >= {} deg/s, at least 30 needed to measure a scale factor",
                rot.len(),
                Column::RefRate.name(),
                fit::MIN_RATE_DPS
            ),
        ));
    }
    let (lo, hi) = rot
        .iter()
        .map(|&k| temp[k])
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| {
            (a.min(x), b.max(x))
        });
    if hi - lo < fit::MIN_SPAN_C {
        return Err(text.column_error(
            Column::Temp,
            format!(
                "temperature span {:.2} degC over the rotating rows; the scale-factor-over-temperature model needs at least {} degC",
                hi - lo,
                fit::MIN_SPAN_C
            ),
        ));
    }
    Ok(fit::prepare(t, w, y, &temp))
}

#[derive(Args, Debug, Clone)]
pub struct FitArgs {
    /// Run file: continuous-rotation or multi-point (t_s, ref_rate_dps, rate_dps, temp_c).
    #[arg(long)]
    pub data: PathBuf,
    /// Coefficient file to write (what the firmware loads).
    #[arg(long)]
    pub out: PathBuf,
    #[arg(long)]
    pub json: bool,
}

/// JSON of `fit scale-factor` (docs/interfaces.md keys first).
#[derive(serde::Serialize)]
struct FitJson<'a> {
    knees_c: Vec<f64>,
    knees_ci_c: Vec<[f64; 2]>,
    residual_ppm: f64,
    residual_ppm_se: f64,
    segments: &'a [fit::Segment],
    #[serde(flatten)]
    fit: &'a SfFit,
    #[serde(skip_serializing_if = "Option::is_none")]
    plateaus: Option<&'a [fit::Plateau]>,
    table: TableJson,
    out: String,
}

#[derive(serde::Serialize)]
struct TableJson {
    temps_c: Vec<f64>,
    sf_ppm: Vec<f64>,
    bias_dph: Vec<f64>,
    sensor_lag_s: f64,
    record_crc32: String,
}

/// Fits either kind of run.
pub fn fit_run_data(inp: &SfInput) -> Result<(SfFit, Option<Vec<fit::Plateau>>), SfFitError> {
    let rot = fit::rotating(&inp.w);
    match fit::plateaus(inp, &rot) {
        Some(groups) => fit::fit_multipoint(inp, &groups).map(|(f, p)| (f, Some(p))),
        None => fit::fit_continuous(inp).map(|f| (f, None)),
    }
}

pub fn fit_run(a: &FitArgs) -> Result<(), LabError> {
    let inp = read_run(&a.data)?;
    let name = a.data.display().to_string();
    let (f, plateaus) = fit_run_data(&inp).map_err(|e| LabError::input(&a.data, e.to_string()))?;
    f.table.check().map_err(|e| {
        LabError::input(
            &a.data,
            format!(
                "the fitted table is out of the firmware's range ({e:?}): {:?}",
                f.table
            ),
        )
    })?;
    let n = f.table.n;
    let record = f.table.to_record();
    let crc = format!("0x{:08x}", gyro_coeffs::record::crc_of(&record));
    let mut info = toml::Table::new();
    info.insert("data".into(), name.clone().into());
    info.insert("method".into(), f.method.name().into());
    info.insert(
        "knees_c".into(),
        toml::Value::Array(f.knees.iter().map(|k| k.value.into()).collect()),
    );
    info.insert("residual_ppm".into(), f.residual_ppm.value.into());
    info.insert("record_crc32".into(), crc.clone().into());
    gyro_coeffs::file::write(
        &a.out,
        &CoeffFile::fog_scale_factor(&f.table, info),
        "FOG scale factor and bias over coil temperature (docs/fog.md), written by gyro-lab fit scale-factor.\n\
         output = (1 + sf_ppm*1e-6)*rate + bias_dph, linear in the coil temperature between the nodes, held outside;\n\
         coil temperature = sensor + sensor_lag_s * d(sensor)/dt. Load with `gyro-lab compensate` or build the\n\
         firmware with FOG_SF_COEFFS=<this file>.",
    )
    .map_err(|e| LabError::coeffs_io(&a.out, &e))?;
    if a.json {
        return json_line(&FitJson {
            knees_c: f.knees.iter().map(|k| k.value).collect(),
            knees_ci_c: f.knees.iter().map(|k| [k.lo, k.hi]).collect(),
            residual_ppm: f.residual_ppm.value,
            residual_ppm_se: f.residual_ppm.se,
            segments: &f.segments,
            fit: &f,
            plateaus: plateaus.as_deref(),
            table: TableJson {
                temps_c: f.table.temps_c[..n].to_vec(),
                sf_ppm: f.table.sf_ppm[..n].to_vec(),
                bias_dph: f.table.bias_dph[..n].to_vec(),
                sensor_lag_s: f.table.sensor_lag_s,
                record_crc32: crc,
            },
            out: a.out.display().to_string(),
        });
    }
    println!(
        "{} fit, {} rows, coil {:.2} .. {:.2} degC",
        f.method, f.rows_used, f.range_c[0], f.range_c[1]
    );
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
    for s in &f.segments {
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
        "residual {:.3} +- {:.3} ppm RMS of 60 s means",
        f.residual_ppm.value, f.residual_ppm.se
    );
    for n in &f.notes {
        println!("note: {n}");
    }
    println!("written: {} (record CRC {crc})", a.out.display());
    Ok(())
}

fn rounded(v: &[f64]) -> Vec<f64> {
    v.iter().map(|x| (x * 10.0).round() / 10.0).collect()
}

/// The firmware's compensation (fog/scale_factor.rs) on a run: one coil
/// sensor update per row (period from `t_s`), then the row's angle
/// increment compensated as a frame of its closure steps. Returns the
/// compensated rate (deg/s) and the flags of each row.
pub fn compensate_rows(
    table: &ScaleFactorTable,
    t: &[f64],
    rate_dps: &[f64],
    temp_c: &[f64],
) -> (Vec<f64>, Vec<u8>) {
    let fog = FogConfig::new(FogParams::default()).expect("reference FOG configuration");
    let lsb = fog.rad_per_angle_lsb();
    let dt_p = fog.closure_period_s();
    let mut comp = ScaleFactorComp::default();
    let (mut out, mut flags) = (Vec::with_capacity(t.len()), Vec::with_capacity(t.len()));
    let first = if t.len() > 1 { t[1] - t[0] } else { 1.0 };
    fit::each_sensor_update(t, &fog, table, |k, cfg| {
        comp.update_temperature(cfg, Some((temp_c[k] * 256.0).round() as i32));
        let h = if k > 0 { t[k] - t[k - 1] } else { first };
        // The row as frames of at most 1 s of closure steps (the frame word
        // counts steps in a u16).
        let steps = (h / dt_p).round().max(1.0);
        let chunks = (steps / 12_500.0).ceil().max(1.0);
        let angle = rate_dps[k] * DEG * h / lsb / chunks;
        let mut sum = 0.0;
        let mut f = 0u8;
        for _ in 0..chunks as usize {
            let (a, w) =
                comp.compensate(cfg, angle.round() as i64, (steps / chunks).round() as u16);
            sum += a as f64;
            f |= w.flags;
        }
        out.push(sum * lsb / DEG / h);
        flags.push(f);
    });
    (out, flags)
}

#[derive(serde::Serialize)]
struct CompensateJson {
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

/// `gyro-lab compensate` with a `fog_scale_factor` file.
pub fn compensate_run(
    a: &crate::thermal::CompensateArgs,
    table: &ScaleFactorTable,
) -> Result<(), LabError> {
    let (text, [temp]) = RunFile::read(&a.data, 2, [Column::Temp])?;
    let (t, w, y) = (&text.run.t_s, &text.run.ref_rate_dps, &text.run.rate_dps);
    let (comp, flags) = compensate_rows(table, t, y, &temp);
    text.write_back(&a.out, &[(Column::CompensatedRate, &comp)])?;
    let err = |v: &[f64]| -> Vec<f64> { v.iter().zip(w).map(|(a, b)| a - b).collect() };
    let (raw, raw_se, _) = fit::window_rms_ppm(t, w, &err(y), fit::RESIDUAL_WINDOW_S);
    let (c, c_se, m) = fit::window_rms_ppm(t, w, &err(&comp), fit::RESIDUAL_WINDOW_S);
    let s = CompensateJson {
        raw_ppm: raw,
        raw_ppm_se: raw_se,
        comp_ppm: c,
        comp_ppm_se: c_se,
        windows: m,
        flags_seen: flags.iter().fold(0, |x, f| x | f),
        out: a.out.display().to_string(),
    };
    if a.json {
        return json_line(&s);
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
    println!("written: {}", a.out.display());
    Ok(())
}
