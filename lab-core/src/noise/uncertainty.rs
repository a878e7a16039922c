//! How far a fitted noise model can be trusted (docs/noise.md):
//!
//! - The estimates' covariance: variance 2 AVAR^2/edf each, correlated
//!   between averaging times (overlapping estimates share samples) as the
//!   fitted noise's spectrum says ([`spectral_correlation`]; it matches the
//!   Monte Carlo on the project's generators); quantization (about 0.3 at
//!   any ratio) and the ramp weigh in by their shares. A sinusoid adds no
//!   scatter of its own; its beat with the noise is one variable for the
//!   whole curve, along the sinusoid's shape: a rank-one term of the
//!   parameters' covariance, not of the residuals'.
//! - The parameters' covariance: the sandwich `(J'WJ)^-1 J'W S W J
//!   (J'WJ)^-1`, J the model's derivatives (the coefficients, and the log
//!   of the sinusoid's frequency and of the Markov correlation time), S the
//!   estimates' covariance. Conditional on the model.
//! - Goodness of fit: z_i = (AVAR_i - model_i) / sd_i, chi-square = sum
//!   z_i^2. Correlated estimates make it a scaled chi-square (Satterthwaite:
//!   g chi2_h with g = tr(R^2)/n, h = n/g, R the estimates' correlation);
//!   the model is consistent when the chi-square is below the 99 % point of
//!   that distribution (residual degrees of freedom h (n - p)/n).
//! - Honest intervals: each parameter's variance is multiplied by the
//!   larger of 1, the chi-square per degree of freedom and the mean z^2
//!   where its term carries the model (weighted by its share). Where the
//!   model leaves the measured intervals at averaging times a term
//!   dominates, the term's interval is widened to the values those points
//!   ask for and the term is marked unreliable; so is a term whose own
//!   curve stands above a measured interval (it contradicts the curve).

use super::edf::interval;
use super::model::{
    noise_psd, sin_beat_sd, Correlated, Curve, Fitted, Goodness, Interval, Sinusoid, TermFit,
};
use super::profile::{self, Which};
use super::terms::{ALL, CONF, COUNT, MARKOV, SIN};
use crate::numerics::stats::{chi2_quantile, normal_quantile};
use nalgebra::DMatrix;

/// A fitted parameter: a shape's coefficient, the log frequency, the log
/// correlation time.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Param {
    Coef(usize),
    LnF,
    LnT,
    LnTf,
}

impl Param {
    fn shape(self) -> usize {
        match self {
            Param::Coef(j) => j,
            Param::LnF => SIN,
            Param::LnT => MARKOV,
            Param::LnTf => 1,
        }
    }
}

/// Which shapes the curve shows, with the parameters' covariance.
#[derive(Clone, Debug)]
pub struct Checked {
    pub present: [bool; ALL],
    /// Coefficient over its standard error (0 where not fitted).
    pub significance: [f64; ALL],
    /// Whether the shape carries half of the model somewhere.
    pub shows: [bool; ALL],
    /// Kept by the likelihood though its interval reaches zero (fit.rs).
    pub by_likelihood: [bool; ALL],
    pub params: Vec<Param>,
    pub cov: Option<DMatrix<f64>>,
    /// `(J'WJ)^-1`, the cost's inverse curvature.
    pub naive: Option<DMatrix<f64>>,
}

/// The normal quantile of each of the two intervals of the sinusoid (amplitude,
/// frequency) and of the Markov term (sigma, correlation time): a
/// simultaneous 95 % set (Bonferroni, each 97.5 %), so that both hold the
/// truth together in at least 95 % of records. Two exact 95 % intervals
/// hold it together in only about 90 % (the bench before this: amplitude
/// alone 95/100, frequency alone 94/100, both 89/100).
fn z_pair() -> f64 {
    normal_quantile(1.0 - (1.0 - CONF) / 4.0)
}

