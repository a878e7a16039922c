//! The commands for Python: each reads what it is given as the command
//! line reads its files, calls the same function of gyro_lab_core, and
//! hands back the same JSON, text and report (outcome.rs), with the arrays
//! a notebook wants beside them.

use crate::inputs::{ReadIn, RunIn};
use crate::outcome::{detached, Native};
use gyro_lab_core::commands::{
    allan as allan_cmd, compensate as compensate_cmd, discover as discover_cmd,
    fit_scale_factor as sf_cmd, fit_thermal as thermal_cmd, frames, lockin as lockin_cmd,
    model_file, simulate_run as simulate_cmd,
};
use gyro_lab_core::data::read_spec::ReadSpec;
use gyro_lab_core::data::run_file::{Column, Reference, RunFile};
use gyro_lab_core::data::source::Source;
use gyro_lab_core::error::LabError;
use gyro_lab_core::model::grade::Grade;
use gyro_lab_core::model::gyro_kind::GyroKind;
use numpy::PyArray1;
use pyo3::prelude::*;
use pyo3::types::{PyBytes, PyDict};

/// Columns by name, as numpy arrays.
type Arrays<'py> = Vec<(String, Bound<'py, PyArray1<f64>>)>;

/// Named columns as Python's list of (name, array) pairs: the vectors
/// handed to numpy, not copied.
fn named_arrays<'py>(py: Python<'py>, cols: Vec<(String, Vec<f64>)>) -> Arrays<'py> {
    cols.into_iter()
        .map(|(n, v)| (n, PyArray1::from_vec(py, v)))
        .collect()
}

/// A command on one run: the run and the reading options taken from
/// Python as the command line takes its file and options, then `f` on
/// them with the GIL released and no panic let through.
fn on_run<T: Send>(
    py: Python<'_>,
    run: &Bound<'_, PyAny>,
    label: &str,
    read: Option<&Bound<'_, PyDict>>,
    f: impl FnOnce(Source<'_>, &ReadSpec) -> Result<T, LabError> + Send,
) -> PyResult<T> {
    let held = RunIn::new(run, label)?;
    let run = held.prepare()?;
    let read = ReadIn::from_dict(read)?;
    detached(py, || f(run.source(), &read.spec()?))
}

/// The columns of a run file, by name (those the run has).
#[pyfunction]
#[pyo3(signature = (run, label, read=None))]
pub fn read_run<'py>(
    py: Python<'py>,
    run: &Bound<'py, PyAny>,
    label: &str,
    read: Option<&Bound<'py, PyDict>>,
) -> PyResult<Arrays<'py>> {
    let cols = on_run(py, run, label, read, |source, spec| {
        let optional: Vec<Column> = Column::ALL
            .into_iter()
            .filter(|c| !c.required() && *c != Column::RefRate)
            .collect();
        let r = RunFile::read_long(source, spec, Reference::ZeroIfAbsent, 1, &optional)?;
        let mut out = vec![(Column::Time.name().to_owned(), r.t_s.clone())];
        if r.has_reference {
            out.push((Column::RefRate.name().to_owned(), r.ref_rate_dps.clone()));
        }
        out.push((Column::Rate.name().to_owned(), r.rate_dps.clone()));
        for c in optional {
            if let Some(v) = r.column(c) {
                out.push((c.name().to_owned(), v.to_vec()));
            }
        }
        Ok(out)
    })?;
    Ok(named_arrays(py, cols))
}

/// `gyro-lab allan`.
#[pyfunction]
#[pyo3(signature = (run, label, column, read=None))]
pub fn allan(
    py: Python<'_>,
    run: &Bound<'_, PyAny>,
    label: &str,
    column: &str,
    read: Option<&Bound<'_, PyDict>>,
) -> PyResult<Native> {
    on_run(py, run, label, read, |source, spec| {
        let o = allan_cmd::allan(source, column, spec)?;
        let (json, text, summary) = (o.json(), o.text(None), o.summary());
        Ok(Native::new(
            &json,
            text,
            summary,
            Some(Box::new(move || {
                let r = o.report();
                (r.html(), r.fragment())
            })),
        ))
    })
}

/// A model or a coefficient set's text and what to call it.
type Named = (String, String);

