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
