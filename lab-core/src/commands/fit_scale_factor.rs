//! `fit scale-factor`: the FOG scale factor over temperature (knees by
//! BIC) fitted on a continuous-rotation or multi-point run
//! (calibration/scale_factor/): the table the firmware loads, the JSON,
//! the text and the report.

use super::fit_thermal::{with_checks, FitOutcome};
use super::reports;
use super::run_inputs::scale_factor_run;
use crate::calibration::scale_factor::diagnostics::diagnostics;
use crate::calibration::scale_factor::fit::fit;
use crate::calibration::scale_factor::multipoint::Plateau;
use crate::calibration::scale_factor::result::SfFit;
use crate::data::read_spec::ReadSpec;
use crate::data::source::Source;
use crate::error::LabError;
use gyro_coeffs::file::{CoeffFile, FittedRange};

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
}

#[derive(serde::Serialize)]
struct TableJson {
    temps_c: Vec<f64>,
    sf_ppm: Vec<f64>,
    bias_dph: Vec<f64>,
    sensor_lag_s: f64,
    record_crc32: String,
}

/// The scale-factor table fitted on a run.
pub fn fit_scale_factor(
    source: Source,
    spec: &ReadSpec,
    report: bool,
) -> Result<FitOutcome, LabError> {
    let (inp, checked) = scale_factor_run(source, spec)?;
    let (mut f, plateaus) = fit(&inp).map_err(|e| source.origin().whole(e.to_string()))?;
    f.warnings.splice(0..0, checked.calibration_warnings());
    f.table.check().map_err(|_| {
        source.origin().whole(format!(
            "the fitted table is outside what the firmware holds ({}): this run does not \
             determine the scale factor over temperature; fit on a continuous-rotation run at \
             50 deg/s or more through the chamber's range (e.g. `gyro-lab simulate scale-factor`)",
            table_problem(&f.table)
        ))
    })?;
    let (coeffs_toml, crc) = table_file(&source.name(), &f)?;
    let report = report.then(|| {
        let d = diagnostics(&inp, &f);
        reports::scale_factor::report(&source.name(), &f, &d, plateaus.as_deref())
    });
    let n = f.table.n;
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
            record_crc32: crc.clone(),
        },
    })
    .unwrap_or_default();
    Ok(FitOutcome {
        coeffs_toml,
        record_crc32: crc,
        json: with_checks(j, &checked),
        text: lines(&f),
        report,
    })
}

/// The coefficient file of the fit, and its record's CRC.
fn table_file(data: &str, f: &SfFit) -> Result<(String, String), LabError> {
    let record = f.table.to_record();
    let crc = format!("0x{:08x}", gyro_coeffs::record::crc_of(&record));
    let mut info = toml::Table::new();
    info.insert("data".into(), data.into());
    info.insert("method".into(), f.method.name().into());
    info.insert(
        "knees_c".into(),
        toml::Value::Array(f.knees.iter().map(|k| k.value.into()).collect()),
    );
    info.insert("residual_ppm".into(), f.residual_ppm.value.into());
    info.insert("record_crc32".into(), crc.clone().into());
    let mut file = CoeffFile::fog_scale_factor(&f.table, info);
    file.range = Some(FittedRange { temp_c: f.range_c });
    let text = gyro_coeffs::file::to_text(
        &file,
        "FOG scale factor and bias over coil temperature (docs/fog.md), written by gyro-lab fit scale-factor.\n\
         output = (1 + sf_ppm*1e-6)*rate + bias_dph, linear in the coil temperature between the nodes, held outside;\n\
         coil temperature = sensor + sensor_lag_s * d(sensor)/dt. Load with `gyro-lab compensate` or build the\n\
         firmware with FOG_SF_COEFFS=<this file>.",
    )
    .map_err(|e| LabError::Io { file: None, msg: e })?;
    Ok((text, crc))
}

