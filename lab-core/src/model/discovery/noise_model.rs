//! The residual's own noise, as the criterion and the intervals see it
//! (docs/discovery.md): the window means of the residual are an effect's
//! regressors times its parameters plus noise, and the noise is what the
//! Allan analysis of the residual says it is (IEEE 952 terms):
//!
//! - white (quantization and angle random walk): variance
//!   `2 Q^2/tau^2 + N^2/tau` for a window of tau, scaled by the window's
//!   share of rows;
//! - bias instability (flicker, two-sided PSD B^2/(2 pi f)): a sum of
//!   first-order Markov processes with correlation times spaced by
//!   r = sqrt(10) from 2 s to the record's length, each of variance
//!   B^2 ln(r)/pi (Lorentzians of equal variance spaced by r sum to
//!   sigma^2/(2 f ln r): the flat Allan floor);
//! - rate random walk: a Wiener process of increments K^2 dt, starting at
//!   zero (its start is the constant every fit carries);
//! - exponentially correlated (first-order Markov) noise of variance q^2
//!   and correlation time T_c (physics.md 3: a random walk below T_c, white
//!   above; what a regressor's own filtered sensor noise leaves, among
//!   others).
//!
//! The terms are fitted to the residual's Allan variance here
//! ([`fit_terms`], on the noise analysis's estimator), every term kept;
//! then, given the terms of a selection, the random walk, flicker and
//! Markov levels are refined by maximum likelihood (likelihood.rs): the
//! innovations' likelihood weighs the slowest frequencies, where the
//! Allan curve has the fewest estimates.
//!
//! Generalised least squares with this covariance is ordinary least squares
//! on the Kalman filter's standardised innovations: [`Whitener`] runs the
//! filter's gains (they do not depend on the data) over any column. A
//! random walk then makes a slow shape cheap to imitate, and a record-long
//! drift stops passing for a warm-up.

use super::windows::Windows;
use crate::noise::adev::{averaging_factors, oavar};
use crate::noise::edf::edf_oavar;
use crate::noise::terms::{basis, COUNT};

/// Spacing of the flicker approximation's correlation times.
const FLICKER_SPACING: f64 = 3.162_277_660_168_379_5;
/// Shortest flicker correlation time, s (faster ones are white in a 1 s mean).
const FLICKER_MIN_S: f64 = 2.0;

/// Fewest windows whose scatter the noise's colour is measured from (the
/// Allan fit of [`NoiseModel::from_residual`] and the likelihood of
/// [`refine`]); a shorter record is a short one (docs/discovery.md).
pub const MIN_COLOUR_WINDOWS: usize = 64;

/// The noise of the residual's window means.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct NoiseModel {
    /// Variance of a full window's mean from white noise, (deg/s)^2.
    pub white: f64,
    /// Flicker B^2, (deg/s)^2.
    pub flicker: f64,
    /// Random-walk K^2, (deg/s)^2/s.
    pub random_walk: f64,
    /// Markov variance q^2, (deg/s)^2, and correlation time, s.
    pub markov: f64,
    pub markov_s: f64,
}

impl NoiseModel {
    /// White noise of the window means' robust scatter (half the median
    /// squared difference of neighbours over the chi-square median): the
    /// first pass, before anything is known of the residual's colour.
    pub fn white_of(means: &[f64], keep: &[bool]) -> Self {
        let m: Vec<f64> = means
            .iter()
            .zip(keep)
            .filter(|(_, k)| **k)
            .map(|(v, _)| *v)
            .collect();
        let d2: Vec<f64> = m.windows(2).map(|p| (p[1] - p[0]).powi(2)).collect();
        let white = super::white::white_var_of_diffs(&d2)
            .unwrap_or(1e-12)
            .max(1e-30);
        Self {
            white,
            flicker: 0.0,
            random_walk: 0.0,
            markov: 0.0,
            markov_s: 1.0,
        }
    }