fn z95() -> f64 {
    normal_quantile(0.5 + CONF / 2.0)
}

/// Correlation of two AVAR estimates at taus with ratio r >= 1 for the two
/// shapes not taken through their spectrum ([`spectral_correlation`]):
/// quantization (Monte Carlo on the project's generators, about 0.3 at any
/// ratio) and the ramp (no noise: a random walk's degrees of freedom, its
/// kernel).
fn kernel(t: usize, r: f64) -> f64 {
    if r == 1.0 {
        return 1.0;
    }
    match t {
        0 => 0.3,
        _ => r.powf(-0.35),
    }
}

fn sds(f: &Fitted) -> Vec<f64> {
    f.model
        .iter()
        .zip(&f.edf)
        .map(|(m, e)| m * (2.0 / e).sqrt())
        .collect()
}

/// Frequencies per decade of the spectral integral, and the phase pi f tau
/// beyond which a filter's oscillation is replaced by its mean.
const PER_DECADE_F: f64 = 20.0;
const ENVELOPE_X: f64 = 3.0 * std::f64::consts::PI;

/// The correlation of the AVAR estimates at `taus` for Gaussian noise of
/// one-sided PSD `psd` (rate, any mixture). An estimate at tau is the mean
/// square of the Allan difference, whose power response is |H(f)|^2 = 4
/// sin^4(pi f tau) / (pi f tau)^2; for a record of length T much longer
/// than both taus, Cov(V_i, V_j) = (1/4T) int S(f)^2 |H_i|^2 |H_j|^2 df
/// (Isserlis; Parseval over the lags). The integral on a log grid of
/// frequency from 0.01/tau_max to Nyquist, 20 a decade, |H|^2 by its mean
/// 1.5/x^2 (and |H|^4 by 16 (35/128)/x^4) where x = pi f tau > 3 pi. Against
/// the generators (400 records of 20 000 s, adjacent octaves / a decade
/// apart): white 0.50 / 0.03 (this 0.53 / 0.05), flicker 0.69 / 0.07 (0.69
/// / 0.09), random walk 0.88 / 0.40 (0.89 / 0.44), Markov T = 20 s at 2-4,
/// 20-40, 100-200 s 0.86, 0.76, 0.50 (0.87, 0.77, 0.58).
pub fn spectral_correlation(taus: &[f64], tau0: f64, psd: impl Fn(f64) -> f64) -> DMatrix<f64> {
    let n = taus.len();
    let (f0, f1) = (0.01 / taus[n - 1], 0.5 / tau0);
    let k = ((f1 / f0).log10() * PER_DECADE_F).ceil().max(1.0) as usize;
    let dl = (f1 / f0).ln() / k as f64;
    let freqs: Vec<f64> = (0..=k).map(|i| f0 * (dl * i as f64).exp()).collect();
    let weight: Vec<f64> = freqs.iter().map(|&f| psd(f).powi(2) * f * dl).collect();
    let h = |f: f64, tau: f64| {
        let x = std::f64::consts::PI * f * tau;
        if x > ENVELOPE_X {
            (1.5 / (x * x), 16.0 * 35.0 / 128.0 / x.powi(4))
        } else {
            let v = 4.0 * x.sin().powi(4) / (x * x);
            (v, v * v)
        }
    };
    let a = DMatrix::from_fn(n, freqs.len(), |i, q| {
        h(freqs[q], taus[i]).0 * weight[q].sqrt()
    });
    let diag: Vec<f64> = (0..n)
        .map(|i| {
            freqs
                .iter()
                .zip(&weight)
                .map(|(&f, w)| w * h(f, taus[i]).1)
                .sum::<f64>()
        })
        .collect();
    let cov = &a * a.transpose();
    DMatrix::from_fn(n, n, |i, j| {
        if i == j {
            1.0
        } else {
            let d = (diag[i] * diag[j]).sqrt();
            if d > 0.0 {
                (cov[(i, j)] / d).clamp(0.0, 1.0)
            } else {
                0.0
            }
        }
    })
}

