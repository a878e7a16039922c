//! A formula evaluated on a run, row by row: its columns by name, the
//! term's parameters, `pi`; `ddt` and `d2dt2` are the tool's own filtered
//! derivatives in time (below), the same wherever a term is evaluated
//! (`simulate run --model`, `discover --model`, `discover`'s own fit).
//! A division by zero or a value that is not finite anywhere on the run
//! is an error at the place in the formula that made it.

use super::parse::{Expr, Func, Node, Op};
use crate::data::run_file::Column;
use crate::model::discovery::terms::curvature;
use crate::model::inputs::centered_slope;
use std::collections::BTreeMap;
use std::ops::Range;

/// `ddt(x)`: the least-squares slope of x over this many seconds either
/// side of each row (fewer at the record's ends): long enough to average a
/// quantised sensor's steps, short against thermal time constants.
pub const DDT_HALF_WIDTH_S: f64 = 30.0;
/// `d2dt2(x)`: the slope of that slope, each over this many seconds either
/// side, and a local cubic's curvature near the record's ends.
pub const D2DT2_HALF_WIDTH_S: f64 = 120.0;

/// The columns a formula may name: the run's inputs. Not the output
/// (`rate_dps`, the angle): a model predicts those.
pub const INPUT_COLUMNS: [Column; 7] = [
    Column::Time,
    Column::RefRate,
    Column::Temp,
    Column::MonoA,
    Column::MonoB,
    Column::Case,
    Column::RefAcc,
];

/// What a formula is evaluated with.
pub struct Env<'a> {
    /// The run's input columns present, by name (time among them).
    pub columns: &'a BTreeMap<&'a str, &'a [f64]>,
    /// The term's parameters.
    pub params: &'a BTreeMap<String, f64>,
}

/// A formula that cannot be evaluated on this run: where in its text, and
/// why.
#[derive(Clone, Debug, PartialEq)]
pub struct EvalError {
    pub span: Range<usize>,
    pub msg: String,
}

/// A value per row, or one for all rows.
enum Val {
    Row(Vec<f64>),
    All(f64),
}

impl Val {
    fn map(self, f: impl Fn(f64) -> f64) -> Val {
        match self {
            Val::All(a) => Val::All(f(a)),
            Val::Row(v) => Val::Row(v.into_iter().map(f).collect()),
        }
    }

    fn zip(self, o: Val, f: impl Fn(f64, f64) -> f64) -> Val {
        match (self, o) {
            (Val::All(a), Val::All(b)) => Val::All(f(a, b)),
            (Val::Row(a), Val::All(b)) => Val::Row(a.into_iter().map(|x| f(x, b)).collect()),
            (Val::All(a), Val::Row(b)) => Val::Row(b.into_iter().map(|y| f(a, y)).collect()),
            (Val::Row(a), Val::Row(b)) => {
                Val::Row(a.into_iter().zip(b).map(|(x, y)| f(x, y)).collect())
            }
        }
    }

    /// The first row (0 for a constant) where `bad` holds.
    fn first(&self, bad: impl Fn(f64) -> bool) -> Option<usize> {
        match self {
            Val::All(a) => bad(*a).then_some(0),
            Val::Row(v) => v.iter().position(|&x| bad(x)),
        }
    }
}

/// Names a formula uses, with the span of each use.
pub fn names(n: &Node) -> Vec<(String, Range<usize>)> {
    fn go(n: &Node, out: &mut Vec<(String, Range<usize>)>) {
        match &n.expr {
            Expr::Num(_) => {}
            Expr::Name(s) => out.push((s.clone(), n.span.clone())),
            Expr::Neg(x) | Expr::Call(_, x) => go(x, out),
            Expr::Bin(_, l, r) | Expr::Lag(l, r) | Expr::Within(_, l, r) => {
                go(l, out);
                go(r, out);
            }
        }
    }
    let mut v = vec![];
    go(n, &mut v);
    v
}

