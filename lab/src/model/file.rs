//! The model file, model.toml (README.md): `kind = "gyro_model"`,
//! `version`, `gyro = "fog"|"rlg"|"mems"`, an optional `[nominal]` table, then
//! `[[effect]]` tables with `name` and the effect's parameters. Read from
//! and written to text here; the commands do the files.
//!
//! ```toml
//! kind = "gyro_model"
//! version = 1
//! gyro = "fog"                 # or "rlg", "mems"
//! [nominal]                    # optional, informative (e.g. phi0_rad, closure_hz)
//! [[effect]]
//! name = "bias"
//! bias_dph = 0.3
//! [[effect]]
//! name = "scale_factor_knee"
//! knee_c = 48.0
//! slope_change_ppm_per_c = 6.0
//! ```

use super::effects::Effect;
use super::gyro_kind::GyroKind;
use super::gyro_model::{Model, ModelEffect};
use super::ranges::{domain_error, Extent};
use std::collections::BTreeMap;

pub const VERSION: u16 = 1;

/// What is wrong with a model file's text, and where.
#[derive(Clone, Debug, PartialEq)]
pub enum ModelFileError {
    /// At a line and character column.
    At {
        line: u64,
        column: usize,
        msg: String,
    },
    /// The text as a whole.
    Whole(String),
    /// A model of another gyro than the one asked for (its `gyro` value
    /// at line, column).
    OtherGyro {
        line: u64,
        column: usize,
        found: GyroKind,
        asked: GyroKind,
    },
}

impl ModelFileError {
    fn at(text: &str, offset: usize, msg: String) -> Self {
        let (line, column) = place(text, offset);
        ModelFileError::At { line, column, msg }
    }
}

/// Line and character column of a byte offset.
fn place(text: &str, offset: usize) -> (u64, usize) {
    let before = &text[..offset.min(text.len())];
    let line = before.matches('\n').count() + 1;
    let col = before.len() - before.rfind('\n').map_or(0, |i| i + 1) + 1;
    (line as u64, col)
}

#[derive(serde::Deserialize)]
#[serde(deny_unknown_fields)]
struct RawModel {
    kind: toml::Spanned<String>,
    version: toml::Spanned<u16>,
    gyro: toml::Spanned<String>,
    #[serde(default)]
    nominal: toml::Table,
    #[serde(default)]
    effect: Vec<toml::Spanned<RawEffect>>,
}

#[derive(serde::Deserialize)]
struct RawEffect {
    name: toml::Spanned<String>,
    #[serde(flatten)]
    params: BTreeMap<String, toml::Value>,
}

/// Where each parameter's value starts in the text (byte offsets), by name.
pub type Places = BTreeMap<String, usize>;

/// The byte offset of the value of `key` inside the table text at `span`
/// (its `key = value` line), else the table's start.
fn value_offset(text: &str, span: &std::ops::Range<usize>, key: &str) -> usize {
    let body = &text[span.start.min(text.len())..span.end.min(text.len())];
    let mut off = span.start;
    for line in body.split_inclusive('\n') {
        let trimmed = line.trim_start();
        let lead = line.len() - trimmed.len();
        if let Some(rest) = trimmed.strip_prefix(key) {
            let after = rest.trim_start();
            if let Some(v) = after.strip_prefix('=') {
                let v_lead = v.len() - v.trim_start().len();
                return off + lead + key.len() + (rest.len() - after.len()) + 1 + v_lead;
            }
        }
        off += line.len();
    }
    span.start
}

/// One `[[effect]]` table of a model of the `gyro`: a named effect of
/// the library, with every parameter it has and no other, each inside its
/// domain (ranges.rs); and where its values are.
fn effect(
    text: &str,
    e: toml::Spanned<RawEffect>,
    gyro: GyroKind,
) -> Result<(ModelEffect, Places), ModelFileError> {
    let at = |s: std::ops::Range<usize>, msg: String| ModelFileError::at(text, s.start, msg);
    let span = e.span();
    let e = e.into_inner();
    let n = e.name.get_ref();
    let Some(effect) = Effect::from_name(n) else {
        let names: Vec<&str> = Effect::ALL.iter().map(|e| e.name()).collect();
        return Err(at(
            e.name.span(),
            format!(
                "unknown effect `{n}` (the effects are {})",
                names.join(", ")
            ),
        ));
    };
    if !effect.applies_to(gyro) {
        return Err(at(
            e.name.span(),
            format!("`{n}` is not an effect of the {}", gyro.name()),
        ));
    }
    let mut params = BTreeMap::new();
    let mut places = Places::new();
    for (k, v) in &e.params {
        if !effect.params().contains(&k.as_str()) {
            return Err(at(
                span.clone(),
                format!(
                    "effect `{n}` has no parameter `{k}` (its parameters: {})",
                    effect.params().join(", ")
                ),
            ));
        }
        let x = v.as_float().or(v.as_integer().map(|i| i as f64));
        let place = value_offset(text, &span, k);
        match x {
            Some(x) if x.is_finite() => {
                if let Some(why) = domain_error(effect, k, x, None) {
                    return Err(ModelFileError::at(
                        text,
                        place,
                        format!("effect `{n}`: {why}"),
                    ));
                }
                params.insert(k.clone(), x)
            }
            _ => {
                return Err(ModelFileError::at(
                    text,
                    place,
                    format!("effect `{n}`: parameter `{k}` is not a finite number"),
                ))
            }
        };
        places.insert(k.clone(), place);
    }
    for p in effect.params() {
        if !params.contains_key(p) {
            return Err(at(
                span.clone(),
                format!("effect `{n}` lacks parameter `{p}`"),
            ));
        }
    }
    Ok((ModelEffect { effect, params }, places))
}