/// The estimates' correlation matrix under the model: the noise's scatter
/// through its spectrum ([`spectral_correlation`], every noise type but
/// quantization and the ramp, which weigh in by their shares with their
/// own kernels), plus the sinusoid's beat with the noise, one variable for
/// the whole curve (model.rs, `sin_beat_sd`).
pub fn correlation(c: &Curve, f: &Fitted) -> DMatrix<f64> {
    let n = c.taus.len();
    let tau0 = c.tau0();
    // Shares of the estimate's noise: quantization, ramp, the rest.
    let share: Vec<[f64; 3]> = (0..n)
        .map(|i| {
            let tau = c.taus[i];
            let q = f.shapes.part(0, tau).max(0.0);
            let r = f.shapes.part(4, tau).max(0.0);
            let rest: f64 = (1..ALL)
                .filter(|&t| t != 4 && t != SIN)
                .map(|t| f.shapes.part(t, tau).max(0.0))
                .sum();
            let tot = q + r + rest;
            if tot > 0.0 {
                [q / tot, r / tot, rest / tot]
            } else {
                [0.0, 0.0, 1.0]
            }
        })
        .collect();
    let mut spectral_shapes = f.shapes;
    spectral_shapes.c[0] = 0.0;
    let spec = spectral_correlation(c.taus, tau0, |fr| noise_psd(&spectral_shapes, fr, tau0));
    DMatrix::from_fn(n, n, |i, j| {
        if i == j {
            return 1.0;
        }
        let r = c.taus[i].max(c.taus[j]) / c.taus[i].min(c.taus[j]);
        let (a, b) = (share[i], share[j]);
        (a[0] * b[0]).sqrt() * kernel(0, r)
            + (a[1] * b[1]).sqrt() * kernel(4, r)
            + (a[2] * b[2]).sqrt() * spec[(i, j)]
    })
}

/// The sinusoid's beat with the noise at each averaging time (model.rs,
/// `sin_beat_sd`): one variable for the whole curve.
fn beats(c: &Curve, f: &Fitted) -> Vec<f64> {
    c.taus
        .iter()
        .map(|&tau| sin_beat_sd(&f.shapes, tau, c.tau0(), c.n_phase))
        .collect()
}

/// The degrees of freedom of each measured estimate with the beat counted
/// (its interval: the beat is a real error of the point, though not of
/// the residuals).
pub fn measured_edf(c: &Curve, f: &Fitted) -> Vec<f64> {
    let sd = sds(f);
    beats(c, f)
        .iter()
        .enumerate()
        .map(|(i, b)| (2.0 * f.model[i].powi(2) / (sd[i] * sd[i] + b * b)).max(1.0))
        .collect()
}

/// Satterthwaite's scale g and degrees of freedom h of the chi-square of
/// correlated estimates.
pub fn satterthwaite(c: &Curve, f: &Fitted) -> (f64, f64) {
    let r = correlation(c, f);
    let n = c.taus.len() as f64;
    let tr2: f64 = r.iter().map(|v| v * v).sum();
    let g = (tr2 / n).max(1.0);
    (g, n / g)
}

/// Normalised residuals of the model.
fn residuals(c: &Curve, f: &Fitted) -> Vec<f64> {
    sds(f)
        .iter()
        .enumerate()
        .map(|(i, sd)| (c.avar[i] - f.model[i]) / sd)
        .collect()
}

pub fn chi2(c: &Curve, f: &Fitted) -> f64 {
    residuals(c, f).iter().map(|z| z * z).sum()
}

fn params(f: &Fitted) -> Vec<Param> {
    let mut p: Vec<Param> = (0..ALL).filter(|&j| f.has(j)).map(Param::Coef).collect();
    if f.has(SIN) {
        p.push(Param::LnF);
    }
    if f.has(MARKOV) {
        p.push(Param::LnT);
    }
    if f.filtered() {
        p.push(Param::LnTf);
    }
    p
}

