//! A behavioural gyro model: the gyro kind, nominal parameters, and the named
//! effects it contains with their parameters (effects.rs holds every
//! formula). Evaluated on a run's inputs it is "the simulation": output =
//! reference rate + the sum of the effects.
//!
//! ```toml
//! kind = "gyro_model"
//! version = 1
//! gyro = "fog"                 # or "rlg"
//! [nominal]                    # optional, informative (e.g. phi0_rad, closure_hz)
//! [[effect]]
//! name = "bias"
//! bias_dph = 0.3
//! [[effect]]
//! name = "scale_factor_knee"
//! knee_c = 48.0
//! slope_change_ppm_per_c = 6.0
//! ```

use crate::data::run_file::Column;
use crate::effects::{Effect, GyroKind, Inputs};
use crate::error::{ColumnRef, LabError};
use std::collections::BTreeMap;
use std::path::Path;

pub const VERSION: u16 = 1;

/// One effect of a model with its parameters.
#[derive(Clone, Debug, PartialEq)]
pub struct ModelEffect {
    pub effect: Effect,
    pub params: BTreeMap<String, f64>,
}

#[derive(Clone, Debug, PartialEq)]
pub struct Model {
    pub gyro: GyroKind,
    pub nominal: toml::Table,
    pub effects: Vec<ModelEffect>,
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

/// An error at a byte offset of the model file: its line and character
/// column.
fn error_at(path: &Path, text: &str, offset: usize, msg: String) -> LabError {
    let before = &text[..offset.min(text.len())];
    let line = before.matches('\n').count() + 1;
    let col = before.len() - before.rfind('\n').map_or(0, |i| i + 1) + 1;
    LabError::at(
        path,
        line as u64,
        ColumnRef {
            index: col,
            name: None,
        },
        msg,
    )
}

impl Model {
    /// The ideal gyro: output = reference rate.
    pub fn ideal(gyro: GyroKind) -> Self {
        Self {
            gyro,
            nominal: toml::Table::new(),
            effects: vec![],
        }
    }

    /// Reads and checks a model file for a gyro of kind `expect`; errors are
    /// one line, `file:line:column: message`.
    pub fn read(path: &Path, expect: GyroKind) -> Result<Self, LabError> {
        let text = std::fs::read_to_string(path)
            .map_err(|e| LabError::input(path, format!("cannot read: {e}")))?;
        let raw: RawModel = toml::from_str(&text).map_err(|e| {
            let msg = e.message().replace('\n', " ");
            match e.span() {
                Some(s) => error_at(path, &text, s.start, msg),
                None => LabError::input(path, msg),
            }
        })?;
        let at = |s: std::ops::Range<usize>, msg: String| error_at(path, &text, s.start, msg);
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
        let gyro = match raw.gyro.get_ref().as_str() {
            "fog" => GyroKind::Fog,
            "rlg" => GyroKind::Rlg,
            g => return Err(at(raw.gyro.span(), format!("gyro `{g}`: fog or rlg"))),
        };
        if gyro != expect {
            return Err(at(
                raw.gyro.span(),
                format!(
                    "a model of the {} but --gyro {}",
                    gyro.name(),
                    expect.name()
                ),
            ));
        }
        let mut effects = vec![];
        for e in raw.effect {
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
                match x {
                    Some(x) if x.is_finite() => params.insert(k.clone(), x),
                    _ => {
                        return Err(at(
                            span.clone(),
                            format!("effect `{n}`: parameter `{k}` is not a finite number"),
                        ))
                    }
                };
            }
            for p in effect.params() {
                if !params.contains_key(p) {
                    return Err(at(
                        span.clone(),
                        format!("effect `{n}` lacks parameter `{p}`"),
                    ));
                }
            }
            effects.push(ModelEffect { effect, params });
        }
        Ok(Self {
            gyro,
            nominal: raw.nominal,
            effects,
        })
    }

    pub fn to_toml(&self) -> String {
        let mut t = toml::Table::new();
        t.insert("kind".into(), "gyro_model".into());
        t.insert("version".into(), (VERSION as i64).into());
        t.insert("gyro".into(), self.gyro.name().into());
        if !self.nominal.is_empty() {
            t.insert("nominal".into(), toml::Value::Table(self.nominal.clone()));
        }
        let effects: Vec<toml::Value> = self
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

    pub fn write(&self, path: &Path, comment: &str) -> Result<(), LabError> {
        let head: String = comment.lines().map(|l| format!("# {l}\n")).collect();
        std::fs::write(path, format!("{head}{}", self.to_toml())).map_err(|e| LabError::io(path, e))
    }

    /// The effects whose inputs the run lacks (the model cannot be evaluated
    /// on it then), with the columns missing.
    pub fn missing_inputs(&self, inp: &Inputs) -> Vec<(Effect, &'static [Column])> {
        self.effects
            .iter()
            .filter(|e| !e.effect.available(inp))
            .map(|e| (e.effect, e.effect.needs()))
            .collect()
    }

    /// The simulated output, deg/s: reference rate plus every effect.
    pub fn evaluate(&self, inp: &Inputs) -> Vec<f64> {
        let mut y = inp.w.clone();
        for e in &self.effects {
            for (o, c) in y.iter_mut().zip(e.effect.contribution(inp, &e.params)) {
                *o += c;
            }
        }
        y
    }
}
