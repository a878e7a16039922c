//! What a command found, held for Python: the JSON and the text made at
//! once, the report made when first asked for (a notebook shows it; a
//! loop over a fleet may never look). Errors and panics turned into
//! Python's exceptions.

use gyro_lab_core::error::LabError;
use pyo3::exceptions::{PyOSError, PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use std::sync::{Mutex, OnceLock};

/// Makes the report's HTML, once.
type Render = Box<dyn FnOnce() -> (String, String) + Send>;

/// A command's answer.
#[pyclass(frozen, module = "gyrolab._native")]
pub struct Native {
    json: String,
    text: Vec<String>,
    summary: Vec<String>,
    /// The report as a page and as a fragment, made on first use.
    html: OnceLock<Option<(String, String)>>,
    render: Mutex<Option<Render>>,
}

impl Native {
    pub fn new(
        json: &serde_json::Value,
        text: Vec<String>,
        summary: Vec<String>,
        render: Option<Render>,
    ) -> Self {
        let html = OnceLock::new();
        if render.is_none() {
            let _ = html.set(None);
        }
        Self {
            json: json.to_string(),
            text,
            summary,
            html,
            render: Mutex::new(render),
        }
    }

    fn report(&self, py: Python<'_>) -> Option<(String, String)> {
        py.detach(|| {
            self.html
                .get_or_init(|| {
                    let f = self.render.lock().ok()?.take()?;
                    std::panic::catch_unwind(std::panic::AssertUnwindSafe(f)).ok()
                })
                .clone()
        })
    }
}

#[pymethods]
impl Native {
    /// The command line's `--json` object, as its text.
    fn json(&self) -> &str {
        &self.json
    }

    /// The command line's text, line by line.
    fn text(&self) -> Vec<String> {
        self.text.clone()
    }

    /// The verdict in a few lines.
    fn summary(&self) -> Vec<String> {
        self.summary.clone()
    }

    /// The report as a self-contained page (None where the command has none).
    fn html(&self, py: Python<'_>) -> Option<String> {
        self.report(py).map(|r| r.0)
    }

    /// The report as a fragment for a notebook's output cell.
    fn fragment(&self, py: Python<'_>) -> Option<String> {
        self.report(py).map(|r| r.1)
    }
}

/// The lab's error as Python's: bad input (a file, a column, a cell, an
/// option) is `ValueError` with the command line's message; a failed
/// write `OSError`.
pub fn to_py(e: LabError) -> PyErr {
    match e {
        LabError::Io { .. } => PyOSError::new_err(e.to_string()),
        LabError::Bench(_) => PyRuntimeError::new_err(e.to_string()),
        _ => PyValueError::new_err(e.to_string()),
    }
}

/// Runs `f` without the GIL, a panic caught and said as a bug.
pub fn detached<T: Send>(
    py: Python<'_>,
    f: impl FnOnce() -> Result<T, LabError> + Send,
) -> PyResult<T> {
    let r = py.detach(|| std::panic::catch_unwind(std::panic::AssertUnwindSafe(f)));
    match r {
        Ok(r) => r.map_err(to_py),
        Err(p) => {
            let msg = p
                .downcast_ref::<&str>()
                .map(|s| s.to_string())
                .or_else(|| p.downcast_ref::<String>().cloned())
                .unwrap_or_default();
            Err(PyRuntimeError::new_err(format!(
                "gyrolab: internal error, a bug (please report it with the input): {msg}"
            )))
        }
    }
}
