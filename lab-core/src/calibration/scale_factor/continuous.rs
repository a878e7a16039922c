//! The fit of a continuous-rotation run (docs/fog.md): s a polynomial of
//! degree D = 1..=3 in T with K = 0..=3 knees (`sum_d s_d (T - 20)^d +
//! sum c_k max(0, T - T_k)`); b is `b0 + b1 (T - 20)` where the run has
//! both rate signs (or rest), else it cannot be told from s and is left in
//! it. The knee temperatures and the lag are found by search (the rest is
//! linear); one criterion (BIC) chooses among all (D, K): the families of
//! families.rs; each knee and the lag get a profile-likelihood 95 %
//! interval (intervals.rs). The fit works on 10 s bin means, weighted by
//! their sample counts; a residual lag-1 correlation inflates the variance
//! (and the BIC's likelihood) by (1 + rho)/(1 - rho). The chosen model is
//! tabulated for the firmware (tabulate.rs).

use super::bins::bin;
use super::continuous_model::{
    refine, Candidate, Model, KNEE_MARGIN_C, MAX_DEGREE, MAX_KNEES, T_REF_C,
};
use super::families::{choose, Family, Scored};
use super::input::{rotating, SfInput, MIN_RATE_DPS};
use super::intervals::{knee_intervals, lag_interval};
use super::residual::{noise_floor_ppm, window_rms_ppm, RESIDUAL_WINDOW_S};
use super::result::{
    BiasModel, Est, FitMethod, Interval, Polynomial, Segment, SfCurve, SfFit, SfFitError,
};
use super::tabulate;
use super::warnings;
use crate::numerics::lsq::LsFit;
use crate::numerics::search::CHI2_1_95;

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

/// The models of `no_knee`'s degree with 0, 1, ... `MAX_KNEES` knees: each
/// adds to the one before the knee that lowers the residual most (a
/// 0.5 degC grid over `lo..hi`, away from the ends and the other knees),
/// then refines every knee and the lag.
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
                let s = m.sse(prev.lag, prev.degree, &k);
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
    let rf = m
        .fit(c.lag, c.degree, &c.knees)
        .ok_or(SfFitError::Singular)?;
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

/// BIC of a model, the likelihood divided by the inflation `phi`; the
/// knee temperatures count as parameters.
fn bic(m: &Model, c: &Candidate, phi: f64) -> f64 {
    let n = m.b.w.len() as f64;
    let k = c.knees.len();
    n * (c.sse / n).ln() / phi + (m.params(c.degree, k) + k) as f64 * n.ln()
}

/// The fitted curves of the chosen model: the scale-factor error s(T)
/// (relative) and the bias b(T) (deg/s), with the coefficients' covariance
/// scaled by `var`.
struct Curves<'a> {
    f: LsFit,
    degree: usize,
    knees: &'a [f64],
    with_bias: bool,
    var: f64,
}

