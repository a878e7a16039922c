//! Model files on disk for the commands that take or write one (`discover`,
//! `simulate run`): the text is model/file.rs's.

use crate::error::{ColumnRef, LabError};
use crate::model::file::{parse, to_toml, ModelFileError};
use crate::model::gyro_kind::GyroKind;
use crate::model::gyro_model::Model;
use std::path::Path;

/// Reads and checks a model file for a gyro of kind `gyro` (the one
/// `--gyro` or the profile asks for).
pub fn read_model(path: &Path, gyro: GyroKind) -> Result<Model, LabError> {
    let text = std::fs::read_to_string(path)
        .map_err(|e| LabError::input(path, format!("cannot read: {e}")))?;
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
    parse(&text, gyro).map_err(|e| match e {
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
    })
}

/// Writes a model file, `comment` as `#` lines before it.
pub fn write_model(path: &Path, model: &Model, comment: &str) -> Result<(), LabError> {
    let head: String = comment.lines().map(|l| format!("# {l}\n")).collect();
    std::fs::write(path, format!("{head}{}", to_toml(model))).map_err(|e| LabError::io(path, e))
}