/// d model(tau) / d param.
fn derivative(f: &Fitted, p: Param, tau: f64) -> f64 {
    let sh = &f.shapes;
    let h = 1e-5f64;
    let moved = |p: Param, e: f64| {
        let mut s = *sh;
        match p {
            Param::LnF => s.f *= e.exp(),
            Param::LnT => s.t *= e.exp(),
            _ => s.tf *= e.exp(),
        }
        s.part(p.shape(), tau)
    };
    match p {
        Param::Coef(j) => sh.unit(j, tau),
        _ => (moved(p, h) - moved(p, -h)) / (2.0 * h),
    }
}

/// The sandwich covariance of the model's parameters, and the naive one
/// `(J'WJ)^-1` (the inverse curvature of the weighted cost, W the inverse
/// variances: what the cost's rise measures, profile.rs).
fn covariance(c: &Curve, f: &Fitted, ps: &[Param]) -> Option<(DMatrix<f64>, DMatrix<f64>)> {
    let (n, p) = (c.taus.len(), ps.len());
    if p == 0 || n < p {
        return None;
    }
    let x = DMatrix::from_fn(n, p, |i, k| derivative(f, ps[k], c.taus[i]));
    let scale: Vec<f64> = (0..p)
        .map(|k| x.column(k).norm().max(f64::MIN_POSITIVE))
        .collect();
    let xs = DMatrix::from_fn(n, p, |i, k| x[(i, k)] / scale[k]);
    let sd = sds(f);
    let wx = DMatrix::from_fn(n, p, |i, k| xs[(i, k)] / (sd[i] * sd[i]));
    let bread = (xs.transpose() * &wx).try_inverse()?;
    let rho = correlation(c, f);
    let beat = beats(c, f);
    let sigma = DMatrix::from_fn(n, n, |i, j| rho[(i, j)] * sd[i] * sd[j] + beat[i] * beat[j]);
    let meat = wx.transpose() * sigma * &wx;
    let cov = &bread * meat * &bread;
    let out = DMatrix::from_fn(p, p, |a, b| cov[(a, b)] / (scale[a] * scale[b]));
    let naive = DMatrix::from_fn(p, p, |a, b| bread[(a, b)] / (scale[a] * scale[b]));
    (0..p)
        .all(|k| out[(k, k)].is_finite() && naive[(k, k)].is_finite())
        .then_some((out, naive))
}

/// Whether shape j carries at least half of the model somewhere.
fn shows(c: &Curve, f: &Fitted, j: usize) -> bool {
    (0..c.taus.len()).any(|i| f.shapes.part(j, c.taus[i]) >= 0.5 * f.model[i])
}

/// Which shapes of the fit the curve shows: at least half of the model
/// somewhere, and an interval of the coefficient that excludes zero.
pub fn check(c: &Curve, f: &Fitted) -> Checked {
    let ps = params(f);
    let both = covariance(c, f, &ps);
    let naive = both.as_ref().map(|b| b.1.clone());
    let cov = both.map(|b| b.0);
    let mut present = [false; ALL];
    let mut significance = [0.0; ALL];
    match &cov {
        Some(cov) => {
            for (k, p) in ps.iter().enumerate() {
                if let Param::Coef(j) = *p {
                    let se = cov[(k, k)].max(0.0).sqrt();
                    significance[j] = f.shapes.c[j] / se.max(f64::MIN_POSITIVE);
                    present[j] = shows(c, f, j) && f.shapes.c[j] - z95() * se > 0.0;
                }
            }
        }
        None => {
            // Degenerate: the power laws that show stay, the searched
            // shapes go.
            for j in 0..COUNT {
                present[j] = f.has(j) && shows(c, f, j);
            }
        }
    }
    let mut sh = [false; ALL];
    for (j, v) in sh.iter_mut().enumerate() {
        *v = f.has(j) && shows(c, f, j);
    }
    Checked {
        present,
        significance,
        shows: sh,
        by_likelihood: [false; ALL],
        params: ps,
        cov,
        naive,
    }
}