    /// White noise from the scatter of the residual's own samples within
    /// each window (neighbours' differences, so no slow shape enters),
    /// as the variance of a full window's mean: on a record too short for
    /// its window means to show their noise, the one level the samples
    /// still measure. The mean square difference, its largest 1 % left out
    /// (a table's rate step), over the share of a Gaussian's chi-square(1)
    /// mean below its 99 % quantile (P(chi2_3 < 6.635) / 0.99).
    pub fn white_of_samples(r: &[f64], win: &Windows) -> Option<Self> {
        let mut d2: Vec<f64> = (1..r.len().min(win.idx.len()))
            .filter(|&k| win.idx[k] == win.idx[k - 1])
            .map(|k| (r[k] - r[k - 1]).powi(2))
            .filter(|v| v.is_finite())
            .collect();
        if d2.len() < 10 {
            return None;
        }
        d2.sort_by(f64::total_cmp);
        let kept = &d2[..(d2.len() as f64 * 0.99).ceil() as usize];
        let ms = kept.iter().sum::<f64>() / kept.len() as f64;
        let var = ms / (2.0 * 0.915_508 / 0.99);
        let mut counts = win.count.clone();
        counts.sort_by(f64::total_cmp);
        let nominal = counts
            .get(counts.len() / 2)
            .copied()
            .unwrap_or(1.0)
            .max(1.0);
        let white = var / nominal;
        (white > 0.0).then_some(Self {
            white,
            flicker: 0.0,
            random_walk: 0.0,
            markov: 0.0,
            markov_s: 1.0,
        })
    }

    /// From the Allan variance of a residual's window means `means` (the
    /// windows `keep` says; spikes left out), `tau0` s apart: the IEEE 952
    /// terms fitted by [`fit_terms`] to the curve up to a tenth of the
    /// record. The rate ramp is
    /// fitted but left out of the model: a drift is a shape for the fit to
    /// find, not noise. Falls back to [`Self::white_of`] where the record
    /// is too short.
    pub fn from_residual(means: &[f64], keep: &[bool], tau0: f64) -> Self {
        let m: Vec<f64> = means
            .iter()
            .zip(keep)
            .filter(|(_, k)| **k)
            .map(|(v, _)| *v)
            .collect();
        let white = Self::white_of(means, keep);
        if m.len() < MIN_COLOUR_WINDOWS {
            return white;
        }
        // Averaging times up to a fifth of the record: beyond, the few
        // independent estimates are the ones the fit's slow shapes have
        // emptied (the likelihood of [`refine`] sees those).
        let ms: Vec<usize> = averaging_factors(m.len(), 10)
            .into_iter()
            .filter(|&k| k <= m.len() / 5)
            .collect();
        let taus: Vec<f64> = ms.iter().map(|&k| k as f64 * tau0).collect();
        let avar = oavar(&m, &ms);
        let Some((c, mk)) = fit_terms(&taus, &avar, &ms, m.len() + 1) else {
            return white;
        };
        let w = 2.0 * c[0] / (tau0 * tau0) + c[1] / tau0;
        Self {
            white: if w > 0.0 { w } else { white.white },
            flicker: c[2],
            random_walk: c[3],
            markov: mk.0,
            markov_s: mk.1,
        }
    }

    /// The model with its slow levels no larger than a gyro's of the
    /// given caps (bias instability deg/h, random walk deg/h/sqrt(h),
    /// Markov deg/h; grade.rs's `noise_caps`).
    pub fn capped(&self, (b, k, q): (f64, f64, f64)) -> Self {
        let mut m = *self;
        m.flicker = m.flicker.min((b / 3600.0).powi(2));
        m.random_walk = m.random_walk.min((k / 216_000.0).powi(2));
        m.markov = m.markov.min((q / 3600.0).powi(2));
        m
    }

