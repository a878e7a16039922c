//! The noise model's types (docs/noise.md): the shapes' coefficients, the
//! measured curve, a model fitted to it, the reported terms with their
//! intervals and the goodness of fit; and the degrees of freedom of a
//! mixture of noise types.

use super::edf::{edf_oavar, markov_edf_per_length};
use super::terms::{shape, ALL, ALPHA, COUNT, MARKOV, SIN};

/// The coefficients of the seven shapes (terms.rs: c_j >= 0, zero where
/// absent), the sinusoid's frequency (Hz), the Markov correlation time (s)
/// and the white noise's filter time constant (s, 0 where unfiltered).
#[derive(Clone, Copy, Debug, Default)]
pub struct Shapes {
    pub c: [f64; ALL],
    pub f: f64,
    pub t: f64,
    pub tf: f64,
}

impl Shapes {
    /// Shape j's part of the AVAR at tau.
    pub fn part(&self, j: usize, tau: f64) -> f64 {
        if self.c[j] > 0.0 {
            self.c[j] * self.unit(j, tau)
        } else {
            0.0
        }
    }
    pub fn at(&self, tau: f64) -> f64 {
        (0..ALL).map(|j| self.part(j, tau)).sum()
    }
    /// Shape j at tau for a unit coefficient.
    pub fn unit(&self, j: usize, tau: f64) -> f64 {
        shape(j, tau, self.f, self.t, self.tf)
    }
}

/// A value with its 95 % interval.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Interval {
    pub value: f64,
    pub lo: f64,
    pub hi: f64,
}

/// The sinusoid: amplitude deg/s, frequency Hz.
#[derive(Clone, Copy, Debug)]
pub struct Sinusoid {
    pub amplitude_dps: Interval,
    pub frequency_hz: Interval,
    pub reliable: bool,
}

/// The first-order Markov term: stationary sigma deg/h, correlation time
/// s; its white-noise limit N = q_c T_c (deg/sqrt(h)) and short-tau limit
/// K = q_c (deg/h/sqrt(h)).
#[derive(Clone, Copy, Debug)]
pub struct Correlated {
    pub sigma_dph: Interval,
    pub tau_s: Interval,
    pub white_limit_dpsh: Interval,
    pub reliable: bool,
}

#[derive(Clone, Debug)]
pub struct TermFit {
    /// The power laws (c units, terms.rs), present or not, with their
    /// intervals (honest: widened where the model misses, uncertainty.rs).
    pub c: [f64; COUNT],
    pub present: [bool; COUNT],
    pub lo: [f64; COUNT],
    pub hi: [f64; COUNT],
    /// False where the term dominates averaging times the model misses.
    pub reliable: [bool; COUNT],
    /// The bias instability is only bounded: the floor is not resolved (the
    /// curve does not turn up after it), so the flicker's level is at most
    /// the floor's reading, floor/0.664 (analysis.rs), and B's value and
    /// interval are held to it.
    pub bias_upper_bound: bool,
    pub sinusoid: Option<Sinusoid>,
    pub correlated: Option<Correlated>,
    /// The time constant of the filter the white rate noise passed (its
    /// curve bends below the -1/2 line at the shortest averaging times), s.
    pub arw_filter_s: Option<Interval>,
    /// Every shape's coefficient, the frequency and the correlation time.
    pub shapes: Shapes,
    /// Per averaging time: the model's AVAR, the shape dominating it
    /// (index into the shapes, terms::shape_name) and the degrees of
    /// freedom used.
    pub model: Vec<f64>,
    pub dominant: Vec<usize>,
    pub edf: Vec<f64>,
    /// The model against the measured intervals.
    pub goodness: Goodness,
}

impl TermFit {
    pub fn model_at(&self, tau: f64) -> f64 {
        self.shapes.at(tau)
    }
}

/// The measured curve: AVAR at taus (averaging factors ms) of a record of
/// n_phase angle points.
pub struct Curve<'a> {
    pub taus: &'a [f64],
    pub avar: &'a [f64],
    pub ms: &'a [usize],
    pub n_phase: usize,
}

impl Curve<'_> {
    pub fn n(&self) -> usize {
        self.taus.len()
    }
    pub fn tau0(&self) -> f64 {
        self.taus[0] / self.ms[0] as f64
    }
}

/// A model fitted at one frequency and correlation time: its shapes, the
/// shapes it may use, its AVAR and degrees of freedom per averaging time.
#[derive(Clone, Debug)]
pub struct Fitted {
    pub shapes: Shapes,
    pub active: [bool; ALL],
    pub model: Vec<f64>,
    pub edf: Vec<f64>,
}

impl Fitted {
    /// Whether shape j is in the model.
    pub fn has(&self, j: usize) -> bool {
        self.active[j] && self.shapes.c[j] > 0.0
    }
    /// Whether the white noise is filtered.
    pub fn filtered(&self) -> bool {
        self.has(1) && self.shapes.tf > 0.0
    }
    /// How many searched parameters the model has (frequency, correlation
    /// time, filter time constant).
    pub fn nonlinear(&self) -> usize {
        usize::from(self.has(SIN)) + usize::from(self.has(MARKOV)) + usize::from(self.filtered())
    }
}