fn lines(f: &SfFit) -> Vec<String> {
    let mut out = vec![];
    out.push(format!(
        "{} fit, {} rows, coil {:.2} .. {:.2} degC",
        f.method, f.rows_used, f.range_c[0], f.range_c[1]
    ));
    out.push(format!(
        "model: {} ({}), degree {}, {} knee(s); BIC margin over the next family {:.1}",
        f.model,
        f.model.describe(),
        f.degree,
        f.knees.len(),
        f.criterion_margin
    ));
    for b in &f.families {
        out.push(format!(
            "  best {:<22} degree {} knees {}: BIC {:.1} ({:+.1})",
            b.model.name(),
            b.degree,
            b.knees,
            b.bic,
            b.delta_bic
        ));
    }
    if f.knees.is_empty() {
        out.push(format!(
            "knees: none (BIC by knee count: {:?})",
            rounded(&f.bic)
        ));
    }
    for k in &f.knees {
        out.push(format!(
            "knee at {:.2} degC (95 % interval {:.2} .. {:.2}); BIC by knee count {:?}",
            k.value,
            k.lo,
            k.hi,
            rounded(&f.bic)
        ));
    }
    if let Some(p) = &f.polynomial {
        let terms: Vec<String> = p
            .coef_ppm
            .iter()
            .enumerate()
            .map(|(k, c)| format!("{:+.6} ({:.6}) x^{k}", c.value, c.se))
            .collect();
        out.push(format!(
            "polynomial, x = T - {} degC, ppm: {}",
            p.t_ref_c,
            terms.join(" ")
        ));
    }
    let t = &f.tabulation;
    out.push(format!(
        "table: {} nodes, spacing {:?} degC, firmware lookup within {:.4} ppm of the model",
        t.nodes,
        t.spacing_c
            .iter()
            .map(|h| (h * 1000.0).round() / 1000.0)
            .collect::<Vec<_>>(),
        t.max_error_ppm
    ));
    if f.segments.len() > 12 {
        out.push(format!(
            "  {} table segments (the polynomial tabulated): see the JSON's segments",
            f.segments.len()
        ));
    }
    for s in f.segments.iter().filter(|_| f.segments.len() <= 12) {
        out.push(format!(
            "  {:7.2} .. {:7.2} degC: K_SF = 1 {:+.2} ppm ({:.2}) {:+.4} ppm/degC ({:.4}) x T",
            s.from_c,
            s.to_c,
            s.k0_ppm,
            s.k0_se * 1e6,
            s.k_t_ppm_per_c,
            s.k_t_se * 1e6
        ));
    }
    if let Some(l) = f.sensor_lag_s {
        out.push(format!(
            "coil sensor lag {:.1} s (95 % interval {:.1} .. {:.1})",
            l.value, l.lo, l.hi
        ));
    }
    if let Some(b) = f.bias {
        out.push(format!(
            "bias {:.4} +- {:.4} deg/h at 20 degC, {:+.5} +- {:.5} deg/h/degC",
            b.at_20c_dph.value, b.at_20c_dph.se, b.slope_dph_per_c.value, b.slope_dph_per_c.se
        ));
    }
    for (name, e) in [
        ("asymmetry", f.asymmetry_ppm),
        ("nonlinearity", f.nonlinearity_ppm),
    ] {
        match e {
            Some(e) => out.push(format!("{name} {:.3} +- {:.3} ppm", e.value, e.se)),
            None => out.push(format!("{name}: not measurable on this run")),
        }
    }
    out.push(format!(
        "residual {:.3} +- {:.3} ppm RMS of 60 s means (noise floor {:.3} +- {:.3})",
        f.residual_ppm.value, f.residual_ppm.se, f.noise_floor_ppm.value, f.noise_floor_ppm.se
    ));
    for n in &f.notes {
        out.push(format!("note: {n}"));
    }
    for w in &f.warnings {
        out.push(format!("warning: {}", w.message));
    }
    out
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