/// The model's goodness of fit.
fn goodness(c: &Curve, f: &Fitted, n_params: usize) -> Goodness {
    let n = c.taus.len();
    let z = residuals(c, f);
    let chi2: f64 = z.iter().map(|v| v * v).sum();
    let dof = (n as f64 - n_params as f64).max(1.0);
    let (g, h) = satterthwaite(c, f);
    let h_res = (h * dof / n as f64).max(1.0);
    let limit = g * chi2_quantile(0.99, h_res);
    let edf = measured_edf(c, f);
    let outside: Vec<usize> = (0..n)
        .filter(|&i| {
            let (lo, hi) = interval(c.avar[i].sqrt(), edf[i], CONF);
            let m = f.model[i].sqrt();
            m < lo || m > hi
        })
        .collect();
    Goodness {
        chi2,
        dof,
        chi2_per_dof: chi2 / dof,
        limit_per_dof: limit / dof,
        consistent: chi2 <= limit,
        outside,
        z,
    }
}

/// Shape j's share of the model at averaging time i.
fn share(c: &Curve, f: &Fitted, j: usize, i: usize) -> f64 {
    f.shapes.part(j, c.taus[i]) / f.model[i]
}

/// `i` widened to hold `(lo, hi)`.
fn widen(i: &mut Interval, (lo, hi): (f64, f64)) {
    i.lo = i.lo.min(lo);
    i.hi = i.hi.max(hi);
}

/// The profile intervals of the sinusoid or the Markov term (profile.rs),
/// from the parameters' sandwich and naive covariances and their variance
/// inflations `lambda`.
fn profile_of(
    c: &Curve,
    f: &Fitted,
    chk: &Checked,
    lambda: &[f64],
    which: Which,
) -> Option<profile::Profile> {
    let (sand, naive) = (chk.cov.as_ref()?, chk.naive.as_ref()?);
    let (j, lp) = match which {
        Which::Sin => (SIN, Param::LnF),
        Which::Markov => (MARKOV, Param::LnT),
    };
    let kc = chk.params.iter().position(|&p| p == Param::Coef(j))?;
    let kp = chk.params.iter().position(|&p| p == lp)?;
    let cj = f.shapes.c[j];
    // Variance of the log size: ln A = ln c / 2; ln sigma = (ln c + ln T) / 2.
    let size_var = |m: &DMatrix<f64>| match which {
        Which::Sin => 0.25 * m[(kc, kc)] / (cj * cj),
        Which::Markov => 0.25 * (m[(kc, kc)] / (cj * cj) + m[(kp, kp)] + 2.0 * m[(kc, kp)] / cj),
    };
    let param = profile::Spread {
        sandwich: sand[(kp, kp)],
        naive: naive[(kp, kp)],
        inflation: lambda[kp],
    };
    let size = profile::Spread {
        sandwich: size_var(sand),
        naive: size_var(naive),
        inflation: lambda[kc],
    };
    profile::profile(c, f, which, param, size, z_pair())
}