    /// Its stationary correlated processes over a record of `span` s:
    /// (correlation time s, variance (deg/s)^2), the flicker's sum of
    /// Markov processes first ([`Whitener`]'s).
    pub fn processes(&self, span: f64) -> Vec<(f64, f64)> {
        let mut comps = vec![];
        if self.flicker > 0.0 {
            let var_fl = self.flicker * FLICKER_SPACING.ln() / std::f64::consts::PI;
            let mut tc = FLICKER_MIN_S;
            while tc <= span.max(FLICKER_MIN_S) * FLICKER_SPACING {
                comps.push((tc, var_fl));
                tc *= FLICKER_SPACING;
            }
        }
        if self.markov > 0.0 {
            comps.push((self.markov_s.max(1e-6), self.markov));
        }
        comps
    }

    /// Standard deviation of a mean over `tau` s of stationary noise
    /// (white and flicker; a random walk wanders, it has no level to
    /// deviate from), deg/s.
    pub fn sd_of_mean(&self, tau: f64, window_s: f64) -> f64 {
        let fl = 2.0 * std::f64::consts::LN_2 / std::f64::consts::PI * self.flicker;
        let tc = self.markov_s.max(1e-9);
        let x = tau.max(window_s) / tc;
        let mk = self.markov * 2.0 / x * (1.0 - (1.0 - (-x).exp()) / x);
        (self.white * window_s / tau.max(window_s) + fl + mk).sqrt()
    }
}

/// Allan variance of first-order Markov noise of unit variance and
/// correlation time `tc` at `tau`: physics.md 3's `(q_c T_c)^2/tau (1 -
/// T_c/(2 tau) (3 - 4 e^(-tau/T_c) + e^(-2 tau/T_c)))` with the driving
/// density q_c^2 = 2 sigma^2/T_c of a process of variance sigma^2.
pub fn markov_avar(tau: f64, tc: f64) -> f64 {
    let x = tau / tc;
    2.0 * tc / tau * (1.0 - (3.0 - 4.0 * (-x).exp() + (-2.0 * x).exp()) / (2.0 * x))
}

/// The five IEEE 952 coefficients (Q^2, N^2, B^2, K^2, R^2) and a
/// first-order Markov term (q^2, T_c) fitted to an Allan variance curve
/// `avar` at `taus` (averaging factors `ms`, `n_phase` angle points):
/// non-negative weighted least squares (the best of the subsets whose
/// solution is non-negative, T_c on a grid), reweighted twice at the model
/// (an estimate's variance 2 AVAR^2/edf). Unlike the noise analysis's
/// reported terms, no term is dropped for carrying less than half the
/// curve: a bias instability that white noise hides at every measured
/// averaging time still widens the interval of a record-long bias.
pub fn fit_terms(
    taus: &[f64],
    avar: &[f64],
    ms: &[usize],
    n_phase: usize,
) -> Option<([f64; COUNT], (f64, f64))> {
    let n = taus.len();
    if n < 3 {
        return None;
    }
    let edf: Vec<f64> = ms
        .iter()
        .map(|&m| edf_oavar(0, m, n_phase).max(1.0))
        .collect();
    let (t_lo, t_hi) = (taus[0] * 2.0, taus[n - 1] / 2.0);
    let mut tcs = vec![0.0];
    if t_hi > t_lo {
        tcs.extend((0..10).map(|i| t_lo * (t_hi / t_lo).powf(i as f64 / 9.0)));
    }
    let mut model = avar.to_vec();
    let mut best = None;
    for _ in 0..3 {
        let w: Vec<f64> = (0..n)
            .map(|i| edf[i] / (2.0 * model[i].max(1e-300).powi(2)))
            .collect();
        let mut fit: Option<([f64; COUNT], (f64, f64), f64)> = None;
        for &tc in &tcs {
            let terms = COUNT + usize::from(tc > 0.0);
            for mask in 1u32..(1 << terms) {
                let sub: Vec<usize> = (0..terms).filter(|j| mask & (1 << j) != 0).collect();
                if sub.len() > n {
                    continue;
                }
                let cols: Vec<Vec<f64>> = sub
                    .iter()
                    .map(|&j| {
                        taus.iter()
                            .map(|&t| {
                                if j < COUNT {
                                    basis(j, t)
                                } else {
                                    markov_avar(t, tc)
                                }
                            })
                            .collect()
                    })
                    .collect();
                let Some(f) = crate::numerics::lsq::wls(&cols, avar, Some(&w)) else {
                    continue;
                };
                if f.coef.iter().any(|&c| c < 0.0) || fit.as_ref().is_some_and(|b| b.2 <= f.sse) {
                    continue;
                }
                let mut c = [0.0; COUNT];
                let mut mk = (0.0, 1.0);
                for (k, &j) in sub.iter().enumerate() {
                    if j < COUNT {
                        c[j] = f.coef[k];
                    } else {
                        mk = (f.coef[k], tc);
                    }
                }
                fit = Some((c, mk, f.sse));
            }
        }
        let (c, mk, _) = fit?;
        model = taus
            .iter()
            .map(|&t| {
                (0..COUNT).map(|j| c[j] * basis(j, t)).sum::<f64>() + mk.0 * markov_avar(t, mk.1)
            })
            .collect();
        best = Some((c, mk));
    }
    best
}

