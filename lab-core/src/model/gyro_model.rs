//! A behavioural gyro model: the gyro kind, nominal parameters, and the named
//! effects it contains with their parameters (effects.rs holds every
//! formula). Evaluated on a run's inputs it is "the simulation": output =
//! reference rate + the sum of the effects. Its file is file.rs.

use super::effects::Effect;
use super::gyro_kind::GyroKind;
use super::inputs::Inputs;
use super::term::{EvalError, Term};
use crate::data::run_file::Column;
use std::collections::BTreeMap;

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
    /// Terms outside the library (`name = "term"`), after the effects.
    pub terms: Vec<Term>,
}

impl Model {
    /// The ideal gyro: output = reference rate.
    pub fn ideal(gyro: GyroKind) -> Self {
        Self {
            gyro,
            nominal: toml::Table::new(),
            effects: vec![],
            terms: vec![],
        }
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

    /// The first term that cannot be evaluated on this run (its index and
    /// why): the commands refuse such a model at the formula's place
    /// before they evaluate it.
    pub fn check_terms(&self, inp: &Inputs) -> Result<(), (usize, EvalError)> {
        for (i, t) in self.terms.iter().enumerate() {
            t.evaluate(inp).map_err(|e| (i, e))?;
        }
        Ok(())
    }

    /// The simulated output, deg/s: reference rate plus every effect and
    /// term. A term that cannot be evaluated on the run ([`Self::check_terms`])
    /// makes the output NaN, never a silent zero.
    pub fn evaluate(&self, inp: &Inputs) -> Vec<f64> {
        let mut y = inp.w.clone();
        for e in &self.effects {
            for (o, c) in y.iter_mut().zip(e.effect.contribution(inp, &e.params)) {
                *o += c;
            }
        }
        for t in &self.terms {
            match t.evaluate(inp) {
                Ok(v) => y.iter_mut().zip(v).for_each(|(o, c)| *o += c / 3600.0),
                Err(_) => y.iter_mut().for_each(|o| *o = f64::NAN),
            }
        }
        y
    }
}
