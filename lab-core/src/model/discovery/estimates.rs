//! The parameters of the effects found and carried, from the final joint
//! fit (the nuisance terms in it, so that what the library does not
//! explain drags no effect), with 95 % intervals that account for the
//! residual's coloured noise: generalised least squares on the whitened
//! problem (design.rs), its variance scaled by the fit's own whitened
//! residual and by the correlation that residual still holds (design.rs's
//! batch-means inflation). The covariance is the Gauss-Newton one of all
//! parameters at once (the non-linear ones' derivative columns beside the
//! linear columns), so a linear parameter's interval includes what the
//! uncertain knee, time constant or lock-in rate it goes with adds; a
//! non-linear parameter's interval is the wider of that and its profile.

use super::design::{inflation, Design};
use super::select::{columns, params_of};
use super::terms::{without, Kind, Term};
use crate::model::effects::Effect;
use crate::numerics::lsq::wls;
use crate::numerics::stats::t_975;

/// An effect's parameters with 95 % intervals: (name, value, lo, hi).
#[derive(Clone, Debug)]
pub struct Estimate {
    pub effect: Effect,
    pub params: Vec<(&'static str, f64, f64, f64)>,
    /// The criterion's change were it taken out of the final fit
    /// (negative: it pays).
    pub delta_bic: f64,
    /// Share of the residual's variance (1 s means) it explains.
    pub explained_share: f64,
}

/// The final joint fit: every term's estimate (None for terms without a
/// name: shapes, steps), its part of the residual in window means (deg/s),
/// and the variance scale of the whitened residual.
pub struct Final {
    pub estimates: Vec<Option<Estimate>>,
    pub parts: Vec<Vec<f64>>,
    pub scale: f64,
}

/// Estimates of every term of `terms` (the constant first) from their joint
/// fit.
pub fn estimate(d: &Design, terms: &[Term]) -> Option<Final> {
    let f = d.fit(terms)?;
    let n = d.n();
    let p: usize = terms.iter().map(|t| t.kind.dof()).sum();
    let phi = d.phi.max(inflation(&f.resid, &d.wh.keep));
    // Residual degrees of freedom: Student's t for the variance the
    // residual measures (none left: no interval at all).
    let dof = n - p as f64;
    let scale = (f.sse / dof.max(1.0) * phi).max(d.min_scale);
    let q = t_975(dof);
    let cov = jacobian_cov(d, terms, &f.coef);
    let parts = d.parts(terms, &f.coef);
    let w = &d.win.count;
    let ss = |x: &[f64]| -> f64 {
        x.iter()
            .zip(w)
            .zip(&d.wh.keep)
            .filter(|(_, k)| **k)
            .map(|((v, c), _)| c * v * v)
            .sum()
    };
    let sum_parts: Vec<f64> = (0..d.r.len())
        .map(|k| parts.iter().map(|p| p[k]).sum::<f64>())
        .collect();
    let r_full: Vec<f64> = d.r.iter().zip(&sum_parts).map(|(a, b)| a - b).collect();
    let (ss0, ss_full) = (ss(&d.r), ss(&r_full));
    let c_full = d.criterion(f.sse, p);
    let mut out = vec![];
    let mut col = 0;
    for (j, t) in terms.iter().enumerate() {
        let ncol = columns(t.kind);
        let effect = match t.kind {
            Kind::Constant => Some(Effect::Bias),
            Kind::Effect(e) => Some(e),
            _ => None,
        };
        let Some(effect) = effect else {
            out.push(None);
            col += ncol;
            continue;
        };
        let values = params_of(terms, &f, j);
        let mut params = vec![];
        for (i, (name, v)) in values.iter().enumerate() {
            if i < ncol {
                let se = cov
                    .as_ref()
                    .map_or(f64::NAN, |c| (c.0[(col + i, col + i)] * scale).sqrt());
                params.push((*name, *v, v - q * se, v + q * se));
            } else {
                let (lo, hi) = profile(d, terms, j, f.sse, q * q * scale);
                // The Gauss-Newton interval, in the search's variable.
                let wald = cov.as_ref().and_then(|c| {
                    let k = c.1.iter().position(|&x| x == j)?;
                    let se = (c.0[(c.2 + k, c.2 + k)] * scale).sqrt();
                    let log = t.kind.effect().is_some_and(|e| e.search_log());
                    Some(if log {
                        ((v.ln() - q * se).exp(), (v.ln() + q * se).exp())
                    } else {
                        (v - q * se, v + q * se)
                    })
                });
                let (lo, hi) = match wald {
                    _ if q.is_nan() => (f64::NAN, f64::NAN),
                    Some((a, b)) if a.is_finite() && b.is_finite() => (lo.min(a), hi.max(b)),
                    _ => (lo, hi),
                };
                params.push((*name, *v, lo, hi));
            }
        }
        col += ncol;
        let rest = without(terms, j);
        let delta_bic = c_full - d.criterion_of(&rest);
        let with_back: Vec<f64> = r_full.iter().zip(&parts[j]).map(|(a, b)| a + b).collect();
        let share = if ss0 > 0.0 {
            ((ss(&with_back) - ss_full) / ss0).clamp(0.0, 1.0)
        } else {
            0.0
        };
        out.push(Some(Estimate {
            effect,
            params,
            delta_bic,
            explained_share: share,
        }));
    }
    Some(Final {
        estimates: out,
        parts,
        scale,
    })
}

/// Widens `fin`'s intervals to hold, about its own values, those of
/// `other` (the same terms fitted under another noise model: one whose
/// slow noise the record cannot exclude) about its values: each side the
/// larger distance.
pub fn widen(fin: &mut Final, other: &Final) {
    for (a, b) in fin.estimates.iter_mut().zip(&other.estimates) {
        let (Some(a), Some(b)) = (a, b) else {
            continue;
        };
        for (p, q) in a.params.iter_mut().zip(&b.params) {
            let (below, above) = (q.1 - q.2, q.3 - q.1);
            if below.is_finite() && above.is_finite() {
                p.2 = p.2.min(p.1 - below);
                p.3 = p.3.max(p.1 + above);
            }
        }
    }
}

/// The unscaled covariance of every linear coefficient (first, in the
/// fit's column order) and of the non-linear parameters (after, for the
/// terms listed, in ln x where the search is logarithmic): (cov, terms with
/// a non-linear parameter, index of the first of them).
fn jacobian_cov(
    d: &Design,
    terms: &[Term],
    coef: &[f64],
) -> Option<(nalgebra::DMatrix<f64>, Vec<usize>, usize)> {
    let (mut cols, y) = d.whitened_problem(terms);
    let nlin = cols.len();
    let mut which = vec![];
    let mut col = 0;
    for (j, t) in terms.iter().enumerate() {
        let nc = columns(t.kind);
        if let Kind::Effect(e) = t.kind {
            if e.nonlinear_param().is_some() {
                let own = &coef[col.min(coef.len())..(col + nc).min(coef.len())];
                let log = e.search_log();
                let at: fn(f64, f64) -> f64 = if log {
                    |x, s| x * s.exp()
                } else {
                    |x, s| x + s
                };
                let h = if log { 1e-4 } else { 1e-3 * t.x.abs().max(1.0) };
                let mut tp = *t;
                tp.x = at(t.x, h);
                let up = d.whitened_part(&tp, own);
                tp.x = at(t.x, -h);
                let dn = d.whitened_part(&tp, own);
                let g: Vec<f64> = up
                    .iter()
                    .zip(&dn)
                    .map(|(a, b)| (a - b) / (2.0 * h))
                    .collect();
                if g.iter().any(|v| *v != 0.0) {
                    cols.push(g);
                    which.push(j);
                }
            }
        }
        col += nc;
    }
    if cols.is_empty() {
        return None;
    }
    let ls = wls(&cols, &y, None)?;
    Some((ls.cov_unscaled, which, nlin))
}

/// Profile-likelihood 95 % interval of `terms[j]`'s non-linear parameter:
/// scanned each way from the estimate until the whitened sum of squares
/// rises by chi-square(1, 95 %) times the variance scale, the crossing
/// interpolated in the square root of the rise (linear for a quadratic
/// profile); the step halved until the first one stays under it. `thr` is
/// that rise: the squared t quantile times the variance scale.
fn profile(d: &Design, terms: &[Term], j: usize, sse: f64, thr: f64) -> (f64, f64) {
    let Kind::Effect(e) = terms[j].kind else {
        return (f64::NAN, f64::NAN);
    };
    let log = e.search_log();
    let x = terms[j].x;
    let prof = |u: f64| {
        let mut ts = terms.to_vec();
        ts[j].x = if log { u.exp() } else { u };
        d.sse(&ts) - sse
    };
    let (u0, bound) = if log { (x.ln(), 5.0) } else { (x, 30.0) };
    let side = |dir: f64| -> f64 {
        let mut step = if log { 0.02 } else { 0.1 };
        for _ in 0..40 {
            if prof(u0 + dir * step) < thr {
                break;
            }
            step *= 0.5;
        }
        let (mut u, mut prev) = (u0, 0.0f64);
        let mut k = 0;
        while (u - u0).abs() < bound && k < 400 {
            let nu = u + dir * step;
            let dv = prof(nu);
            if dv >= thr {
                let (a, b, c) = (prev.max(0.0).sqrt(), dv.sqrt(), thr.sqrt());
                let f = if b > a {
                    ((c - a) / (b - a)).clamp(0.0, 1.0)
                } else {
                    1.0
                };
                return u + dir * step * f;
            }
            u = nu;
            prev = dv;
            k += 1;
            if k % 20 == 0 {
                step *= 2.0;
            }
        }
        u0 + dir * bound
    };
    let (lo, hi) = (side(-1.0), side(1.0));
    if log {
        (lo.exp(), hi.exp())
    } else {
        (lo, hi)
    }
}
