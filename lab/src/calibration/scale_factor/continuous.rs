//! The fit of a continuous-rotation run (docs/fog.md): s continuous
//! piecewise linear in T with K knees (`s0 + s1 (T - 20) + sum c_k max(0,
//! T - T_k)`); b is `b0 + b1 (T - 20)` where the run has both rate signs
//! (or rest), else it cannot be told from s and is left in it. The knee
//! temperatures and the lag are found by search (the rest is linear), K =
//! 0..=3 is chosen by BIC, each knee and the lag get a profile-likelihood
//! 95 % interval (intervals.rs). The fit works on 10 s bin means, weighted
//! by their sample counts; a residual lag-1 correlation inflates the
//! variance (and the BIC's likelihood) by (1 + rho)/(1 - rho).

use super::bins::bin;
use super::continuous_model::{refine, Candidate, Model, KNEE_MARGIN_C, MAX_KNEES};
use super::input::{rotating, SfInput, MIN_RATE_DPS};
use super::intervals::{knee_intervals, lag_interval};
use super::residual::{window_rms_ppm, RESIDUAL_WINDOW_S};
use super::result::{BiasModel, Est, FitMethod, Interval, Segment, SfFit, SfFitError};
use crate::numerics::lsq::LsFit;
use crate::numerics::search::CHI2_1_95;
use gyro_coeffs::fog_scale_factor::ScaleFactorTable;

/// Whether the run turns both ways (or rests as well as turns): only then
/// can the bias be told from the scale factor.
fn bias_separable(w: &[f64]) -> bool {
    let signs: std::collections::BTreeSet<i8> = w
        .iter()
        .map(|&w| {
            if w >= MIN_RATE_DPS {
                1
            } else if w <= -MIN_RATE_DPS {
                -1
            } else {
                0
            }
        })
        .collect();
    signs.len() >= 2
}

/// The models with 0, 1, ... `MAX_KNEES` knees: each adds to the one before
/// the knee that lowers the residual most (a 0.5 degC grid over `lo..hi`,
/// away from the ends and the other knees), then refines every knee and the
/// lag.
fn knee_models(m: &Model, no_knee: Candidate, lo: f64, hi: f64) -> Vec<Candidate> {
    let mut models = vec![no_knee];
    for _ in 1..=MAX_KNEES {
        let prev = models[models.len() - 1].clone();
        let mut best: Option<(f64, f64)> = None;
        let mut t = lo + KNEE_MARGIN_C;
        while t <= hi - KNEE_MARGIN_C {
            if prev.knees.iter().all(|k| (k - t).abs() >= KNEE_MARGIN_C) {
                let mut k = prev.knees.clone();
                k.push(t);
                k.sort_by(f64::total_cmp);
                let s = m.sse(prev.lag, &k);
                if best.is_none_or(|b| s < b.1) {
                    best = Some((t, s));
                }
            }
            t += 0.5;
        }
        let Some((t, _)) = best else { break };
        let mut c = prev.clone();
        c.knees.push(t);
        c.knees.sort_by(f64::total_cmp);
        refine(m, &mut c, lo, hi);
        models.push(c);
    }
    models
}

/// The variance inflation for correlated noise, (1 + rho)/(1 - rho), from
/// the lag-1 correlation of `c`'s weighted residual within constant-rate
/// stretches (rho held to 0..0.9).
fn noise_inflation(m: &Model, c: &Candidate) -> Result<f64, SfFitError> {
    let nb = m.b.w.len();
    let rf = m.fit(c.lag, &c.knees).ok_or(SfFitError::Singular)?;
    let z: Vec<f64> = (0..nb).map(|i| rf.resid[i] * m.b.n[i].sqrt()).collect();
    let (mut num, mut den) = (0.0, 0.0);
    for i in 0..nb {
        den += z[i] * z[i];
        if i > 0 && m.b.group[i] == m.b.group[i - 1] {
            num += z[i] * z[i - 1];
        }
    }
    let rho = if den > 0.0 {
        (num / den).clamp(0.0, 0.9)
    } else {
        0.0
    };
    Ok((1.0 + rho) / (1.0 - rho))
}

