//! Model files for the commands that take one (`discover`, `simulate
//! run`), from a file or as text a caller holds: the format is
//! model/file.rs's; errors are placed at the file's (or the text's) line
//! and column.

use crate::error::{ColumnRef, LabError};
use crate::model::file::{
    check_on_run, check_terms_on_run, parse_placed, to_toml, ModelFileError, Placed,
};
use crate::model::gyro_kind::GyroKind;
use crate::model::gyro_model::Model;
use crate::model::inputs::Inputs;
use crate::model::ranges::Extent;
use std::path::{Path, PathBuf};

/// A model read from its file, with what the checks on a run need.
pub struct ModelFile {
    pub model: Model,
    /// The file, or the caller's name for the text.
    path: PathBuf,
    text: String,
    places: Placed,
}

impl ModelFile {
    /// The domains that depend on the run (a knee inside the temperatures
    /// it covers), refused at the parameter's line and column.
    pub fn check_on_run(&self, extent: &Extent) -> Result<(), LabError> {
        check_on_run(&self.text, &self.model, &self.places, extent)
            .map_err(|e| placed(&self.path, e))
    }

    /// The terms evaluated on the run: one that cannot be (a division by
    /// zero, a column the run lacks) refused at its place in the formula.
    pub fn check_terms(&self, inp: &Inputs) -> Result<(), LabError> {
        check_terms_on_run(&self.text, &self.model, &self.places, inp)
            .map_err(|e| placed(&self.path, e))
    }
}

/// A model file read, keeping the text for the checks on a run.
pub fn read_model_file(path: &Path, gyro: GyroKind) -> Result<ModelFile, LabError> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| LabError::input(path, format!("cannot read: {e}")))?;
    model_from_text(text, path, gyro)
}

/// A model given as its file's text; `name` places its errors (a path, or
/// what the caller calls it).
pub fn model_from_text(
    text: String,
    name: impl Into<PathBuf>,
    gyro: GyroKind,
) -> Result<ModelFile, LabError> {
    let path = name.into();
    let (model, places) = parse_placed(&text, gyro).map_err(|e| placed(&path, e))?;
    Ok(ModelFile {
        model,
        path,
        text,
        places,
    })
}

/// A model file's error as the lab's, at its place in `path`.
fn placed(path: &Path, e: ModelFileError) -> LabError {
    let at = |line, column, msg| {
        LabError::at(
            path,
            line,
            ColumnRef {
                index: column,
                name: None,
            },
            msg,
        )
    };
    match e {
        ModelFileError::At { line, column, msg } => at(line, column, msg),
        ModelFileError::Whole(msg) => LabError::input(path, msg),
        ModelFileError::OtherGyro {
            line,
            column,
            found,
            asked,
        } => at(
            line,
            column,
            format!(
                "a model of the {} but --gyro {}",
                found.name(),
                asked.name()
            ),
        ),
    }
}

/// A model file's text, `comment` as `#` lines before it.
pub fn model_text(model: &Model, comment: &str) -> String {
    let head: String = comment.lines().map(|l| format!("# {l}\n")).collect();
    format!("{head}{}", to_toml(model))
}
