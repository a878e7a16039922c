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
//! [[effect]]
//! name = "term"                # outside the library (model/term/)
//! formula = "k_dph * ref_rate_dps^2"
//! k_dph = -1.2e-3
//! ```

use super::effects::Effect;
use super::gyro_kind::GyroKind;
use super::gyro_model::{Model, ModelEffect};
use super::inputs::Inputs;
use super::ranges::{domain_error, Extent};
use super::term::Term;
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
    // The table's span may cover only its `[[effect]]` header: its keys
    // run from there to the next header.
    let body = &text[span.start.min(text.len())..];
    let mut off = span.start;
    for (i, line) in body.split_inclusive('\n').enumerate() {
        if i > 0 && line.trim_start().starts_with('[') {
            break;
        }
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

/// The name of a term outside the library, and its formula's key.
pub const TERM: &str = "term";
const FORMULA: &str = "formula";

/// One `[[effect]]` table with `name = "term"`: its formula (a TOML string
/// on one line, so a place in the formula is a place in the file) and its
/// parameters, every one a finite number the formula uses. Its places:
/// `formula` at the formula's first character.
fn term(text: &str, e: toml::Spanned<RawEffect>) -> Result<(Term, Places), ModelFileError> {
    let span = e.span();
    let e = e.into_inner();
    let mut params = BTreeMap::new();
    let mut places = Places::new();
    let mut formula = None;
    for (k, v) in &e.params {
        let place = value_offset(text, &span, k);
        if k == FORMULA {
            let Some(f) = v.as_str() else {
                return Err(ModelFileError::at(
                    text,
                    place,
                    "term: `formula` is not a string".into(),
                ));
            };
            // Past the opening quote of a basic or literal string.
            let start = place + 1;
            if text.get(start..start + f.len()) != Some(f) {
                return Err(ModelFileError::at(
                    text,
                    place,
                    "term: write the formula on one line, without escapes".into(),
                ));
            }
            formula = Some(f.to_string());
            places.insert(FORMULA.into(), start);
            continue;
        }
        match v.as_float().or(v.as_integer().map(|i| i as f64)) {
            Some(x) if x.is_finite() => {
                params.insert(k.clone(), x);
                places.insert(k.clone(), place);
            }
            _ => {
                return Err(ModelFileError::at(
                    text,
                    place,
                    format!("term: parameter `{k}` is not a finite number"),
                ))
            }
        }
    }
    let Some(formula) = formula else {
        return Err(ModelFileError::at(
            text,
            span.start,
            format!(
                "term: no `formula` (e.g. formula = \"k_dph * {}^2\")",
                crate::data::run_file::Column::RefRate.name()
            ),
        ));
    };
    let at = places[FORMULA];
    let t = Term::new(&formula, params)
        .map_err(|e| ModelFileError::at(text, at + e.span.start, format!("term: {}", e.msg)))?;
    Ok((t, places))
}

/// Where the values of a model file's effects and terms are, in order.
#[derive(Clone, Debug, Default)]
pub struct Placed {
    pub effects: Vec<Places>,
    pub terms: Vec<Places>,
}

/// Reads and checks the text of a model file for a gyro of kind `expect`.
pub fn parse(text: &str, expect: GyroKind) -> Result<Model, ModelFileError> {
    parse_placed(text, expect).map(|(m, _)| m)
}

/// [`parse`], with where each effect's parameter values are in the text
/// (for the checks that need the run, [`check_on_run`]).
pub fn parse_placed(text: &str, expect: GyroKind) -> Result<(Model, Placed), ModelFileError> {
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
    let mut effects = vec![];
    let mut terms = vec![];
    let mut placed = Placed::default();
    for e in raw.effect {
        if e.get_ref().name.get_ref() == TERM {
            let (t, p) = term(text, e)?;
            terms.push(t);
            placed.terms.push(p);
        } else {
            let (m, p) = effect(text, e, gyro)?;
            effects.push(m);
            placed.effects.push(p);
        }
    }
    Ok((
        Model {
            gyro,
            nominal: raw.nominal,
            effects,
            terms,
        },
        placed,
    ))
}

/// The domains that depend on the run (a knee inside the temperatures it
/// covers): the first parameter outside, at its place in `text`.
pub fn check_on_run(
    text: &str,
    model: &Model,
    placed: &Placed,
    extent: &Extent,
) -> Result<(), ModelFileError> {
    for (e, pl) in model.effects.iter().zip(&placed.effects) {
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

/// The terms on the run: the first that cannot be evaluated (a division
/// by zero, a column the run lacks, a value that is not finite), at its
/// place in the formula.
pub fn check_terms_on_run(
    text: &str,
    model: &Model,
    placed: &Placed,
    inp: &Inputs,
) -> Result<(), ModelFileError> {
    model.check_terms(inp).map_err(|(i, e)| {
        let at = placed.terms.get(i).and_then(|p| p.get(FORMULA)).copied();
        ModelFileError::at(
            text,
            at.unwrap_or(0) + e.span.start,
            format!("term: {}", e.msg),
        )
    })
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
        .chain(model.terms.iter().map(|t| {
            let mut m = toml::Table::new();
            m.insert("name".into(), TERM.into());
            m.insert(FORMULA.into(), t.formula.clone().into());
            for (k, v) in &t.params {
                m.insert(k.clone(), (*v).into());
            }
            toml::Value::Table(m)
        }))
        .collect();
    if !effects.is_empty() {
        t.insert("effect".into(), toml::Value::Array(effects));
    }
    toml::to_string(&t).unwrap_or_default()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::data::run_file::Column;

    fn model_text(term: &str) -> String {
        format!("kind = \"gyro_model\"\nversion = 1\ngyro = \"fog\"\n[[effect]]\nname = \"bias\"\nbias_dph = 0.5\n[[effect]]\nname = \"term\"\n{term}\n")
    }

    fn err_at(text: &str) -> (u64, usize, String) {
        match parse(text, GyroKind::Fog) {
            Err(ModelFileError::At { line, column, msg }) => (line, column, msg),
            other => panic!("{other:?}"),
        }
    }

    #[test]
    fn a_term_reads_and_writes_back_the_same_model() {
        let w = Column::RefRate.name();
        let text = model_text(&format!("formula = \"k_dph * {w}^2\"\nk_dph = -1.2e-3"));
        let m = parse(&text, GyroKind::Fog).unwrap();
        assert_eq!(m.effects.len(), 1);
        assert_eq!(m.terms.len(), 1);
        assert_eq!(m.terms[0].params["k_dph"], -1.2e-3);
        let again = parse(&to_toml(&m), GyroKind::Fog).unwrap();
        assert_eq!(again, m);
    }

    #[test]
    fn a_bad_term_is_refused_at_its_place() {
        // Line 9 is the formula's; column 12 its first character.
        let (line, col, msg) = err_at(&model_text("formula = \"k * (x + \"\nk = 1"));
        assert_eq!((line, col), (9, 21), "{msg}");
        let (line, col, msg) = err_at(&model_text("formula = \"k * speed\"\nk = 1"));
        assert_eq!((line, col), (9, 16), "{msg}");
        assert!(msg.contains("unknown name `speed`"), "{msg}");
        let (line, _, msg) = err_at(&model_text("formula = \"k * pi\"\nk = 1\nc = 2"));
        assert_eq!(line, 9);
        assert!(msg.contains("parameter `c` is not used"), "{msg}");
        let (line, col, msg) = err_at(&model_text("formula = \"k * pi\"\nk = \"one\""));
        assert_eq!((line, col), (10, 5), "{msg}");
        let (line, _, msg) = err_at(&model_text("k = 1"));
        assert_eq!(line, 7, "{msg}");
        assert!(msg.contains("no `formula`"), "{msg}");
    }

    #[test]
    fn a_term_that_divides_by_zero_on_the_run_is_refused_there() {
        let t = Column::Time.name();
        let text = model_text(&format!("formula = \"k / ({t} - 3)\"\nk = 1"));
        let (m, placed) = parse_placed(&text, GyroKind::Fog).unwrap();
        let inp = Inputs::new(
            (0..10).map(|k| k as f64).collect(),
            vec![0.0; 10],
            None,
            None,
            None,
            None,
        );
        match check_terms_on_run(&text, &m, &placed, &inp) {
            Err(ModelFileError::At { line, column, msg }) => {
                // The divisor `(t_s - 3)` starts at the formula's 5th character.
                assert_eq!((line, column), (9, 16), "{msg}");
                assert!(msg.contains("divides by zero"), "{msg}");
            }
            other => panic!("{other:?}"),
        }
        // The model's output is the reference plus bias and term elsewhere.
        let text = model_text(&format!("formula = \"k * {t}\"\nk = 36"));
        let m = parse(&text, GyroKind::Fog).unwrap();
        let y = m.evaluate(&inp);
        for (k, y) in y.iter().enumerate() {
            let want = (0.5 + 36.0 * k as f64) / 3600.0;
            assert!((y - want).abs() < 1e-15, "{k}: {y} against {want}");
        }
    }
}
