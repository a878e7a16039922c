//! The residual of the model written averages to zero over its record.
//! The constant every fit carries is estimated by generalised least
//! squares under the residual's noise; where that noise holds a random
//! walk or a flicker, the estimate is the level the noise wanders about
//! at the record's ends, not the record's mean, and a model whose
//! residual has a mean of -106 deg/h over its own record (issue 38's
//! measured hub) is not one a user can trust. So the model's constant is
//! moved to the mean of what it leaves (its interval widened to hold
//! both), or, where the model carries none and the mean stands out of
//! its noise, one is added; the residual's mean and its standard
//! deviation (from the stationary part of the noise) are reported.

use super::estimates::Estimate;
use super::noise_floor::gap;
use super::result::{Carried, Discovery, Run};
use crate::model::effects::Effect;
use crate::model::gyro_model::ModelEffect;

/// The bias parameter's name (effects.rs's for `Effect::Bias`).
fn bias_param() -> &'static str {
    Effect::Bias.linear_params()[0]
}

fn shift(e: &mut Estimate, by: f64) {
    for p in e.params.iter_mut().filter(|p| p.0 == bias_param()) {
        p.1 += by;
        p.2 = p.2.min(p.2 + by);
        p.3 = p.3.max(p.3 + by);
    }
}

/// Centres `d`'s model on `run`: its residual after averages to zero
/// (`window_s`: the gap's averaging).
pub fn centre(run: &Run, mut d: Discovery, window_s: f64) -> Discovery {
    let w = d.gap_windows.mean(&d.residual_after);
    if w.is_empty() {
        return d;
    }
    let mean = w.iter().sum::<f64>() / w.len() as f64;
    let t = &run.inputs.t;
    let span = t.last().copied().unwrap_or(0.0) - t.first().copied().unwrap_or(0.0);
    let sd = d.noise.sd_of_mean(span.max(window_s), window_s);
    let by = mean * 3600.0;
    let bias = d
        .model_after
        .effects
        .iter()
        .rposition(|e| e.effect == Effect::Bias);
    let moved = match bias {
        Some(i) => {
            *d.model_after.effects[i]
                .params
                .entry(bias_param().to_owned())
                .or_insert(0.0) += by;
            let est = d
                .found
                .iter_mut()
                .chain(d.carried.iter_mut().map(|c| &mut c.estimate))
                .rfind(|e| e.effect == Effect::Bias);
            if let Some(e) = est {
                shift(e, by);
            }
            true
        }
        None if mean.abs() > 2.0 * sd => {
            let mut params = std::collections::BTreeMap::new();
            params.insert(bias_param().to_owned(), by);
            d.model_after.effects.push(ModelEffect {
                effect: Effect::Bias,
                params,
            });
            let h = 1.96 * sd * 3600.0;
            d.carried.push(Carried {
                estimate: Estimate {
                    effect: Effect::Bias,
                    params: vec![(bias_param(), by, by - h, by + h)],
                    delta_bic: 0.0,
                    explained_share: 0.0,
                },
                why: "the constant the residual's mean asks for (the fit carried none): the model's residual averages to zero over the record".into(),
            });
            true
        }
        None => false,
    };
    if moved {
        d.residual_after.iter_mut().for_each(|r| *r -= mean);
        d.gap_after_dph = gap(&d.gap_windows, &d.residual_after);
        // What stands above the noise is part of the gap, centred too.
        if let Some(u) = d.unexplained.as_mut() {
            u.excess_dph = u.excess_dph.min(d.gap_after_dph);
        }
        // Centred twice (each library run the search compared, then the
        // result): the moves add.
        d.centred_by_dph += by;
    }
    let after = d.gap_windows.mean(&d.residual_after);
    d.residual_mean_dph = after.iter().sum::<f64>() / after.len() as f64 * 3600.0;
    d.residual_mean_sd_dph = sd * 3600.0;
    d
}