/// The Kalman filter's gains for a noise model over a run's windows: it
/// turns any column of window means into its standardised innovations.
pub struct Whitener {
    /// States: the random walk, then the flicker processes.
    states: usize,
    /// Per window: each state's transition factor, the gains, and
    /// 1/sqrt(innovation variance) (0 for a window left out).
    phi: Vec<f64>,
    gain: Vec<f64>,
    inv_sd: Vec<f64>,
    /// Sum of the logarithms of the innovation variances.
    log_det: f64,
    pub keep: Vec<bool>,
}

/// The variance of a mean over `x` correlation times of a first-order
/// Markov process of unit variance: 2 (x - 1 + e^(-x))/x^2 (1 at x = 0).
pub fn markov_mean_var(x: f64) -> f64 {
    if x < 1e-4 {
        1.0 - x / 3.0
    } else {
        2.0 * (x - 1.0 + (-x).exp()) / (x * x)
    }
}

/// Columns [`Whitener::whiten_many`] filters side by side.
const WHITEN_GROUP: usize = 8;

/// A correlated process faster than this many of its correlation times
/// per observation is white there.
const WHITE_BEYOND: f64 = 3.0;

impl Whitener {
    /// The gains of `noise` over windows `win` (mid times, row counts),
    /// using the windows `keep` marks.
    pub fn new(noise: &NoiseModel, win: &Windows, keep: &[bool]) -> Self {
        Self::averaged(noise, win, keep, 0.0)
    }