/// Reads and checks the text of a model file for a gyro of kind `expect`.
pub fn parse(text: &str, expect: GyroKind) -> Result<Model, ModelFileError> {
    parse_placed(text, expect).map(|(m, _)| m)
}

/// [`parse`], with where each effect's parameter values are in the text
/// (for the checks that need the run, [`check_on_run`]).
pub fn parse_placed(text: &str, expect: GyroKind) -> Result<(Model, Vec<Places>), ModelFileError> {
    let raw: RawModel = toml::from_str(text).map_err(|e| {
        let msg = e.message().replace('\n', " ");
        match e.span() {
            Some(s) => ModelFileError::at(text, s.start, msg),
            None => ModelFileError::Whole(msg),
        }
    })?;
    let at = |s: std::ops::Range<usize>, msg: String| ModelFileError::at(text, s.start, msg);
    if raw.kind.get_ref() != "gyro_model" {
        return Err(at(
            raw.kind.span(),
            format!(
                "kind `{}`: not a gyro model (kind = \"gyro_model\")",
                raw.kind.get_ref()
            ),
        ));
    }
    if *raw.version.get_ref() != VERSION {
        return Err(at(
            raw.version.span(),
            format!(
                "version {} (this tool reads version {VERSION})",
                raw.version.get_ref()
            ),
        ));
    }
    let Some(gyro) = GyroKind::from_name(raw.gyro.get_ref()) else {
        let g = raw.gyro.get_ref();
        return Err(at(raw.gyro.span(), format!("gyro `{g}`: fog, rlg or mems")));
    };
    if gyro != expect {
        let (line, column) = place(text, raw.gyro.span().start);
        return Err(ModelFileError::OtherGyro {
            line,
            column,
            found: gyro,
            asked: expect,
        });
    }
    let (effects, places): (Vec<ModelEffect>, Vec<Places>) = raw
        .effect
        .into_iter()
        .map(|e| effect(text, e, gyro))
        .collect::<Result<Vec<_>, _>>()?
        .into_iter()
        .unzip();
    Ok((
        Model {
            gyro,
            nominal: raw.nominal,
            effects,
        },
        places,
    ))
}

/// The domains that depend on the run (a knee inside the temperatures it
/// covers): the first parameter outside, at its place in `text`.
pub fn check_on_run(
    text: &str,
    model: &Model,
    places: &[Places],
    extent: &Extent,
) -> Result<(), ModelFileError> {
    for (e, pl) in model.effects.iter().zip(places) {
        for (k, v) in &e.params {
            if let Some(why) = domain_error(e.effect, k, *v, Some(extent)) {
                let off = pl.get(k).copied().unwrap_or(0);
                return Err(ModelFileError::at(
                    text,
                    off,
                    format!("effect `{}`: {why}", e.effect.name()),
                ));
            }
        }
    }
    Ok(())
}

/// The model as a model file's text.
pub fn to_toml(model: &Model) -> String {
    let mut t = toml::Table::new();
    t.insert("kind".into(), "gyro_model".into());
    t.insert("version".into(), (VERSION as i64).into());
    t.insert("gyro".into(), model.gyro.name().into());
    if !model.nominal.is_empty() {
        t.insert("nominal".into(), toml::Value::Table(model.nominal.clone()));
    }
    let effects: Vec<toml::Value> = model
        .effects
        .iter()
        .map(|e| {
            let mut m = toml::Table::new();
            m.insert("name".into(), e.effect.name().into());
            for (k, v) in &e.params {
                m.insert(k.clone(), (*v).into());
            }
            toml::Value::Table(m)
        })
        .collect();
    if !effects.is_empty() {
        t.insert("effect".into(), toml::Value::Array(effects));
    }
    toml::to_string(&t).unwrap_or_default()
}