/// `gyro-lab discover`: the answer, the model file's text and the
/// residual's columns.
#[pyfunction]
#[pyo3(signature = (run, label, gyro, model=None, grade=None, validate=None, read=None))]
#[allow(clippy::too_many_arguments)]
pub fn discover<'py>(
    py: Python<'py>,
    run: &Bound<'py, PyAny>,
    label: &str,
    gyro: &str,
    model: Option<Named>,
    grade: Option<&str>,
    validate: Option<&Bound<'py, PyAny>>,
    read: Option<&Bound<'py, PyDict>>,
) -> PyResult<(Native, String, Arrays<'py>)> {
    let held = RunIn::new(run, label)?;
    let run = held.prepare()?;
    let validate_held = validate.map(|v| RunIn::new(v, "validate")).transpose()?;
    let validate = validate_held.as_ref().map(|v| v.prepare()).transpose()?;
    let read = ReadIn::from_dict(read)?;
    let (native, toml, residual) = detached(py, || {
        let spec = read.spec()?;
        let gyro = GyroKind::from_name(gyro)
            .ok_or_else(|| LabError::Usage(format!("gyro `{gyro}`: fog, rlg or mems")))?;
        let grade = grade
            .map(|g| {
                Grade::from_name(g).ok_or_else(|| {
                    LabError::Usage(format!(
                        "grade `{g}`: navigation, tactical, industrial or consumer"
                    ))
                })
            })
            .transpose()?;
        let model = model
            .map(|(text, name)| model_file::model_from_text(text, &name, gyro).map(|m| (m, name)))
            .transpose()?;
        let vsrc = validate.as_ref().map(|v| v.source());
        let o = discover_cmd::discover_run(discover_cmd::Request {
            source: run.source(),
            spec: &spec,
            gyro,
            model,
            grade,
            validate: vsrc,
        })?;
        let residual = vec![
            (Column::Time.name().to_owned(), o.data.inputs.t.clone()),
            (
                "residual_before_dps".to_owned(),
                o.d.residual_before.clone(),
            ),
            ("residual_after_dps".to_owned(), o.d.residual_after.clone()),
        ];
        let (json, text, summary, toml) = (o.json(), o.text(None), o.summary(), o.model_toml());
        let native = Native::new(
            &json,
            text,
            summary,
            Some(Box::new(move || {
                let r = o.report();
                (r.html(), r.fragment())
            })),
        );
        Ok((native, toml, residual))
    })?;
    Ok((native, toml, named_arrays(py, residual)))
}

/// A fit's answer and its coefficient file's text.
fn fit(o: thermal_cmd::FitOutcome) -> (Native, String) {
    let summary = o.text.iter().rev().take(2).rev().cloned().collect();
    let report = o.report;
    let native = Native::new(
        &o.json,
        o.text,
        summary,
        report.map(|r| -> Box<dyn FnOnce() -> (String, String) + Send> {
            Box::new(move || (r.html(), r.fragment()))
        }),
    );
    (native, o.coeffs_toml)
}

/// `gyro-lab fit thermal`.
#[pyfunction]
#[pyo3(signature = (run, label, read=None))]
pub fn fit_thermal(
    py: Python<'_>,
    run: &Bound<'_, PyAny>,
    label: &str,
    read: Option<&Bound<'_, PyDict>>,
) -> PyResult<(Native, String)> {
    on_run(py, run, label, read, |source, spec| {
        thermal_cmd::fit_thermal(source, spec, true).map(fit)
    })
}

/// `gyro-lab fit scale-factor`.
#[pyfunction]
#[pyo3(signature = (run, label, read=None))]
pub fn fit_scale_factor(
    py: Python<'_>,
    run: &Bound<'_, PyAny>,
    label: &str,
    read: Option<&Bound<'_, PyDict>>,
) -> PyResult<(Native, String)> {
    on_run(py, run, label, read, |source, spec| {
        sf_cmd::fit_scale_factor(source, spec, true).map(fit)
    })
}

