//! A term outside the physics library (docs/interfaces.md, "Model file"):
//! a formula over the run's input columns and the term's named parameters,
//! its value a rate in deg/h. A user who suspects an effect writes one by
//! hand; `discover` proposes one where the residual holds what no library
//! effect explains. parse.rs is the grammar (and the formula written back
//! as text), eval.rs the evaluation on a run.

pub mod eval;
pub mod parse;

pub use eval::{evaluate, names, Env, EvalError, INPUT_COLUMNS};
pub use parse::{parse, to_text, Expr, Func, Node, Op, ParseError};

use crate::data::run_file::Column;
use crate::model::inputs::Inputs;
use std::collections::BTreeMap;
use std::ops::Range;

/// A term of a model: its formula as written, its tree, and its
/// parameters' values.
#[derive(Clone, Debug, PartialEq)]
pub struct Term {
    pub formula: String,
    pub node: Node,
    pub params: BTreeMap<String, f64>,
}

/// What is wrong with a term before any run is seen: where in the formula
/// (a byte span of its text), and why.
#[derive(Clone, Debug, PartialEq)]
pub struct TermError {
    pub span: Range<usize>,
    pub msg: String,
}

impl Term {
    /// The term of `formula` with `params`: it must parse, every name it
    /// uses must be an input column, a parameter or `pi`, and every
    /// parameter must be used (a parameter no formula reads is a typo).
    pub fn new(formula: &str, params: BTreeMap<String, f64>) -> Result<Term, TermError> {
        let node = parse(formula).map_err(|e| TermError {
            span: e.offset..e.offset,
            msg: e.msg,
        })?;
        let used = names(&node);
        for (n, span) in &used {
            let known =
                params.contains_key(n) || n == "pi" || INPUT_COLUMNS.iter().any(|c| c.name() == n);
            if !known && (n == Column::Rate.name() || n == Column::Angle.name()) {
                return Err(TermError {
                    span: span.clone(),
                    msg: format!("`{n}` is the gyro's output, which the model predicts: a term is built from the run's inputs"),
                });
            }
            if !known {
                let ps: Vec<&str> = params.keys().map(String::as_str).collect();
                let cols: Vec<&str> = INPUT_COLUMNS.iter().map(|c| c.name()).collect();
                return Err(TermError {
                    span: span.clone(),
                    msg: format!(
                        "unknown name `{n}` (a term reads the run's inputs {}, its parameters {}, and pi)",
                        cols.join(", "),
                        if ps.is_empty() { "(none)".to_string() } else { ps.join(", ") }
                    ),
                });
            }
        }
        if let Some(p) = params.keys().find(|p| !used.iter().any(|(n, _)| n == *p)) {
            return Err(TermError {
                span: 0..formula.len(),
                msg: format!("parameter `{p}` is not used by the formula"),
            });
        }
        Ok(Term {
            formula: formula.to_string(),
            node,
            params,
        })
    }

    /// The term's value on every row of the run, deg/h.
    pub fn evaluate(&self, inp: &Inputs) -> Result<Vec<f64>, EvalError> {
        let columns = inp.columns();
        evaluate(
            &self.node,
            &Env {
                columns: &columns,
                params: &self.params,
            },
            inp.len(),
        )
    }
}