/// The formula's value on every row of a run of `rows` rows, deg/h.
pub fn evaluate(n: &Node, env: &Env, rows: usize) -> Result<Vec<f64>, EvalError> {
    let t = env.columns.get(Column::Time.name()).copied().unwrap_or(&[]);
    let at = |k: usize| {
        t.get(k).map_or(String::new(), |t| {
            format!(" (at {} = {t})", Column::Time.name())
        })
    };
    let v = eval(n, env, &at)?;
    if let Some(k) = v.first(|x| !x.is_finite()) {
        return Err(EvalError {
            span: n.span.clone(),
            msg: format!("the formula is not finite{}", at(k)),
        });
    }
    Ok(match v {
        Val::All(a) => vec![a; rows],
        Val::Row(r) => r,
    })
}

fn eval(n: &Node, env: &Env, at: &dyn Fn(usize) -> String) -> Result<Val, EvalError> {
    let err = |msg: String| EvalError {
        span: n.span.clone(),
        msg,
    };
    Ok(match &n.expr {
        Expr::Num(v) => Val::All(*v),
        Expr::Name(s) => {
            if let Some(c) = env.columns.get(s.as_str()) {
                Val::Row(c.to_vec())
            } else if let Some(p) = env.params.get(s) {
                Val::All(*p)
            } else if s == "pi" {
                Val::All(std::f64::consts::PI)
            } else {
                return Err(err(unknown_name(s, env)));
            }
        }
        Expr::Neg(x) => eval(x, env, at)?.map(|a| -a),
        Expr::Bin(op, l, r) => {
            let (a, b) = (eval(l, env, at)?, eval(r, env, at)?);
            match op {
                Op::Add => a.zip(b, |x, y| x + y),
                Op::Sub => a.zip(b, |x, y| x - y),
                Op::Mul => a.zip(b, |x, y| x * y),
                Op::Div => {
                    if let Some(k) = b.first(|y| y == 0.0) {
                        return Err(EvalError {
                            span: r.span.clone(),
                            msg: format!("divides by zero{}", at(k)),
                        });
                    }
                    a.zip(b, |x, y| x / y)
                }
                Op::Pow => {
                    let v = a.zip(b, pow);
                    if let Some(k) = v.first(|x| !x.is_finite()) {
                        return Err(err(format!("a power that is not finite{}", at(k))));
                    }
                    v
                }
            }
        }
        Expr::Lag(x, tau) => {
            let a = eval(x, env, at)?;
            let tau = match eval(tau, env, at)? {
                Val::All(v) if v > 0.0 && v.is_finite() => v,
                _ => {
                    return Err(EvalError {
                        span: tau.span.clone(),
                        msg: "a lag's time constant is a positive number of seconds".into(),
                    })
                }
            };
            let t = env.columns.get(Column::Time.name()).copied().unwrap_or(&[]);
            match a {
                Val::All(v) => Val::All(v),
                Val::Row(r) => Val::Row(lag(t, &r, tau)),
            }
        }
        Expr::Within(f, x, h) => {
            let half = match eval(h, env, at)? {
                Val::All(v) if v > 0.0 && v.is_finite() => v,
                _ => {
                    return Err(EvalError {
                        span: h.span.clone(),
                        msg: format!("{}'s half width is a positive number of seconds", f.name()),
                    })
                }
            };
            derivative(*f, eval(x, env, at)?, env, half)
        }
        Expr::Call(f, x) => {
            let a = eval(x, env, at)?;
            match f {
                Func::Abs => a.map(f64::abs),
                Func::Sin => a.map(f64::sin),
                Func::Cos => a.map(f64::cos),
                Func::Exp => {
                    let v = a.map(f64::exp);
                    if let Some(k) = v.first(|x| !x.is_finite()) {
                        return Err(err(format!("exp overflows{}", at(k))));
                    }
                    v
                }
                Func::Step => a.map(|v| if v >= 0.0 { 1.0 } else { 0.0 }),
                // Parsed as Expr::Lag (two arguments); never one.
                Func::Lag => return Err(err("lag takes two arguments: lag(x, tau)".into())),
                Func::Ddt => derivative(*f, a, env, DDT_HALF_WIDTH_S),
                Func::D2dt2 => derivative(*f, a, env, D2DT2_HALF_WIDTH_S),
            }
        }
    })
}

/// `ddt` or `d2dt2` of `a` with its slopes over `half` s either side.
fn derivative(f: Func, a: Val, env: &Env, half: f64) -> Val {
    let t = env.columns.get(Column::Time.name()).copied().unwrap_or(&[]);
    match a {
        // The derivative of a constant.
        Val::All(_) => Val::All(0.0),
        Val::Row(r) if f == Func::Ddt => Val::Row(centered_slope(t, &r, half)),
        Val::Row(r) => Val::Row(curvature(t, &r, half)),
    }
}