/// `gyro-lab compensate`: the answer, and the run as read with
/// `rate_comp_dps` added.
#[pyfunction]
#[pyo3(signature = (coeffs, run, label, read=None, cubic_from=None))]
pub fn compensate<'py>(
    py: Python<'py>,
    coeffs: Named,
    run: &Bound<'py, PyAny>,
    label: &str,
    read: Option<&Bound<'py, PyDict>>,
    cubic_from: Option<&Bound<'py, PyAny>>,
) -> PyResult<(Native, Arrays<'py>)> {
    let held = RunIn::new(run, label)?;
    let run = held.prepare()?;
    let cubic_held = cubic_from
        .map(|v| RunIn::new(v, "cubic_from"))
        .transpose()?;
    let cubic = cubic_held.as_ref().map(|v| v.prepare()).transpose()?;
    let read = ReadIn::from_dict(read)?;
    let (native, cols) = detached(py, || {
        let spec = read.spec()?;
        let set = compensate_cmd::read_coeffs(&coeffs.0, &coeffs.1)?;
        let o = compensate_cmd::compensate_run(&compensate_cmd::Request {
            coeffs: &set,
            coeffs_name: &coeffs.1,
            source: run.source(),
            spec: &spec,
            cubic_from: cubic.as_ref().map(|v| v.source()),
            report: true,
        })?;
        let r = &o.run.run;
        let mut cols = vec![
            (Column::Time.name().to_owned(), r.t_s.clone()),
            (Column::RefRate.name().to_owned(), r.ref_rate_dps.clone()),
            (Column::Rate.name().to_owned(), r.rate_dps.clone()),
        ];
        for c in [
            Column::Temp,
            Column::MonoA,
            Column::MonoB,
            Column::Case,
            Column::RefAcc,
        ] {
            if let Some(v) = r.column(c) {
                cols.push((c.name().to_owned(), v.to_vec()));
            }
        }
        cols.push((
            Column::CompensatedRate.name().to_owned(),
            o.comp_dps.clone(),
        ));
        let summary = o.text.iter().take(2).cloned().collect();
        let report = o.report;
        let native = Native::new(
            &o.json,
            o.text,
            summary,
            report.map(|r| -> Box<dyn FnOnce() -> (String, String) + Send> {
                Box::new(move || (r.html(), r.fragment()))
            }),
        );
        Ok((native, cols))
    })?;
    Ok((native, named_arrays(py, cols)))
}

/// `gyro-lab lockin`.
#[pyfunction]
#[pyo3(signature = (fringe, label, pulses_per_deg, input_rate_dps=None, read=None))]
pub fn lockin(
    py: Python<'_>,
    fringe: &Bound<'_, PyAny>,
    label: &str,
    pulses_per_deg: f64,
    input_rate_dps: Option<f64>,
    read: Option<&Bound<'_, PyDict>>,
) -> PyResult<Native> {
    on_run(py, fringe, label, read, |source, spec| {
        let o = lockin_cmd::lockin(source, spec, pulses_per_deg, input_rate_dps, true)?;
        let summary = o
            .text
            .iter()
            .filter(|l| l.starts_with("lock-in"))
            .cloned()
            .collect();
        let report = o.report;
        Ok(Native::new(
            &o.json,
            o.text,
            summary,
            report.map(|r| -> Box<dyn FnOnce() -> (String, String) + Send> {
                Box::new(move || (r.html(), r.fragment()))
            }),
        ))
    })
}

/// `gyro-lab simulate run`: the run's columns.
#[pyfunction]
#[pyo3(signature = (model, profile, duration_s=None, dt_s=None, seed=1, arw_dpsh=None, bias_instability_dph=None, rate_random_walk_dphsh=None))]
#[allow(clippy::too_many_arguments)]
pub fn simulate_run<'py>(
    py: Python<'py>,
    model: Named,
    profile: &str,
    duration_s: Option<f64>,
    dt_s: Option<f64>,
    seed: u64,
    arw_dpsh: Option<f64>,
    bias_instability_dph: Option<f64>,
    rate_random_walk_dphsh: Option<f64>,
) -> PyResult<Arrays<'py>> {
    let cols = detached(py, || {
        let profile = simulate_cmd::profile(profile)?;
        let m = model_file::model_from_text(model.0, &model.1, profile.gyro())?;
        let (run, _) = simulate_cmd::simulate_run(&simulate_cmd::SimulateRequest {
            model: &m,
            profile,
            dt_s,
            duration_s,
            arw_dpsh,
            bias_instability_dph,
            rate_random_walk_dphsh,
            seed,
        })?;
        Ok(simulate_cmd::columns(&run)
            .into_iter()
            .map(|(c, v)| (c.name().to_owned(), v.to_vec()))
            .collect())
    })?;
    Ok(named_arrays(py, cols))
}

/// The board's frames from a capture's bytes: the FOG and RLG columns and
/// the summary (`record.json`'s keys) as JSON text.
#[pyfunction]
#[pyo3(signature = (data, name, rlg_counts_per_deg=None))]
#[allow(clippy::type_complexity)]
pub fn decode_frames<'py>(
    py: Python<'py>,
    data: &Bound<'py, PyBytes>,
    name: &str,
    rlg_counts_per_deg: Option<f64>,
) -> PyResult<(Arrays<'py>, Arrays<'py>, String)> {
    let bytes = data.as_bytes();
    let d = detached(py, || {
        frames::decode_frames(bytes, name, rlg_counts_per_deg)
    })?;
    let summary = serde_json::to_string(&d.summary).unwrap_or_default();
    Ok((named_arrays(py, d.fog), named_arrays(py, d.rlg), summary))
}