    /// [`Self::new`] for observations that are means over `block_s` s
    /// (blocks of windows, likelihood.rs): each correlated process's
    /// variance is that of its mean over the block and its correlation from
    /// one block to the next that of those means (exact at lag one; as a
    /// first-order process beyond), and those faster than [`WHITE_BEYOND`]
    /// correlation times per block join the white noise.
    /// The random walk is taken at the blocks' times (its mean over a
    /// block differs by a third of a step, small beside the white noise of
    /// a block wherever the walk can be told from it).
    pub fn averaged(noise: &NoiseModel, win: &Windows, keep: &[bool], block_s: f64) -> Self {
        let n = win.len();
        let span = if n > 1 { win.t[n - 1] - win.t[0] } else { 1.0 };
        // The Markov process last, its own variance.
        let comps = noise.processes(span);
        let mut taus: Vec<f64> = vec![];
        let mut vars: Vec<f64> = vec![];
        let mut white_extra = 0.0;
        for (tc, v) in comps {
            let x = block_s / tc;
            let v = v * markov_mean_var(x);
            if x > WHITE_BEYOND {
                white_extra += v;
            } else {
                taus.push(tc);
                vars.push(v);
            }
        }
        let white = noise.white + white_extra;
        let s = 1 + taus.len();
        let mut counts: Vec<f64> = win.count.clone();
        let mid = counts.len() / 2;
        let nominal = if counts.is_empty() {
            1.0
        } else {
            *counts.select_nth_unstable_by(mid, f64::total_cmp).1
        };
        // P: covariance of the state prediction (s x s, row-major).
        let mut p = vec![0.0; s * s];
        for i in 1..s {
            p[i * s + i] = vars[i - 1];
        }
        let mut phi = vec![1.0; n * s];
        let mut gain = vec![0.0; n * s];
        let mut inv_sd = vec![0.0; n];
        let mut log_det = 0.0;
        let mut ph = vec![1.0; s];
        let mut last_dt = f64::NAN;
        let mut ph1 = vec![0.0; s];
        for k in 0..n {
            if k > 0 {
                let dt = (win.t[k] - win.t[k - 1]).max(0.0);
                // The factors change only with the spacing.
                if dt != last_dt {
                    last_dt = dt;
                    ph[0] = 1.0;
                    for (i, tc) in taus.iter().enumerate() {
                        ph[i + 1] = if block_s > 0.0 {
                            // Block means: the lag-one correlation of an
                            // Ornstein-Uhlenbeck process's means over
                            // x = block/tc, (1 - e^-x)^2/(x^2 g(x)), then
                            // the decay over any gap beyond a block.
                            let x = block_s / tc;
                            let lag1 = (1.0 - (-x).exp()).powi(2) / (x * x * markov_mean_var(x));
                            lag1.min(1.0) * (-(dt - block_s).max(0.0) / tc).exp()
                        } else {
                            (-dt / tc).exp()
                        };
                    }
                }
                // P stays symmetric (each pair's update is the same
                // product): the upper triangle, mirrored.
                for i in 0..s {
                    for j in i..s {
                        p[i * s + j] *= ph[i] * ph[j];
                        p[j * s + i] = p[i * s + j];
                    }
                }
                p[0] += noise.random_walk * dt;
                for i in 1..s {
                    p[i * s + i] += vars[i - 1] * (1.0 - ph[i] * ph[i]);
                }
                phi[k * s..(k + 1) * s].copy_from_slice(&ph);
            }
            if !keep[k] {
                continue;
            }
            // Observation: the sum of the states plus white noise.
            for (i, v) in ph1.iter_mut().enumerate() {
                *v = p[i * s..(i + 1) * s].iter().sum();
            }
            let f = ph1.iter().sum::<f64>() + white * nominal / win.count[k].max(1e-9);
            if f <= 0.0 || !f.is_finite() {
                continue;
            }
            for i in 0..s {
                gain[k * s + i] = ph1[i] / f;
            }
            for i in 0..s {
                for j in i..s {
                    p[i * s + j] -= ph1[i] * ph1[j] / f;
                    p[j * s + i] = p[i * s + j];
                }
            }
            inv_sd[k] = 1.0 / f.sqrt();
            log_det += f.ln();
        }
        Self {
            states: s,
            phi,
            gain,
            inv_sd,
            log_det,
            keep: keep.to_vec(),
        }
    }

    /// The standardised innovations of `x` (one value per window; 0 for
    /// a window left out).
    pub fn whiten(&self, x: &[f64]) -> Vec<f64> {
        let s = self.states;
        let mut a = vec![0.0; s];
        let mut out = vec![0.0; x.len()];
        for (k, &xk) in x.iter().enumerate() {
            if k > 0 {
                for (ai, f) in a.iter_mut().zip(&self.phi[k * s..(k + 1) * s]) {
                    *ai *= f;
                }
            }
            if !self.keep[k] || self.inv_sd[k] == 0.0 {
                continue;
            }
            let v = xk - a.iter().sum::<f64>();
            out[k] = v * self.inv_sd[k];
            for (ai, g) in a.iter_mut().zip(&self.gain[k * s..(k + 1) * s]) {
                *ai += g * v;
            }
        }
        out
    }

