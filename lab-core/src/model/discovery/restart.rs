//! A start without the warm-up. The selection is greedy, and its noise
//! model is fitted to what the first names leave: a warm-up taken first
//! on a record whose temperature also moves (a chamber sweep starting
//! hot) fits the first fall of a bias that follows the temperature, the
//! noise model then reads the rest as a random walk, and whitened by that
//! walk the temperature's terms no longer pay. A measured MEMS sweep's
//! first half was left at 252 deg/h that way; started without the
//! warm-up, the temperature's terms leave 86.
//!
//! So where the first library run names a warm-up and the discovery
//! leaves something unexplained, it is run again with the warm-up out of
//! the library, and the start kept is the one whose model leaves the
//! smaller gap by more than the criterion asks (the names' threshold of
//! 10, plus ln n per parameter it adds, as the pruning of names asks).
//! A warm-up the record holds is kept: no start without it closes as
//! much.

use super::result::{Discovery, Options};
use super::select::THRESHOLD as NAME_THRESHOLD;
use crate::model::effects::Effect;
use crate::model::gyro_model::Model;

/// Free parameters of the model written beyond `given`'s: its effects'
/// and its terms'.
fn parameters(given: &Model, d: &Discovery) -> usize {
    let m = &d.model_after;
    let effects: usize = m.effects.iter().map(|e| e.params.len()).sum();
    let terms: usize = m.terms[given.terms.len().min(m.terms.len())..]
        .iter()
        .map(|t| t.params.len())
        .sum();
    effects + terms
}

/// Whether `d`'s model names a warm-up `given` did not hold.
pub fn names_warm_up(given: &Model, d: &Discovery) -> bool {
    d.found.iter().any(|e| e.effect == Effect::WarmUp)
        && !given.effects.iter().any(|e| e.effect == Effect::WarmUp)
}

/// Whether a start that named a warm-up is worth a second: only where
/// it left something unexplained (a start that explains the record to
/// its noise has nothing a second could close).
pub fn worth_another(d: &Discovery) -> bool {
    d.unexplained.is_some()
}

/// The options of the start without the warm-up.
pub fn without_warm_up(opts: &Options) -> Options {
    opts.excluding(Effect::WarmUp)
}

/// The better of two starts: `main` (the warm-up named) and `alt` (the
/// library without it); the one not kept is said in `dropped`.
pub fn better(given: &Model, main: Discovery, alt: Discovery) -> Discovery {
    let n1 = main.gap_windows.len().max(1) as f64;
    // The incumbent's floor, as `prune` judges against.
    let floor2 = main.noise_floor_dph.powi(2).max(1e-300);
    // What the start without the warm-up saves, in noise variances, and
    // what its extra parameters ask.
    let saves = n1 * (main.gap_after_dph.powi(2) - alt.gap_after_dph.powi(2)) / floor2;
    let extra = parameters(given, &alt) as f64 - parameters(given, &main) as f64;
    let asks = NAME_THRESHOLD + extra.max(0.0) * n1.ln();
    if saves.is_finite() && saves > asks {
        let mut alt = alt;
        let fitted = main
            .found
            .iter()
            .find(|e| e.effect == Effect::WarmUp)
            .map(|e| {
                e.params
                    .iter()
                    .map(|p| format!("{} {}", p.0, crate::report::text::sig(p.1)))
                    .collect::<Vec<_>>()
                    .join(", ")
            })
            .unwrap_or_default();
        alt.dropped.push(format!(
            "warm_up ({fitted}: started with it, the discovery left {:.4} deg/h; without it {:.4}: {saves:.1} noise variances saved, more than the {asks:.1} its extra parameters ask)",
            main.gap_after_dph, alt.gap_after_dph
        ));
        alt
    } else {
        main
    }
}