/// BIC of each model, the likelihood divided by the inflation `phi`.
fn bic(m: &Model, models: &[Candidate], phi: f64) -> Vec<f64> {
    let n = m.b.w.len() as f64;
    models
        .iter()
        .map(|c| {
            n * (c.sse / n).ln() / phi + (m.params(c.knees.len()) + c.knees.len()) as f64 * n.ln()
        })
        .collect()
}

/// The fitted curves at the chosen knees: the scale-factor error s(T)
/// (relative) and the bias b(T) (deg/s), with the coefficients' covariance
/// scaled by `var`.
struct Curves<'a> {
    f: LsFit,
    knees: &'a [f64],
    with_bias: bool,
    var: f64,
}

impl Curves<'_> {
    /// The row `a` with s(T) = a . coef.
    fn a_sf(&self, t: f64) -> Vec<f64> {
        let mut a = vec![0.0; self.f.coef.len()];
        a[0] = 1.0;
        a[1] = t - 20.0;
        for (j, k) in self.knees.iter().enumerate() {
            a[2 + j] = (t - k).max(0.0);
        }
        a
    }

    fn dot(&self, a: &[f64]) -> f64 {
        a.iter().zip(&self.f.coef).map(|(x, y)| x * y).sum::<f64>()
    }

    fn sf(&self, t: f64) -> f64 {
        self.dot(&self.a_sf(t))
    }

    fn bias(&self, t: f64) -> f64 {
        let nk = self.knees.len();
        if self.with_bias {
            self.f.coef[2 + nk] + self.f.coef[3 + nk] * (t - 20.0)
        } else {
            0.0
        }
    }

    fn bias_model(&self) -> Option<BiasModel> {
        let (f, nk, v) = (&self.f, self.knees.len(), self.var);
        self.with_bias.then(|| BiasModel {
            at_20c_dph: Est {
                value: f.coef[2 + nk] * 3600.0,
                se: f.se(2 + nk, v) * 3600.0,
            },
            slope_dph_per_c: Est {
                value: f.coef[3 + nk] * 3600.0,
                se: f.se(3 + nk, v) * 3600.0,
            },
        })
    }

    /// The firmware's table: s and b at the nodes, the sensor lag.
    fn table(&self, nodes: &[f64], lag: f64) -> ScaleFactorTable {
        let sf: Vec<f64> = nodes.iter().map(|&t| self.sf(t) * 1e6).collect();
        let bias: Vec<f64> = nodes.iter().map(|&t| self.bias(t) * 3600.0).collect();
        ScaleFactorTable::from_nodes(nodes, &sf, &bias, lag)
    }

    /// The residual over 60 s means of the rotating rows, ppm.
    fn residual_ppm(&self, inp: &SfInput, lag: f64) -> Est {
        let err: Vec<f64> = (0..inp.t.len())
            .map(|k| {
                let tc = inp.ts[k] + lag * inp.d[k];
                inp.y[k] - inp.w[k] - inp.w[k] * self.sf(tc) - self.bias(tc)
            })
            .collect();
        let (rms, rms_se, _) = window_rms_ppm(&inp.t, &inp.w, &err, RESIDUAL_WINDOW_S);
        Est {
            value: rms,
            se: rms_se,
        }
    }
}