/// `x` through a first-order lag of time constant `tau` s over times
/// `t`, from `x`'s first value: exact for `x` linear between rows (the
/// lag of a ramp is the ramp less tau, reached after a few tau).
pub fn lag(t: &[f64], x: &[f64], tau: f64) -> Vec<f64> {
    let mut y = Vec::with_capacity(x.len());
    let mut prev: Option<(f64, f64, f64)> = None;
    for (&tk, &xk) in t.iter().zip(x) {
        let yk = match prev {
            None => xk,
            Some((t0, x0, y0)) => {
                let h = ((tk - t0) / tau).max(0.0);
                let e = (-h).exp();
                // (1 - e^-h)/h, its limit 1 at h = 0.
                let g = if h < 1e-8 {
                    1.0 - 0.5 * h
                } else {
                    (1.0 - e) / h
                };
                xk - (xk - x0) * g + (y0 - x0) * e
            }
        };
        y.push(yk);
        prev = Some((tk, xk, yk));
    }
    y
}

/// x^y, exact for small whole exponents (x^2 is x*x, as the formula says).
fn pow(x: f64, y: f64) -> f64 {
    if y.fract() == 0.0 && y.abs() <= 16.0 {
        x.powi(y as i32)
    } else {
        x.powf(y)
    }
}

fn unknown_name(s: &str, env: &Env) -> String {
    let cols: Vec<&str> = env.columns.keys().copied().collect();
    let params: Vec<&str> = env.params.keys().map(String::as_str).collect();
    let why = if INPUT_COLUMNS.iter().any(|c| c.name() == s) {
        format!("the run has no column `{s}`")
    } else if s == Column::Rate.name() || s == Column::Angle.name() {
        format!("`{s}` is the gyro's output, which the model predicts: a term is built from the run's inputs")
    } else {
        format!("unknown name `{s}`")
    };
    format!(
        "{why} (the run's inputs: {}; the term's parameters: {}; and pi)",
        cols.join(", "),
        if params.is_empty() {
            "none".to_string()
        } else {
            params.join(", ")
        }
    )
}

#[cfg(test)]
mod tests {
    use super::super::parse::parse;
    use super::*;

    /// The formula with the columns' names put in: `{t}` time, `{w}` the
    /// reference rate, `{T}` the coil temperature, `{y}` the output.
    fn f(s: &str) -> String {
        s.replace("{t}", Column::Time.name())
            .replace("{w}", Column::RefRate.name())
            .replace("{T}", Column::Temp.name())
            .replace("{y}", Column::Rate.name())
    }

    fn run(
        formula: &str,
        cols: &[(Column, Vec<f64>)],
        params: &[(&str, f64)],
    ) -> Result<Vec<f64>, EvalError> {
        let n = parse(&f(formula)).unwrap();
        let owned: BTreeMap<&str, &[f64]> =
            cols.iter().map(|(k, v)| (k.name(), v.as_slice())).collect();
        let p: BTreeMap<String, f64> = params.iter().map(|(k, v)| (k.to_string(), *v)).collect();
        let rows = cols.first().map_or(1, |c| c.1.len());
        evaluate(
            &n,
            &Env {
                columns: &owned,
                params: &p,
            },
            rows,
        )
    }

