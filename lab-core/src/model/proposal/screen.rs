//! The candidates screened on window means: each input primitive is
//! evaluated once over the rows (its formula, exactly as the model file
//! reads it; a lag once per time constant of its grid) and averaged over
//! the fit's windows; a candidate's column is then the product of its
//! factors' window means, and a shape of time is evaluated at the
//! windows' mid times. The search costs the windows, not the rows, and no
//! grid of whitened columns is held: each candidate's columns are made,
//! whitened and reduced to their cross-validation statistics in turn.
//!
//! A product of window means is the window mean of the product where the
//! factors hold still within a window (1 s, or the fit's longer window on
//! a day-long record): exact at one row a window, and close elsewhere
//! (the table's rate steps between windows). The term proposed is then
//! evaluated exactly, row by row, from its formula (mod.rs).

use super::candidates::{Candidate, Factor, Prim, PrimKind};
use crate::model::discovery::windows::Windows;
use crate::model::inputs::Inputs;
use crate::model::term::Term;
use std::collections::{BTreeMap, HashMap};

/// The window means of the primitives, and the windows' times as inputs.
pub struct Screen<'a> {
    win: &'a Windows,
    /// Window means of each input primitive without a searched parameter.
    means: Vec<Option<Vec<f64>>>,
    /// ... and of those with one, at each point of its grid.
    searched: HashMap<(usize, u64), Vec<f64>>,
    /// The windows' mid times as a run of one row a window (for the
    /// shapes of time).
    times: Inputs,
}

/// A formula's value per row of `inp` with `params`.
fn eval(text: &str, params: BTreeMap<String, f64>, inp: &Inputs) -> Option<Vec<f64>> {
    Term::new(text, params).ok()?.evaluate(inp).ok()
}

impl<'a> Screen<'a> {
    pub fn new(inp: &Inputs, win: &'a Windows, prims: &[Prim]) -> Self {
        let mut means = vec![None; prims.len()];
        let mut searched = HashMap::new();
        for (i, p) in prims.iter().enumerate() {
            if p.kind != PrimKind::Input {
                continue;
            }
            match &p.searched {
                None => means[i] = eval(&p.text, BTreeMap::new(), inp).map(|x| win.mean(&x)),
                Some(s) => {
                    for &v in &s.grid {
                        let params = BTreeMap::from([(s.name.to_string(), v)]);
                        if let Some(x) = eval(&p.text, params, inp) {
                            searched.insert((i, v.to_bits()), win.mean(&x));
                        }
                    }
                }
            }
        }
        let n = win.len();
        Self {
            win,
            means,
            searched,
            times: Inputs::new(win.t.clone(), vec![0.0; n], None, None, None, None),
        }
    }

    /// The windows screened over.
    pub fn windows(&self) -> &Windows {
        self.win
    }

    /// A candidate's columns (window level, one per part) at a point of
    /// its search; None where a factor cannot be evaluated.
    pub fn columns(&self, prims: &[Prim], c: &Candidate, point: &[f64]) -> Option<Vec<Vec<f64>>> {
        let params = c.params_at(point);
        if c.recipe.is_empty() {
            // An event searched in two parameters: a shape of time.
            return c
                .parts
                .iter()
                .map(|p| eval(&p.shape, params.clone(), &self.times))
                .collect();
        }
        let (common, periodic) = self.product(prims, &c.recipe, &params)?;
        let mut cols = match periodic {
            Some(arg) => vec![
                common.iter().zip(&arg).map(|(a, x)| a * x.sin()).collect(),
                common.iter().zip(&arg).map(|(a, x)| a * x.cos()).collect(),
            ],
            None => vec![common],
        };
        for r in &c.also {
            cols.push(self.product(prims, r, &params)?.0);
        }
        Some(cols)
    }

    /// A recipe's product of window means at `params`, with the argument
    /// of its periodic factor apart (its sine and cosine are two parts).
    fn product(
        &self,
        prims: &[Prim],
        recipe: &[Factor],
        params: &BTreeMap<String, f64>,
    ) -> Option<(Vec<f64>, Option<Vec<f64>>)> {
        let mut common = vec![1.0; self.win.len()];
        let mut periodic: Option<Vec<f64>> = None;
        for f in recipe {
            let p = &prims[f.prim];
            let x: Vec<f64> = match (&p.kind, &p.searched) {
                (PrimKind::Input, None) => self.means[f.prim].clone()?,
                (PrimKind::Input, Some(s)) => {
                    let v = params.get(s.name)?;
                    self.searched.get(&(f.prim, v.to_bits()))?.clone()
                }
                (PrimKind::Periodic, _) => {
                    periodic = Some(eval(&p.text, params.clone(), &self.times)?);
                    continue;
                }
                _ => eval(&p.text, params.clone(), &self.times)?,
            };
            for (a, b) in common.iter_mut().zip(&x) {
                *a *= b.powi(f.power);
            }
        }
        Some((common, periodic))
    }
}