    /// [`Self::whiten`] of each of `xs` (bit for bit the same), taken
    /// [`WHITEN_GROUP`] at a time: the filter's factors and gains (the
    /// states times the windows, megabytes on a day-long record) are read
    /// once per group, and the columns' recursions, each a chain of
    /// dependent additions, run side by side.
    pub fn whiten_many(&self, xs: &[&[f64]]) -> Vec<Vec<f64>> {
        let mut out = Vec::with_capacity(xs.len());
        for group in xs.chunks(WHITEN_GROUP) {
            out.extend(match group.len() {
                1 => self.whiten_group::<1>(group),
                2 => self.whiten_group::<2>(group),
                3 | 4 => self.whiten_group::<4>(group),
                _ => self.whiten_group::<WHITEN_GROUP>(group),
            });
        }
        out
    }

    /// [`Self::whiten`] of up to `G` columns, the states
    /// held state by state across the columns (the same operations on
    /// each column, in the same order, as [`Self::whiten`]'s).
    fn whiten_group<const G: usize>(&self, xs: &[&[f64]]) -> Vec<Vec<f64>> {
        let s = self.states;
        let n = xs.iter().map(|x| x.len()).max().unwrap_or(0);
        let mut a = vec![[0.0f64; G]; s];
        let mut out: Vec<Vec<f64>> = xs.iter().map(|x| vec![0.0; x.len()]).collect();
        for k in 0..n {
            if k > 0 {
                let f = &self.phi[k * s..(k + 1) * s];
                for (ai, fi) in a.iter_mut().zip(f) {
                    for v in ai.iter_mut() {
                        *v *= fi;
                    }
                }
            }
            if !self.keep[k] || self.inv_sd[k] == 0.0 {
                continue;
            }
            // The prediction, summed state by state as `Iterator::sum`
            // does (from -0.0).
            let mut v = [-0.0f64; G];
            for ai in &a {
                for j in 0..G {
                    v[j] += ai[j];
                }
            }
            for (j, x) in xs.iter().enumerate() {
                v[j] = x.get(k).copied().unwrap_or(0.0) - v[j];
                if let Some(o) = out[j].get_mut(k) {
                    *o = v[j] * self.inv_sd[k];
                }
            }
            let g = &self.gain[k * s..(k + 1) * s];
            for (ai, gi) in a.iter_mut().zip(g) {
                for j in 0..G {
                    ai[j] += gi * v[j];
                }
            }
        }
        out
    }

    /// Sum of the logarithms of the innovation variances (the
    /// determinant in the likelihood).
    pub fn log_det(&self) -> f64 {
        self.log_det
    }