impl Curves<'_> {
    /// The row `a` with s(T) = a . coef.
    fn a_sf(&self, t: f64) -> Vec<f64> {
        let mut a = vec![0.0; self.f.coef.len()];
        let x = t - T_REF_C;
        for (p, v) in a.iter_mut().take(self.degree + 1).enumerate() {
            *v = x.powi(p as i32);
        }
        for (j, k) in self.knees.iter().enumerate() {
            a[self.degree + 1 + j] = (t - k).max(0.0);
        }
        a
    }

    fn dot(&self, a: &[f64]) -> f64 {
        a.iter().zip(&self.f.coef).map(|(x, y)| x * y).sum::<f64>()
    }

    fn sf(&self, t: f64) -> f64 {
        self.dot(&self.a_sf(t))
    }

    /// Index of the bias's first coefficient.
    fn bias_at(&self) -> usize {
        self.degree + 1 + self.knees.len()
    }

    fn bias(&self, t: f64) -> f64 {
        let i = self.bias_at();
        if self.with_bias {
            self.f.coef[i] + self.f.coef[i + 1] * (t - T_REF_C)
        } else {
            0.0
        }
    }

    fn bias_model(&self) -> Option<BiasModel> {
        let (f, i, v) = (&self.f, self.bias_at(), self.var);
        self.with_bias.then(|| BiasModel {
            at_20c_dph: Est {
                value: f.coef[i] * 3600.0,
                se: f.se(i, v) * 3600.0,
            },
            slope_dph_per_c: Est {
                value: f.coef[i + 1] * 3600.0,
                se: f.se(i + 1, v) * 3600.0,
            },
        })
    }

    /// The polynomial part in ppm/degC^k with standard errors.
    fn polynomial(&self) -> Polynomial {
        Polynomial {
            t_ref_c: T_REF_C,
            coef_ppm: (0..=self.degree)
                .map(|k| Est {
                    value: self.f.coef[k] * 1e6,
                    se: self.f.se(k, self.var) * 1e6,
                })
                .collect(),
        }
    }

    fn curve(&self) -> SfCurve {
        let i = self.bias_at();
        SfCurve {
            degree: self.degree,
            knees: self.knees.to_vec(),
            t_ref_c: T_REF_C,
            coef: self.f.coef[..i].to_vec(),
            bias: self.with_bias.then(|| (self.f.coef[i], self.f.coef[i + 1])),
        }
    }

    /// The fit's error per row of the run (deg/s): y - w - w s(T) - b(T)
    /// at the coil temperature for `lag`.
    fn row_error(&self, inp: &SfInput, lag: f64) -> Vec<f64> {
        (0..inp.t.len())
            .map(|k| {
                let tc = inp.ts[k] + lag * inp.d[k];
                inp.y[k] - inp.w[k] - inp.w[k] * self.sf(tc) - self.bias(tc)
            })
            .collect()
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

/// Every model of the grid: degrees 1..=`MAX_DEGREE`, each with 0..=
/// `MAX_KNEES` knees.
fn all_models(m: &Model, lag0: f64, sse0: f64, (lo, hi): (f64, f64)) -> Vec<Candidate> {
    let mut out = vec![];
    for degree in 1..=MAX_DEGREE {
        let (lag, sse) = if degree == 1 {
            (lag0, sse0)
        } else {
            m.best_lag(degree, &[], None)
        };
        let start = Candidate {
            degree,
            knees: vec![],
            lag,
            sse,
        };
        out.extend(knee_models(m, start, lo, hi));
    }
    out
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
    // lag fitted with a straight line (refined below).
    let (lag0, sse0) = m.best_lag(1, &[], None);
    let models = all_models(&m, lag0, sse0, m.coil_range(lag0));
    // The noise's correlation from the most flexible model's residual.
    let richest = models
        .iter()
        .min_by(|a, b| a.sse.total_cmp(&b.sse))
        .ok_or(SfFitError::Singular)?;
    let phi = noise_inflation(&m, richest)?;
    let mut scored: Vec<Scored> = models
        .iter()
        .map(|c| Scored {
            model: Family::of(c.degree, c.knees.len()),
            poly_degree: c.degree,
            knees: c.knees.len(),
            knees_c: c.knees.clone(),
            sensor_lag_s: c.lag,
            bic: bic(&m, c, phi),
            delta_bic: 0.0,
        })
        .collect();
    let (best, families, margin) = choose(&mut scored);
    let c = models[best].clone();
    let family = Family::of(c.degree, c.knees.len());
    let bic_by_knees: Vec<f64> = scored
        .iter()
        .filter(|s| s.poly_degree == c.degree)
        .map(|s| s.bic)
        .collect();
    let n = m.b.w.len() as f64;
    let p = m.params(c.degree, c.knees.len()) + c.knees.len() + 1;
    let var = c.sse / (n - p as f64).max(1.0);
    let thr = CHI2_1_95 * phi * var;
    let (lo, hi) = m.coil_range(c.lag);
    let knees = knee_intervals(inp, &m, &c, thr, (lo, hi));
    let (lag_lo, lag_hi) = lag_interval(&m, &c, thr, (lo, hi));

    let curves = Curves {
        f: m.fit(c.lag, c.degree, &c.knees)
            .ok_or(SfFitError::Singular)?,
        degree: c.degree,
        knees: &c.knees,
        with_bias,
        var: phi * var,
    };
    let mut breaks = vec![lo];
    breaks.extend(c.knees.iter().copied());
    breaks.push(hi);
    let (table, tabulation) = tabulate::table(
        &breaks,
        |t| curves.sf(t) * 1e6,
        |t| curves.bias(t) * 3600.0,
        c.lag,
    );
    let nodes = table.temps_c[..table.n].to_vec();
    let segments = segments_from(
        &nodes,
        |t| {
            let a = curves.a_sf(t);
            (curves.dot(&a), a)
        },
        |a| curves.f.se_of(a, curves.var),
    );
    let err = curves.row_error(inp, c.lag);
    let (rms, rms_se, _) = window_rms_ppm(&inp.t, &inp.w, &err, RESIDUAL_WINDOW_S);
    let residual_ppm = Est {
        value: rms,
        se: rms_se,
    };
    let noise_floor = noise_floor_ppm(&inp.t, &inp.w, &err);
    let range = [lo, hi];
    let rot_d: Vec<f64> = (0..m.b.w.len())
        .filter(|&i| m.b.w[i].abs() >= MIN_RATE_DPS)
        .map(|i| m.b.d[i])
        .collect();
    let mut warns: Vec<_> = knees
        .iter()
        .filter_map(|k| warnings::knee_near_edge(k.value, range))
        .collect();
    warns.extend(
        [
            warnings::rate_set(inp, with_bias),
            warnings::temperature_rate_set(&rot_d, lag_hi - lag_lo),
            warnings::span(range),
            warnings::residual(residual_ppm, noise_floor),
            warnings::tabulation(tabulation.max_error_ppm, 0.1),
            warnings::knee_cap(c.knees.len()),
        ]
        .into_iter()
        .flatten(),
    );
    Ok(SfFit {
        method: FitMethod::Continuous,
        model: family,
        degree: family.stated_degree(c.degree),
        knees,
        polynomial: (family != Family::Knees).then(|| curves.polynomial()),
        segments,
        table,
        sensor_lag_s: Some(Interval {
            value: c.lag,
            lo: lag_lo,
            hi: lag_hi,
        }),
        bias: curves.bias_model(),
        asymmetry_ppm: None,
        nonlinearity_ppm: None,
        bic: bic_by_knees,
        criteria: scored,
        families,
        criterion_margin: margin,
        noise_inflation: phi,
        residual_ppm,
        noise_floor_ppm: noise_floor,
        tabulation,
        range_c: range,
        rows_used: rows.len(),
        duration_s: inp.t.last().copied().unwrap_or(0.0) - inp.t.first().copied().unwrap_or(0.0),
        notes: notes(with_bias),
        warnings: warns,
        curve: Some(curves.curve()),
    })
}