/// The fit made into the report: goodness, honest intervals, reliability.
pub fn finish(c: &Curve, f: Fitted, chk: Checked) -> TermFit {
    let n = c.taus.len();
    let ps = chk.params.clone();
    let good = goodness(c, &f, ps.len());
    let z = &good.z;
    let global = good.chi2_per_dof;
    let expect = good.dof / n as f64;
    // Variance inflation per parameter.
    let lambda: Vec<f64> = ps
        .iter()
        .map(|p| {
            let j = p.shape();
            let (mut num, mut den) = (0.0, 0.0);
            for i in 0..n {
                let s = share(c, &f, j, i);
                num += s * z[i] * z[i];
                den += s;
            }
            let local = if den > 0.0 { num / den / expect } else { 1.0 };
            local.max(global).max(1.0)
        })
        .collect();
    let se: Vec<f64> = (0..ps.len())
        .map(|k| {
            chk.cov
                .as_ref()
                .map_or(f64::INFINITY, |cv| (cv[(k, k)].max(0.0) * lambda[k]).sqrt())
        })
        .collect();
    let cov_of = |a: usize, b: usize| -> f64 {
        chk.cov
            .as_ref()
            .map_or(0.0, |cv| cv[(a, b)] * (lambda[a] * lambda[b]).sqrt())
    };
    let zq = z95();
    let zp = z_pair();
    // Measured intervals (variance).
    let edf = measured_edf(c, &f);
    let meas: Vec<(f64, f64)> = (0..n)
        .map(|i| {
            let (lo, hi) = interval(c.avar[i].sqrt(), edf[i], CONF);
            (lo * lo, hi * hi)
        })
        .collect();
    // Coefficient intervals, widened to what the missed points ask for.
    let mut lo = [0.0; ALL];
    let mut hi = [0.0; ALL];
    let mut reliable = [true; ALL];
    for (k, p) in ps.iter().enumerate() {
        let Param::Coef(j) = *p else { continue };
        let cj = f.shapes.c[j];
        let z = if j == SIN || j == MARKOV { zp } else { zq };
        lo[j] = cj - z * se[k];
        hi[j] = cj + z * se[k];
        for i in 0..n {
            let b = f.shapes.unit(j, c.taus[i]);
            let s = share(c, &f, j, i);
            if good.outside.contains(&i) && s >= 0.5 {
                let implied = cj + (c.avar[i] - f.model[i]) / b;
                lo[j] = lo[j].min(implied);
                hi[j] = hi[j].max(implied);
                reliable[j] = false;
            }
            if f.shapes.part(j, c.taus[i]) > meas[i].1 {
                reliable[j] = false;
            }
        }
        if lo[j] <= 0.0 && !chk.by_likelihood[j] {
            reliable[j] = false;
        }
        lo[j] = lo[j].max(0.0);
    }
    let index = |want: Param| ps.iter().position(|&p| p == want);
    let profiled = |which: Which| profile_of(c, &f, &chk, &lambda, which);
    let sinusoid = (f.has(SIN)).then(|| {
        let (a2, a2lo, a2hi) = (f.shapes.c[SIN], lo[SIN], hi[SIN]);
        let k = index(Param::LnF);
        let sf = k.map_or(f64::INFINITY, |k| se[k]);
        let mut amplitude = Interval {
            value: a2.sqrt(),
            lo: a2lo.max(0.0).sqrt(),
            hi: a2hi.max(0.0).sqrt(),
        };
        let mut frequency = Interval {
            value: f.shapes.f,
            lo: f.shapes.f * (-zp * sf).exp(),
            hi: f.shapes.f * (zp * sf).exp(),
        };
        if let Some(pr) = profiled(Which::Sin) {
            widen(&mut amplitude, pr.size);
            widen(&mut frequency, pr.param);
        }
        Sinusoid {
            amplitude_dps: amplitude,
            frequency_hz: frequency,
            reliable: reliable[SIN],
        }
    });
    let correlated = (f.has(MARKOV)).then(|| {
        let (q2, t) = (f.shapes.c[MARKOV], f.shapes.t);
        let kq = index(Param::Coef(MARKOV));
        let kt = index(Param::LnT);
        let (vq, vt, cqt) = match (kq, kt) {
            (Some(a), Some(b)) => (se[a] * se[a] / (q2 * q2), se[b] * se[b], cov_of(a, b) / q2),
            _ => (f64::INFINITY, f64::INFINITY, 0.0),
        };
        // Widening of q_c^2 carried over (relative).
        let wq = ((hi[MARKOV] - q2) / (zp * q2)).powi(2).max(vq);
        let sigma = super::terms::markov_sigma_dph(q2, t);
        let s_sigma = (0.25 * (wq + vt) + 0.5 * cqt).max(0.0).sqrt();
        // N = q_c T_c: ln N = ln q_c^2 / 2 + ln T_c.
        let white = super::terms::markov_white_dpsh(q2, t);
        let s_white = (0.25 * wq + vt + cqt).max(0.0).sqrt();
        let ratio = |s: f64| (zp * s).exp();
        let mut sigma_dph = Interval {
            value: sigma,
            lo: sigma / ratio(s_sigma),
            hi: sigma * ratio(s_sigma),
        };
        let mut tau_s = Interval {
            value: t,
            lo: t / ratio(vt.sqrt()),
            hi: t * ratio(vt.sqrt()),
        };
        if let Some(pr) = profiled(Which::Markov) {
            widen(&mut sigma_dph, (pr.size.0 * 3600.0, pr.size.1 * 3600.0));
            widen(&mut tau_s, pr.param);
        }
        Correlated {
            sigma_dph,
            tau_s,
            white_limit_dpsh: Interval {
                value: white,
                lo: white / ratio(s_white),
                hi: white * ratio(s_white),
            },
            reliable: reliable[MARKOV],
        }
    });
    let arw_filter_s = f.filtered().then(|| {
        let k = index(Param::LnTf);
        let sv = k.map_or(f64::INFINITY, |k| se[k]);
        let tf = f.shapes.tf;
        Interval {
            value: tf,
            lo: tf * (-zq * sv).exp(),
            hi: tf * (zq * sv).exp(),
        }
    });
    let dominant: Vec<usize> = (0..n)
        .map(|i| {
            (0..ALL)
                .max_by(|&a, &b| {
                    f.shapes
                        .part(a, c.taus[i])
                        .total_cmp(&f.shapes.part(b, c.taus[i]))
                })
                .unwrap_or(1)
        })
        .collect();
    let mut present = [false; COUNT];
    let (mut plo, mut phi, mut prel) = ([0.0; COUNT], [0.0; COUNT], [true; COUNT]);
    let mut cc = [0.0; COUNT];
    for j in 0..COUNT {
        present[j] = f.has(j) && chk.present[j];
        cc[j] = f.shapes.c[j];
        if present[j] {
            plo[j] = lo[j];
            phi[j] = hi[j];
            prel[j] = reliable[j];
        }
    }
    TermFit {
        c: cc,
        present,
        lo: plo,
        hi: phi,
        reliable: prel,
        bias_upper_bound: false,
        sinusoid,
        correlated,
        arw_filter_s,
        shapes: f.shapes,
        model: f.model,
        dominant,
        edf,
        goodness: good,
    }
}

#[cfg(test)]
mod tests {
    use super::spectral_correlation;

    #[test]
    fn spectral_correlation_matches_the_generators_monte_carlo() {
        // Monte Carlo on the project's generators (400 records of 20 000 s,
        // docs/notes/issue-21-allan.md): correlation of the estimates at 2
        // and 4 s, and at 2 and 20 s.
        let taus = [2.0, 4.0, 20.0];
        type Psd = fn(f64) -> f64;
        let cases: [(&str, Psd, f64, f64); 3] = [
            ("white", |_| 1.0, 0.50, 0.03),
            ("flicker", |f| 1.0 / f, 0.69, 0.11),
            ("random walk", |f| 1.0 / (f * f), 0.89, 0.43),
        ];
        for (name, psd, octave, decade) in cases {
            let r = spectral_correlation(&taus, 1.0, psd);
            assert!((r[(0, 1)] - octave).abs() < 0.05, "{name}: {}", r[(0, 1)]);
            assert!((r[(0, 2)] - decade).abs() < 0.05, "{name}: {}", r[(0, 2)]);
            assert_eq!(r[(1, 1)], 1.0);
        }
    }
}