    /// Windows used.
    pub fn used(&self) -> usize {
        self.inv_sd.iter().filter(|v| **v > 0.0).count()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand_core::SeedableRng;
    use rand_distr::{Distribution, StandardNormal};

    fn windows(n: usize) -> Windows {
        let t: Vec<f64> = (0..n).map(|k| k as f64 + 0.5).collect();
        Windows::new(&t, 1.0)
    }

    #[test]
    fn white_noise_is_scaled_and_a_random_walk_differenced() {
        let win = windows(400);
        let keep = vec![true; 400];
        // White only: whitening divides by the standard deviation.
        let w = Whitener::new(
            &NoiseModel {
                white: 4.0,
                flicker: 0.0,
                random_walk: 0.0,
                markov: 0.0,
                markov_s: 1.0,
            },
            &win,
            &keep,
        );
        let x: Vec<f64> = (0..400).map(|k| k as f64).collect();
        let y = w.whiten(&x);
        assert!((y[7] - 3.5).abs() < 1e-12);
        // A pure random walk (no white noise to speak of): the innovations
        // are its increments over their standard deviation.
        let rw = NoiseModel {
            white: 1e-12,
            flicker: 0.0,
            random_walk: 0.25,
            markov: 0.0,
            markov_s: 1.0,
        };
        let w = Whitener::new(&rw, &win, &keep);
        let mut rng = rand_xoshiro::Xoshiro256PlusPlus::seed_from_u64(3);
        let mut level = 0.0;
        let walk: Vec<f64> = (0..400)
            .map(|_| {
                let z: f64 = StandardNormal.sample(&mut rng);
                level += 0.5 * z;
                level
            })
            .collect();
        let y = w.whiten(&walk);
        // GLS innovations of the model that made the data: unit variance.
        let var = y[1..].iter().map(|v| v * v).sum::<f64>() / 399.0;
        assert!((var - 1.0).abs() < 0.2, "{var}");
        for k in 2..400 {
            assert!(((walk[k] - walk[k - 1]) / 0.5 - y[k]).abs() < 1e-3);
        }
    }

    #[test]
    fn columns_whitened_together_are_whitened_alone() {
        let n = 3000;
        let win = windows(n);
        let keep: Vec<bool> = (0..n).map(|k| k % 97 != 5).collect();
        let m = NoiseModel {
            white: 2.0,
            flicker: 0.3,
            random_walk: 1e-3,
            markov: 0.5,
            markov_s: 40.0,
        };
        let w = Whitener::new(&m, &win, &keep);
        let cols: Vec<Vec<f64>> = (0..11)
            .map(|j| {
                (0..n - j)
                    .map(|k| ((k * (j + 3)) as f64 * 0.01).sin() + j as f64)
                    .collect()
            })
            .collect();
        let refs: Vec<&[f64]> = cols.iter().map(Vec::as_slice).collect();
        let many = w.whiten_many(&refs);
        for (c, got) in cols.iter().zip(&many) {
            let one = w.whiten(c);
            assert_eq!(one.len(), got.len());
            assert!(one.iter().zip(got).all(|(a, b)| a.to_bits() == b.to_bits()));
        }
    }

    #[test]
    fn markov_allan_variance_limits() {
        // Below T_c a random walk of K^2 = 2 sigma^2/T_c (K^2 tau/3), above
        // it white noise of N^2 = 2 sigma^2 T_c (N^2/tau).
        let tc = 100.0;
        let a = markov_avar(0.1, tc);
        assert!((a / (2.0 / tc * 0.1 / 3.0) - 1.0).abs() < 1e-3, "{a}");
        let b = markov_avar(1e5, tc);
        assert!((b / (2.0 * tc / 1e5) - 1.0).abs() < 2e-3, "{b}");
    }

    #[test]
    fn flicker_innovations_are_white() {
        // The project's flicker generator through the filter of the noise
        // model fitted to its own record: the standardised innovations
        // have unit variance and no lag-1 or long-range correlation left.
        let n = 20_000;
        let b = 1e-3;
        let mut g = gyro_sim::RateNoise::new(
            gyro_sim::NoiseParams {
                n_dps_rts: 3e-3,
                b_dps: b,
                flicker_max_tau_s: n as f64,
                ..Default::default()
            },
            1.0,
            11,
        );
        let x: Vec<f64> = (0..n).map(|_| g.sample()).collect();
        let win = windows(n);
        let keep = vec![true; n];
        let m = NoiseModel::from_residual(&x, &keep, 1.0);
        // The flicker found is the generator's, within its estimate's
        // scatter.
        assert!((m.flicker.sqrt() / b - 1.0).abs() < 0.5, "{m:?}");
        let y = Whitener::new(&m, &win, &keep).whiten(&x);
        let var = y.iter().map(|v| v * v).sum::<f64>() / n as f64;
        assert!((var - 1.0).abs() < 0.1, "{var}");
        let r1 = y.windows(2).map(|p| p[0] * p[1]).sum::<f64>() / (n as f64 * var);
        assert!(r1.abs() < 0.05, "{r1}");
        // Means of 500 innovations: their scatter is that of white noise.
        let blocks: Vec<f64> = y
            .chunks_exact(500)
            .map(|c| c.iter().sum::<f64>() / 500f64.sqrt())
            .collect();
        let bv = blocks.iter().map(|v| v * v).sum::<f64>() / blocks.len() as f64;
        assert!(bv < 2.0, "{bv}");
    }
}
