//! What Python hands over, as the lab reads it: a run as a path or as
//! named columns (numpy float64 arrays read where they lie; other number
//! types converted, anything else refused at its column), and the read
//! options as the command line's `--columns`, units and stretch.

use gyro_lab_core::data::read_spec::ReadSpec;
use gyro_lab_core::data::source::{Columns, Origin, Source};
use gyro_lab_core::error::LabError;
use numpy::{
    PyArray1, PyArrayDescrMethods, PyArrayMethods, PyReadonlyArray1, PyUntypedArray,
    PyUntypedArrayMethods,
};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use std::borrow::Cow;
use std::collections::BTreeMap;
use std::path::PathBuf;

/// One column as held: numpy's own float64 memory, or a converted copy.
enum Held<'py> {
    View(PyReadonlyArray1<'py, f64>),
    Owned(Vec<f64>),
}

/// A run (or a fringe record) from Python.
pub struct RunIn<'py> {
    label: String,
    kind: Kind<'py>,
}

enum Kind<'py> {
    Path(PathBuf),
    Arrays(Vec<(String, Held<'py>)>),
}

impl<'py> RunIn<'py> {
    /// A path (`str` or `os.PathLike`), or a list of (name, array) pairs;
    /// `label` is what errors call it (`run`, `fringe`, `validate`).
    pub fn new(obj: &Bound<'py, PyAny>, label: &str) -> PyResult<Self> {
        let kind = if let Ok(p) = obj.extract::<PathBuf>() {
            Kind::Path(p)
        } else {
            let pairs: Vec<(String, Bound<'py, PyAny>)> = obj.extract().map_err(|_| {
                pyo3::exceptions::PyTypeError::new_err(format!(
                    "{label}: a path, a dict of 1-D arrays or a pandas DataFrame"
                ))
            })?;
            let mut cols = Vec::with_capacity(pairs.len());
            for (name, a) in pairs {
                let held = held(&a, label, &name)?;
                cols.push((name, held));
            }
            Kind::Arrays(cols)
        };
        Ok(Self {
            label: label.to_owned(),
            kind,
        })
    }

    /// What the lab reads: the file, or the columns borrowed (their
    /// lengths checked).
    pub fn prepare(&self) -> PyResult<Prepared<'_>> {
        let cols = match &self.kind {
            Kind::Path(p) => return Ok(Prepared::File(p.clone())),
            Kind::Arrays(cols) => cols,
        };
        let mut c = Columns::new(&self.label);
        for (name, h) in cols {
            let values: Cow<[f64]> = match h {
                Held::View(v) => match v.as_slice() {
                    Ok(s) => Cow::Borrowed(s),
                    Err(_) => Cow::Owned(v.as_array().to_vec()),
                },
                Held::Owned(v) => Cow::Borrowed(v),
            };
            c.push(name, values).map_err(crate::outcome::to_py)?;
        }
        Ok(Prepared::Columns(c))
    }
}

/// A run ready to read, free of Python (it crosses to the thread that
/// works without the GIL).
pub enum Prepared<'a> {
    File(PathBuf),
    Columns(Columns<'a>),
}

impl Prepared<'_> {
    pub fn source(&self) -> Source<'_> {
        match self {
            Prepared::File(p) => Source::File(p),
            Prepared::Columns(c) => Source::Columns(c),
        }
    }
}

/// A column as the lab can read it: 1-D, of numbers; float64 read in
/// place, other integer and float types converted.
fn held<'py>(a: &Bound<'py, PyAny>, label: &str, name: &str) -> PyResult<Held<'py>> {
    let refuse = |msg: String| {
        crate::outcome::to_py(Origin::Memory(label.to_owned()).column(0, 0, name, msg))
    };
    if let Ok(f) = a.cast::<PyArray1<f64>>() {
        return Ok(Held::View(f.readonly()));
    }
    let u = a.cast::<PyUntypedArray>().map_err(|_| {
        refuse(format!(
            "a {}, not a numpy array",
            a.get_type()
                .name()
                .map(|n| n.to_string())
                .unwrap_or_default()
        ))
    })?;
    if u.ndim() != 1 {
        return Err(refuse(format!("a {}-D array; a column is 1-D", u.ndim())));
    }
    let kind = u.dtype().kind();
    if !matches!(kind, b'i' | b'u' | b'f') {
        let dt = u.dtype().to_string();
        return Err(refuse(format!(
            "dtype {dt} is not a number type (int or float): a column holds numbers"
        )));
    }
    let f = a.call_method1("astype", ("float64",))?;
    let f = f.cast::<PyArray1<f64>>()?;
    Ok(Held::Owned(f.readonly().as_array().to_vec()))
}

/// The read options, as the command line's: `columns` maps ours onto the
/// caller's names, the units are the command line's words.
#[derive(Default)]
pub struct ReadIn {
    pub columns: Option<BTreeMap<String, String>>,
    pub rate_unit: Option<String>,
    pub ref_rate_unit: Option<String>,
    pub temp_unit: Option<String>,
    pub time_unit: Option<String>,
    pub from_s: Option<f64>,
    pub to_s: Option<f64>,
}

impl ReadIn {
    /// The options from their dict (the keyword arguments).
    pub fn from_dict(d: Option<&Bound<'_, PyDict>>) -> PyResult<Self> {
        let Some(d) = d else {
            return Ok(Self::default());
        };
        fn get<'py, T: FromPyObjectOwned<'py>>(
            d: &Bound<'py, PyDict>,
            k: &str,
        ) -> PyResult<Option<T>> {
            match d.get_item(k)? {
                Some(v) if !v.is_none() => match v.extract::<T>() {
                    Ok(x) => Ok(Some(x)),
                    Err(e) => {
                        let e: PyErr = e.into();
                        Err(pyo3::exceptions::PyTypeError::new_err(format!("{k}: {e}")))
                    }
                },
                _ => Ok(None),
            }
        }
        Ok(Self {
            columns: get(d, "columns")?,
            rate_unit: get(d, "rate_unit")?,
            ref_rate_unit: get(d, "ref_rate_unit")?,
            temp_unit: get(d, "temp_unit")?,
            time_unit: get(d, "time_unit")?,
            from_s: get(d, "from_s")?,
            to_s: get(d, "to_s")?,
        })
    }

    pub fn spec(&self) -> Result<ReadSpec, LabError> {
        fn unit<U: std::str::FromStr<Err = LabError>>(
            name: &str,
            v: &Option<String>,
        ) -> Result<Option<U>, LabError> {
            v.as_deref()
                .map(|s| {
                    s.parse()
                        .map_err(|e: LabError| LabError::Usage(format!("{name}: {e}")))
                })
                .transpose()
        }
        let spec = ReadSpec {
            rename: self
                .columns
                .iter()
                .flatten()
                .map(|(a, b)| (a.clone(), b.clone()))
                .collect(),
            rate_unit: unit("rate_unit", &self.rate_unit)?,
            ref_rate_unit: unit("ref_rate_unit", &self.ref_rate_unit)?,
            temp_unit: unit("temp_unit", &self.temp_unit)?,
            time_unit: unit("time_unit", &self.time_unit)?,
            from_s: self.from_s,
            to_s: self.to_s,
        };
        spec.check_stretch(["from_s", "to_s"])?;
        Ok(spec)
    }
}