/// Segments between consecutive nodes of a piecewise-linear s(T) given as
/// `s_at(t) = (value, a)` with value = a . coef; `se(a)` the standard error
/// of a . coef. The slope of a segment is the difference of s over it.
fn segments_from(
    nodes: &[f64],
    s_at: impl Fn(f64) -> (f64, Vec<f64>),
    se: impl Fn(&[f64]) -> f64,
) -> Vec<Segment> {
    nodes
        .windows(2)
        .map(|w| {
            let (s0, a0) = s_at(w[0]);
            let (s1, a1) = s_at(w[1]);
            let h = w[1] - w[0];
            let k_t = (s1 - s0) / h;
            let a_t: Vec<f64> = a0.iter().zip(&a1).map(|(x, y)| (y - x) / h).collect();
            // k0 = 1 + s(T0) - k_t*T0.
            let a_k0: Vec<f64> = a0.iter().zip(&a_t).map(|(x, y)| x - y * w[0]).collect();
            let k0m1 = s0 - k_t * w[0];
            Segment {
                from_c: w[0],
                to_c: w[1],
                k0: 1.0 + k0m1,
                k_t,
                k0_se: se(&a_k0),
                k_t_se: se(&a_t),
                k0_ppm: k0m1 * 1e6,
                k_t_ppm_per_c: k_t * 1e6,
            }
        })
        .collect()
}

fn notes(with_bias: bool) -> Vec<String> {
    let mut notes = vec![];
    if !with_bias {
        notes.push(
            "one rate sign: the bias cannot be told from the scale factor and is left in it \
             (a bias error Omega0 on rate w reads as Omega0/w of scale factor)"
                .to_owned(),
        );
    }
    notes.push(
        "asymmetry and nonlinearity need several rate magnitudes: not measurable on a one-rate \
         run; with both signs at one magnitude |w| the bias carries |w|*asymmetry/2"
            .into(),
    );
    notes
}

/// The fit of a continuous-rotation run.
pub fn fit_continuous(inp: &SfInput) -> Result<SfFit, SfFitError> {
    let with_bias = bias_separable(&inp.w);
    let rows: Vec<usize> = if with_bias {
        (0..inp.t.len()).collect()
    } else {
        rotating(&inp.w)
    };
    let m = Model {
        b: bin(inp, &rows),
        with_bias,
    };
    // Calibrated range: the coil temperatures of the rotating bins, at the
    // lag fitted without knees (refined below).
    let (lag0, sse0) = m.best_lag(&[], None);
    let (lo, hi) = m.coil_range(lag0);
    let no_knee = Candidate {
        knees: vec![],
        lag: lag0,
        sse: sse0,
    };
    let models = knee_models(&m, no_knee, lo, hi);
    let phi = noise_inflation(&m, &models[models.len() - 1])?;
    let bic = bic(&m, &models, phi);
    let best_k = (0..bic.len())
        .min_by(|&a, &b| bic[a].total_cmp(&bic[b]))
        .unwrap_or(0);
    let c = models[best_k].clone();
    let n = m.b.w.len() as f64;
    let p = m.params(c.knees.len()) + c.knees.len() + 1;
    let var = c.sse / (n - p as f64).max(1.0);
    let thr = CHI2_1_95 * phi * var;
    let (lo, hi) = m.coil_range(c.lag);
    let knees = knee_intervals(inp, &m, &c, thr, (lo, hi));
    let (lag_lo, lag_hi) = lag_interval(&m, &c, thr, (lo, hi));

    let curves = Curves {
        f: m.fit(c.lag, &c.knees).ok_or(SfFitError::Singular)?,
        knees: &c.knees,
        with_bias,
        var: phi * var,
    };
    let mut nodes = vec![lo];
    nodes.extend(c.knees.iter().copied());
    nodes.push(hi);
    let segments = segments_from(
        &nodes,
        |t| {
            let a = curves.a_sf(t);
            (curves.dot(&a), a)
        },
        |a| curves.f.se_of(a, curves.var),
    );
    Ok(SfFit {
        method: FitMethod::Continuous,
        knees,
        segments,
        table: curves.table(&nodes, c.lag),
        sensor_lag_s: Some(Interval {
            value: c.lag,
            lo: lag_lo,
            hi: lag_hi,
        }),
        bias: curves.bias_model(),
        asymmetry_ppm: None,
        nonlinearity_ppm: None,
        bic,
        noise_inflation: phi,
        residual_ppm: curves.residual_ppm(inp, c.lag),
        range_c: [lo, hi],
        rows_used: rows.len(),
        notes: notes(with_bias),
    })
}