    #[test]
    fn values_as_the_formula_says() {
        let t: Vec<f64> = (0..5).map(|k| k as f64).collect();
        let w = vec![-2.0, -1.0, 0.0, 1.0, 2.0];
        let y = run(
            "k_dph * {w}^2 + c * abs({w}) * step({t} - 2)",
            &[(Column::Time, t.clone()), (Column::RefRate, w.clone())],
            &[("k_dph", 0.5), ("c", 3.0)],
        )
        .unwrap();
        assert_eq!(y, vec![2.0, 0.5, 0.0, 3.5, 8.0]);
        let y = run("2^3^2 - -1 + pi * 0", &[(Column::Time, t.clone())], &[]).unwrap();
        assert_eq!(y, vec![513.0; 5]);
        // ddt of a line is its slope; d2dt2 of a parabola its curvature.
        let t: Vec<f64> = (0..2000).map(|k| k as f64).collect();
        let x: Vec<f64> = t.iter().map(|t| 3.0 + 0.01 * t + 1e-6 * t * t).collect();
        let d = run(
            "ddt({T})",
            &[(Column::Time, t.clone()), (Column::Temp, x.clone())],
            &[],
        )
        .unwrap();
        assert!(
            (d[1000] - (0.01 + 2e-6 * 1000.0)).abs() < 1e-9,
            "{}",
            d[1000]
        );
        let c = run(
            "d2dt2({T})",
            &[(Column::Time, t.clone()), (Column::Temp, x)],
            &[],
        )
        .unwrap();
        assert!(c.iter().all(|c| (c - 2e-6).abs() < 1e-9), "{:?}", &c[..3]);
    }

    #[test]
    fn errors_at_the_place_that_made_them() {
        let t: Vec<f64> = (0..5).map(|k| k as f64).collect();
        let e = run("k / ({t} - 2)", &[(Column::Time, t.clone())], &[("k", 1.0)]).unwrap_err();
        assert_eq!(e.span, 4..13);
        assert!(
            e.msg.contains(&f("divides by zero (at {t} = 2)")),
            "{}",
            e.msg
        );
        let e = run("k * {T}", &[(Column::Time, t.clone())], &[("k", 1.0)]).unwrap_err();
        assert_eq!(e.span, 4..10);
        assert!(
            e.msg.contains(&f("the run has no column `{T}`")),
            "{}",
            e.msg
        );
        let e = run("k * {y}", &[(Column::Time, t.clone())], &[("k", 1.0)]).unwrap_err();
        assert!(e.msg.contains("the gyro's output"), "{}", e.msg);
        let e = run("exp(1000 * {t})", &[(Column::Time, t.clone())], &[]).unwrap_err();
        assert!(
            e.msg.contains(&f("exp overflows (at {t} = 1)")),
            "{}",
            e.msg
        );
        let e = run("({t} - 3)^0.5", &[(Column::Time, t)], &[]).unwrap_err();
        assert!(e.msg.contains(&f("not finite (at {t} = 0)")), "{}", e.msg);
    }

    #[test]
    fn a_derivative_over_a_half_width_given() {
        // A curvature that changes: x = t^4 / 12, so x'' = t^2. A least-
        // squares slope over +-h adds h^2/10 of the third derivative, so
        // the nested slopes read t^2 + 2 h^2 / 5: the width is honoured.
        let t: Vec<f64> = (0..3000).map(|k| k as f64 * 0.1).collect();
        let x: Vec<f64> = t.iter().map(|t| t.powi(4) / 12.0).collect();
        let cols = [(Column::Time, t.clone()), (Column::Temp, x)];
        let at = 1500;
        for h in [5.0, 20.0] {
            let c = run(&format!("d2dt2({{T}}, {h})"), &cols, &[]).unwrap();
            let want = t[at] * t[at] + 0.4 * h * h;
            assert!(
                (c[at] - want).abs() < 2e-3 * want,
                "h {h}: {} vs {want}",
                c[at]
            );
        }
        // The width may be a parameter; the default is D2DT2_HALF_WIDTH_S.
        let a = run("d2dt2({T}, h_s)", &cols, &[("h_s", D2DT2_HALF_WIDTH_S)]).unwrap();
        let b = run("d2dt2({T})", &cols, &[]).unwrap();
        assert_eq!(a, b);
        let a = run("ddt({T}, 30)", &cols, &[]).unwrap();
        let b = run("ddt({T})", &cols, &[]).unwrap();
        assert_eq!(a, b);
        // It prints as it parses.
        let n = crate::model::term::parse::parse(&f("k * d2dt2({T}, 60)")).unwrap();
        assert_eq!(
            crate::model::term::parse::to_text(&n),
            f("k * d2dt2({T}, 60)")
        );
        // A width that is not a positive number of seconds, at its place.
        let e = run("d2dt2({T}, 0)", &cols, &[]).unwrap_err();
        assert!(e.msg.contains("half width"), "{}", e.msg);
        assert_eq!(e.span, f("d2dt2({T}, ").len()..f("d2dt2({T}, 0").len());
    }
}
