//! What every command does with its results: the JSON line, the report
//! file, a progress bar on the terminal.

use gyro_lab_core::error::LabError;
use gyro_lab_core::report::document::Report;
use indicatif::{ProgressBar, ProgressStyle};
use std::path::Path;

/// Prints `v` as one JSON line.
pub fn print_json<T: serde::Serialize>(v: &T) -> Result<(), LabError> {
    let line = serde_json::to_string(v).map_err(|e| LabError::Io {
        file: None,
        msg: e.to_string(),
    })?;
    println!("{line}");
    Ok(())
}

/// Writes a report's HTML to `path`.
pub fn write_report(report: &Report, path: &Path) -> Result<(), LabError> {
    gyro_lab_core::data::atomic::write(path, report.html())
}

/// A progress bar of `len` steps drawn with `template`, or a hidden one
/// when `hidden` (the JSON output is for scripts).
pub fn progress_bar(len: u64, template: &str, hidden: bool) -> ProgressBar {
    if hidden {
        return ProgressBar::hidden();
    }
    let b = ProgressBar::new(len);
    b.set_style(ProgressStyle::with_template(template).unwrap_or(ProgressStyle::default_bar()));
    b
}