/// Degrees of freedom of the Markov term's estimates at tau: a rate random
/// walk well below its correlation time, white noise well above; in
/// between, Greenhall's two combined as a mixture is, with the random
/// walk's weight s that gives the asymptotic value of the Markov spectrum
/// ([`markov_edf_per_length`]); Greenhall's finite-record forms at both
/// ends.
fn markov_inv_sqrt_edf(tau: f64, t: f64, m: usize, n_phase: usize) -> f64 {
    let (rw, white) = (1.0 / 1.079f64, 1.5f64);
    let rho = markov_edf_per_length(tau / t).clamp(rw, white);
    let s = ((1.0 / rho.sqrt() - 1.0 / white.sqrt()) / (1.0 / rw.sqrt() - 1.0 / white.sqrt()))
        .clamp(0.0, 1.0);
    s / edf_oavar(-2, m, n_phase).sqrt() + (1.0 - s) / edf_oavar(0, m, n_phase).sqrt()
}

/// One-sided PSD of the rate noise the shapes hold at `f` Hz, (deg/s)^2/Hz
/// (the sinusoid is a line, the ramp no noise), for rate samples `tau0`
/// apart: quantization 8 Q^2 sin^2(pi f tau0)/tau0 (white angle error of
/// variance Q^2, differenced), white 2 N^2 (through its filter, if any),
/// flicker B^2/(pi f), random walk K^2/(2 pi^2 f^2), Markov 2 q_c^2 T_c^2 /
/// (1 + (2 pi f T_c)^2): the h_alpha each shape's Allan variance
/// (terms.rs) stands for.
pub fn noise_psd(sh: &Shapes, f: f64, tau0: f64) -> f64 {
    use std::f64::consts::PI;
    let lp = |t: f64| 1.0 / (1.0 + (2.0 * PI * f * t).powi(2));
    let c = |j: usize| sh.c[j].max(0.0);
    let white = if sh.tf > 0.0 { lp(sh.tf) } else { 1.0 };
    8.0 * c(0) * (PI * f * tau0).sin().powi(2) / tau0
        + 2.0 * c(1) * white
        + c(2) / (PI * f)
        + c(3) / (2.0 * PI * PI * f * f)
        + 2.0 * c(MARKOV) * sh.t * sh.t * lp(sh.t)
}

/// The standard deviation of the sinusoid's beat with the noise in the AVAR
/// estimate at tau, for a record of `n_phase` angle points `tau0` apart.
/// Over the record the noise holds a component at the sinusoid's frequency,
/// in phase with it, of variance S(f)/T (S the one-sided PSD, T the
/// record's length): at every averaging time the estimate sees the
/// amplitude A + dA, so its AVAR A^2 u(tau) moves by 2 A u(tau) dA. The
/// beat is one random variable for the whole curve (fully correlated
/// between averaging times, uncertainty.rs), not a scatter of each
/// estimate's own.
pub fn sin_beat_sd(sh: &Shapes, tau: f64, tau0: f64, n_phase: usize) -> f64 {
    let a2 = sh.c[SIN];
    if a2 <= 0.0 {
        return 0.0;
    }
    let t = (n_phase.saturating_sub(1)).max(1) as f64 * tau0;
    2.0 * a2.sqrt() * sh.unit(SIN, tau) * (noise_psd(sh, sh.f, tau0) / t).sqrt()
}

/// Degrees of freedom of an estimate whose model is a mixture: each noise
/// type's share s_t with its own (Greenhall) degrees of freedom, combined
/// as if fully correlated, `1/sqrt(edf) = sum s_t / sqrt(edf_t)` (a
/// mixture's estimate is no steadier than its noisiest part). A sinusoid
/// adds no scatter of its own; its beat with the noise ([`sin_beat_sd`])
/// moves every estimate along the sinusoid's own shape, so it leaves the
/// residuals alone and is not counted here: the fit's weights and the
/// chi-square take 2 P_n^2 / edf_n, P_n the noise's part; the beat enters
/// the parameters' covariance and the measured intervals
/// (uncertainty.rs).
pub fn mixture_edf(sh: &Shapes, model: f64, tau: f64, m: usize, n_phase: usize) -> f64 {
    let mut s = 0.0;
    let mut noise = 0.0;
    for t in 0..ALL {
        let p = sh.part(t, tau);
        if p <= 0.0 || t == SIN {
            continue;
        }
        noise += p;
        let inv = if t == MARKOV {
            markov_inv_sqrt_edf(tau, sh.t, m, n_phase)
        } else {
            1.0 / edf_oavar(ALPHA[t], m, n_phase).sqrt()
        };
        s += p * inv;
    }
    if s <= 0.0 || noise <= 0.0 {
        return edf_oavar(0, m, n_phase);
    }
    let edf_n = (noise * noise / (s * s)).max(1.0);
    (model * model * edf_n / (noise * noise)).max(1.0)
}

/// The model against the measured curve.
#[derive(Clone, Debug, Default)]
pub struct Goodness {
    pub chi2: f64,
    /// Averaging times less fitted parameters.
    pub dof: f64,
    pub chi2_per_dof: f64,
    /// The largest chi-square per degree of freedom a right model gives in
    /// 99 % of records (correlated estimates: above 1 by more than the
    /// independent case).
    pub limit_per_dof: f64,
    pub consistent: bool,
    /// Indices of the averaging times where the model leaves the measured
    /// 95 % interval.
    pub outside: Vec<usize>,
    /// Normalised residuals (AVAR - model)/sd.
    pub z: Vec<f64>,
}
