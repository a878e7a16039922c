//! Lock-in rate from a fringe record by the exact harmonic relation
//! (docs/rlg.md).
//!
//! The periodic solution of the lock-in equation makes `exp(i*psi)` a Moebius
//! transform of a uniform rotation `z = exp(i*theta)`, `theta = w*t + theta0`:
//! `exp(i*psi) = exp(i*gamma) * (z + rho)/(1 + rho*z)`
//! `           = exp(i*gamma) * (rho + (1 - rho^2) * sum_n (-rho)^(n-1) z^n)`,
//! so the harmonics fall off geometrically with ratio rho and the beat is
//! `f = w/(2*pi)`. Then `Omega_L = 2*rho/(1 - rho^2) * f/K` and
//! `Omega_I = (1 + rho^2)/(1 - rho^2) * f/K`: no input rate needed.
//!
//! Estimation: (1) a Hann-windowed spectrum gives the beat frequency and the
//! complex amplitudes of the first two harmonics (rho and the phases to start
//! from); (2) the closed form above, `S = A*Im(exp(i*gamma)*w(theta)) + c`, is
//! fitted to the record by Levenberg-Marquardt over (A, c, phase, theta0, rho,
//! w). The fit uses every harmonic at once and is not biased by spectral
//! leakage, aliasing of the upper harmonics or noise in the magnitudes, which
//! limit the plain harmonic ratio. Its covariance gives the uncertainty.

use super::warning::Warning;
use nalgebra::{SMatrix, SVector};
use num_complex::Complex64 as C;
use realfft::RealFftPlanner;
use std::f64::consts::{PI, TAU};

/// What the estimate of one channel found.
#[derive(Clone, Debug, serde::Serialize)]
pub struct ChannelFit {
    /// Harmonic ratio rho = A(n+1)/A(n).
    pub rho: f64,
    /// One-sigma uncertainty of rho from the fit covariance.
    pub rho_std: f64,
    pub beat_hz: f64,
    pub beat_std_hz: f64,
    pub amplitude: f64,
    /// rho from the plain ratio of the windowed spectrum's first two harmonics.
    pub rho_spectrum: f64,
    /// |A2/A1| of the spectrum, as the published approximate formula uses it.
    pub a2_over_a1: f64,
    /// RMS of the fit residual (the noise, when the model holds).
    pub residual_rms: f64,
    /// Complex fundamental amplitude (time origin at the record's middle).
    pub fundamental: (f64, f64),
    /// Samples, and the white noise under the fit's residual (the median
    /// of its spectrum: what the residual's RMS reaches when the model
    /// leaves nothing but noise).
    pub samples: usize,
    pub noise_rms: f64,
    /// The fitted model: A, c, phi, theta0, rho, w (see [`fringe_model`]),
    /// time origin `t_mid`.
    #[serde(skip)]
    pub params: [f64; 6],
    #[serde(skip)]
    pub t_mid: f64,
}

/// The fitted fringe model at time `t`: `A*Im(exp(i*phi')*w(theta)) + c`
/// with the parameters of [`ChannelFit::params`].
pub fn fringe_model(p: &[f64; 6], t_mid: f64, t: f64) -> f64 {
    let (a, c0, phi, th0, rho, w) = (p[0], p[1], p[2], p[3], p[4], p[5]);
    let u = C::from_polar(1.0, phi - th0);
    let z = C::from_polar(1.0, w * (t - t_mid) + th0);
    let wz = (z + rho) / (C::new(1.0, 0.0) + z * rho);
    a * (u * wz).im + c0
}

/// Amplitudes of the first `n` harmonics of the beat `f` (Hz) in the
/// record, Hann-windowed, its mean removed (one pass: each sample's phasor
/// raised to the harmonics by multiplication).
pub fn harmonic_amplitudes(t: &[f64], x: &[f64], f: f64, n: usize) -> Vec<f64> {
    let len = t.len();
    if len == 0 || n == 0 {
        return vec![];
    }
    let mean = x.iter().sum::<f64>() / len as f64;
    let tm = 0.5 * (t[0] + t[len - 1]);
    let mut acc = vec![C::new(0.0, 0.0); n];
    let mut wsum = 0.0;
    for (k, (&tk, &xk)) in t.iter().zip(x).enumerate() {
        let w = 0.5 - 0.5 * (TAU * (k as f64 + 0.5) / len as f64).cos();
        let z = C::from_polar(1.0, -TAU * f * (tk - tm));
        let mut zn = C::new((xk - mean) * w, 0.0);
        for a in acc.iter_mut() {
            zn *= z;
            *a += zn;
        }
        wsum += w;
    }
    acc.iter()
        .map(|a| (a * C::new(0.0, 2.0) / wsum).norm())
        .collect()
}

/// The white-noise RMS under a residual: the median of its Hann-windowed
/// periodogram (for white noise each bin is exponential, its median ln 2
/// times its mean), so a tone or structure left in the residual, which
/// lifts a few bins, does not lift it. Compared with the residual's RMS it
/// says whether the fit left anything but noise.
fn noise_floor_rms(r: &[f64]) -> f64 {
    let n = r.len();
    if n < 16 {
        return f64::NAN;
    }
    let win: Vec<f64> = (0..n)
        .map(|k| 0.5 - 0.5 * (TAU * (k as f64 + 0.5) / n as f64).cos())
        .collect();
    let mut buf: Vec<f64> = r.iter().zip(&win).map(|(x, w)| x * w).collect();
    let fft = RealFftPlanner::<f64>::new().plan_fft_forward(n);
    let mut spec = fft.make_output_vec();
    if fft.process(&mut buf, &mut spec).is_err() {
        return f64::NAN;
    }
    let mut p: Vec<f64> = spec[1..spec.len() - 1]
        .iter()
        .map(|c| c.norm_sqr())
        .collect();
    if p.is_empty() {
        return f64::NAN;
    }
    p.sort_by(f64::total_cmp);
    let w2: f64 = win.iter().map(|w| w * w).sum();
    (p[p.len() / 2] / std::f64::consts::LN_2 / w2).sqrt()
}

#[derive(Debug)]
pub enum EstimateError {
    TooShort,
    NoBeat,
    NoFit,
}

impl std::fmt::Display for EstimateError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            EstimateError::TooShort => "record too short: fewer than 64 samples",
            EstimateError::NoBeat => {
                "no beat in the record: the gyro is locked in, or the record holds fewer than 4 fringes"
            }
            EstimateError::NoFit => "the fringe model did not fit the record",
        })
    }
}

/// Windowed DTFT of `x` at frequency `f` (Hz) on the sample times `t`;
/// returns the complex amplitude C of a component `Im(C*exp(i*2*pi*f*(t - tm)))`.
fn harmonic(t: &[f64], x: &[f64], win: &[f64], f: f64, tm: f64) -> C {
    let mut acc = C::new(0.0, 0.0);
    let mut wsum = 0.0;
    for ((&tk, &xk), &wk) in t.iter().zip(x).zip(win) {
        acc += C::from_polar(xk * wk, -TAU * f * (tk - tm));
        wsum += wk;
    }
    // x = (C e^{i.} - conj(C) e^{-i.})/(2i): the DTFT picks C/(2i) per unit weight.
    acc * C::new(0.0, 2.0) / wsum
}

/// Beat frequency (Hz) from the peak of the Hann-windowed, zero-padded spectrum.
fn spectral_peak(x: &[f64], win: &[f64], dt: f64) -> Option<f64> {
    let n = x.len();
    let nfft = (4 * n).next_power_of_two();
    let mut buf = vec![0.0; nfft];
    for k in 0..n {
        buf[k] = x[k] * win[k];
    }
    let fft = RealFftPlanner::<f64>::new().plan_fft_forward(nfft);
    let mut spec = fft.make_output_vec();
    fft.process(&mut buf, &mut spec).ok()?;
    let mag: Vec<f64> = spec.iter().map(|c| c.norm()).collect();
    // Skip what the window leaves of the offset: below 4 fringes per record.
    let lo = (4 * nfft / n).max(3);
    let (kmax, _) = mag
        .iter()
        .enumerate()
        .take(mag.len() - 1)
        .skip(lo)
        .fold((0, 0.0), |b, (k, &m)| if m > b.1 { (k, m) } else { b });
    if kmax == 0 {
        return None;
    }
    let (a, b, c) = (
        mag[kmax - 1].max(1e-300).ln(),
        mag[kmax].max(1e-300).ln(),
        mag[kmax + 1].max(1e-300).ln(),
    );
    let den = a - 2.0 * b + c;
    let d = if den.abs() > 0.0 {
        (0.5 * (a - c) / den).clamp(-0.5, 0.5)
    } else {
        0.0
    };
    Some((kmax as f64 + d) / (nfft as f64 * dt))
}

/// Parameters of the fit: A, c, phi (= gamma + theta0), theta0, rho, w.
type P = SVector<f64, 6>;

struct Model<'a> {
    t: &'a [f64],
    x: &'a [f64],
    tm: f64,
}

impl Model<'_> {
    /// Sum of squared residuals; with `jac`, also J^T J and J^T r.
    fn eval(&self, p: &P, jac: Option<(&mut SMatrix<f64, 6, 6>, &mut P)>) -> f64 {
        let (a, c0, phi, th0, rho, w) = (p[0], p[1], p[2], p[3], p[4], p[5]);
        let u = C::from_polar(1.0, phi - th0);
        let mut cost = 0.0;
        let mut jj = SMatrix::<f64, 6, 6>::zeros();
        let mut jr = P::zeros();
        let want = jac.is_some();
        for (&tk, &xk) in self.t.iter().zip(self.x) {
            let dtk = tk - self.tm;
            let z = C::from_polar(1.0, w * dtk + th0);
            let den = C::new(1.0, 0.0) + z * rho;
            let wz = (z + rho) / den;
            let uw = u * wz;
            let r = xk - (a * uw.im + c0);
            cost += r * r;
            if want {
                let den2 = den * den;
                let dw_dth = C::new(0.0, 1.0 - rho * rho) * z / den2;
                let dw_drho = (C::new(1.0, 0.0) - z * z) / den2;
                let s_th = a * (u * dw_dth).im;
                let g = P::from([
                    uw.im,
                    1.0,
                    a * uw.re,
                    s_th - a * uw.re,
                    a * (u * dw_drho).im,
                    s_th * dtk,
                ]);
                jj.ger(1.0, &g, &g, 1.0);
                jr.axpy(r, &g, 1.0);
            }
        }
        if let Some((m, v)) = jac {
            *m = jj;
            *v = jr;
        }
        cost
    }
}

/// Levenberg-Marquardt from `p`: the parameters, the cost and J^T J there.
fn levenberg_marquardt(m: &Model, mut p: P) -> (P, f64, SMatrix<f64, 6, 6>) {
    let mut jj = SMatrix::<f64, 6, 6>::zeros();
    let mut jr = P::zeros();
    let mut cost = m.eval(&p, Some((&mut jj, &mut jr)));
    let mut lambda = 1e-3;
    for _ in 0..100 {
        let mut a = jj;
        for i in 0..6 {
            a[(i, i)] *= 1.0 + lambda;
        }
        let Some(step) = a.cholesky().map(|ch| ch.solve(&jr)) else {
            lambda *= 10.0;
            continue;
        };
        let mut q = p + step;
        q[4] = q[4].clamp(-0.99, 0.99);
        let c = m.eval(&q, None);
        if c.is_finite() && c <= cost {
            let done = (cost - c) <= 1e-12 * cost.max(1e-300);
            p = q;
            cost = m.eval(&p, Some((&mut jj, &mut jr)));
            lambda = (lambda * 0.3).max(1e-9);
            if done {
                break;
            }
        } else {
            lambda *= 10.0;
            if lambda > 1e12 {
                break;
            }
        }
    }
    (p, cost, jj)
}

/// Fits one fringe channel. `t` strictly increasing, seconds.
pub fn fit_channel(t: &[f64], x: &[f64]) -> Result<ChannelFit, EstimateError> {
    let n = t.len();
    if n < 64 {
        return Err(EstimateError::TooShort);
    }
    let dt = (t[n - 1] - t[0]) / (n - 1) as f64;
    let tm = 0.5 * (t[0] + t[n - 1]);
    let mean = x.iter().sum::<f64>() / n as f64;
    let xc: Vec<f64> = x.iter().map(|v| v - mean).collect();
    let win: Vec<f64> = (0..n)
        .map(|k| 0.5 - 0.5 * (TAU * (k as f64 + 0.5) / n as f64).cos())
        .collect();
    let f1 = spectral_peak(&xc, &win, dt).ok_or(EstimateError::NoBeat)?;
    if f1 * (t[n - 1] - t[0]) < 4.0 {
        return Err(EstimateError::NoBeat);
    }
    let c1 = harmonic(t, &xc, &win, f1, tm);
    let c2 = harmonic(t, &xc, &win, 2.0 * f1, tm);
    let a2_over_a1 = c2.norm() / c1.norm().max(1e-300);
    let rho0 = a2_over_a1.clamp(1e-4, 0.9);
    // Fundamental phase gamma + theta0; the second harmonic's is
    // gamma + 2*theta0 + pi.
    let phi = c1.arg();
    let th0 = c2.arg() - phi - PI;
    let p = P::from([
        c1.norm() / (1.0 - rho0 * rho0),
        mean,
        phi,
        th0,
        rho0,
        TAU * f1,
    ]);
    let m = Model { t, x, tm };
    let (p, cost, jj) = levenberg_marquardt(&m, p);
    if !cost.is_finite() {
        return Err(EstimateError::NoFit);
    }
    // A fringe stands well above the noise; a locked-in record's "fringe" is
    // noise the fit picked up.
    if p[0].abs() < 3.0 * (cost / n as f64).sqrt() {
        return Err(EstimateError::NoBeat);
    }
    // A negative rho is the same solution half a turn on (z -> -z).
    let rho = p[4].abs();
    let var = cost / (n.saturating_sub(6).max(1)) as f64;
    let params = [p[0], p[1], p[2], p[3], p[4], p[5]];
    let resid: Vec<f64> = t
        .iter()
        .zip(x)
        .map(|(&tk, &xk)| xk - fringe_model(&params, tm, tk))
        .collect();
    let cov = jj.try_inverse().map(|inv| inv * var);
    let sd = |i: usize| cov.map_or(f64::NAN, |c| c[(i, i)].max(0.0).sqrt());
    Ok(ChannelFit {
        rho,
        rho_std: sd(4),
        beat_hz: p[5].abs() / TAU,
        beat_std_hz: sd(5) / TAU,
        amplitude: p[0].abs(),
        rho_spectrum: rho0,
        a2_over_a1,
        residual_rms: var.sqrt(),
        fundamental: (c1.re, c1.im),
        samples: n,
        noise_rms: noise_floor_rms(&resid),
        params,
        t_mid: tm,
    })
}

/// Result of a lock-in measurement.
#[derive(Clone, Debug, serde::Serialize)]
pub struct LockIn {
    pub lock_in_dps: f64,
    /// One-sigma uncertainty of `lock_in_dps` from the fit.
    pub lock_in_std_dps: f64,
    /// Input rate: as given, else estimated from rho and the beat.
    pub input_rate_dps: f64,
    pub input_rate_given: bool,
    /// Input rate from rho and the beat (also when one was given).
    pub input_rate_est_dps: f64,
    pub beat_hz: f64,
    pub harmonic_ratio: f64,
    /// The published approximate formula `Omega_I/sqrt(1 + (A1/(2*A2))^2)` on
    /// the same record (with the input rate given, else the estimated one).
    pub lock_in_approx_dps: f64,
    /// |A2/A1| of the windowed spectrum (mean over the channels).
    pub a2_over_a1: f64,
    pub channels: usize,
    /// 95 % interval of the lock-in rate from the fit (+-1.96 sigma), deg/s.
    pub lock_in_ci_dps: [f64; 2],
    /// Omega_I/Omega_L of the estimate.
    pub rate_ratio: f64,
    /// The fit's relative one-sigma uncertainty of the lock-in rate, and
    /// the Cramer-Rao bound for this record (docs/lockin.md: sigma/(sqrt(N)
    /// A rho) from the pair with unknown offsets, sqrt(2) more from one
    /// channel; the small-lock-in form, exact for Omega_I/Omega_L >= 10).
    pub lock_in_rel_std: f64,
    pub cramer_rao_rel: f64,
    /// Residual RMS of the fit against the record's noise (second
    /// differences), means over the channels.
    pub residual_rms: f64,
    pub noise_rms: f64,
    pub samples: usize,
    pub duration_s: f64,
    pub warnings: Vec<Warning>,
    /// Each channel's fit.
    pub channel_fits: Vec<ChannelFit>,
}

/// The small-lock-in Cramer-Rao bound on the relative error of Omega_L
/// (docs/lockin.md): `sigma/(sqrt(N) A rho)` from the quadrature pair with
/// unknown offsets, sqrt(2) more from one channel.
pub fn cramer_rao_rel(noise_over_amplitude: f64, samples: usize, rho: f64, channels: usize) -> f64 {
    let one = if channels >= 2 { 1.0 } else { 2f64.sqrt() };
    one * noise_over_amplitude / ((samples.max(1) as f64).sqrt() * rho)
}

/// The harmonic ratio for Omega_I/Omega_L = `ratio` (> 1): r - sqrt(r^2 - 1).
pub fn rho_of_ratio(ratio: f64) -> f64 {
    ratio - (ratio * ratio - 1.0).max(0.0).sqrt()
}

/// A fit whose residual stands this far above the record's noise is
/// warned about; so is a relative one-sigma above [`INFORMATION_LIMIT`],
/// and a fit this far above its bound.
pub const RESIDUAL_OVER_NOISE: f64 = 1.2;
pub const INFORMATION_LIMIT: f64 = 0.005;
pub const OVER_BOUND: f64 = 1.5;

fn lockin_warnings(r: &LockIn) -> Vec<Warning> {
    let mut w = vec![];
    if r.residual_rms > RESIDUAL_OVER_NOISE * r.noise_rms {
        w.push(Warning::new(
            "residual_above_noise",
            format!(
                "the fit's residual ({:.3e} RMS) is {:.2} times the noise under it ({:.3e}, from its \
                 spectrum's median): the record holds more than the lock-in equation's fringe (a rate \
                 that changes during the record, a second mode, clipping)",
                r.residual_rms,
                r.residual_rms / r.noise_rms,
                r.noise_rms
            ),
        ));
    }
    if r.lock_in_rel_std > INFORMATION_LIMIT {
        w.push(Warning::new(
            "record_too_short",
            format!(
                "the record's information limits the lock-in rate to +-{:.2} % (one sigma) at \
                 Omega_I/Omega_L = {:.0}: a longer record, less noise, both photodiodes or a lower \
                 input rate would narrow it",
                100.0 * r.lock_in_rel_std,
                r.rate_ratio
            ),
        ));
    }
    if r.rate_ratio >= 10.0 && r.lock_in_rel_std > OVER_BOUND * r.cramer_rao_rel {
        w.push(Warning::new(
            "above_the_bound",
            format!(
                "the fit's uncertainty is {:.1} times the Cramer-Rao bound for this record",
                r.lock_in_rel_std / r.cramer_rao_rel
            ),
        ));
    }
    w
}

/// Lock-in from a record: one channel, or a quadrature pair (then the two fits
/// are averaged and the direction of rotation comes from their phase).
pub fn lock_in(
    t: &[f64],
    s: &[f64],
    q: Option<&[f64]>,
    pulses_per_deg: f64,
    input_rate_dps: Option<f64>,
) -> Result<LockIn, EstimateError> {
    let mut fits = vec![fit_channel(t, s)?];
    if let Some(q) = q {
        fits.push(fit_channel(t, q)?);
    }
    let nf = fits.len() as f64;
    let rho = fits.iter().map(|f| f.rho).sum::<f64>() / nf;
    let rho_std = (fits.iter().map(|f| f.rho_std.powi(2)).sum::<f64>()).sqrt() / nf;
    let beat = fits.iter().map(|f| f.beat_hz).sum::<f64>() / nf;
    let a21 = fits.iter().map(|f| f.a2_over_a1).sum::<f64>() / nf;
    // Q = A*cos(psi) leads S = A*sin(psi) by a quarter turn when psi increases.
    let sign = match fits.get(1) {
        Some(fq) => {
            let cs = C::new(fits[0].fundamental.0, fits[0].fundamental.1);
            let cq = C::new(fq.fundamental.0, fq.fundamental.1);
            if (cq / cs).arg() >= 0.0 {
                1.0
            } else {
                -1.0
            }
        }
        None => 1.0,
    };
    let fk = beat / pulses_per_deg;
    let g = 1.0 - rho * rho;
    let omega_i_est = sign * (1.0 + rho * rho) / g * fk;
    let (omega_i, given) = match input_rate_dps {
        Some(w) => (w, true),
        None => (omega_i_est, false),
    };
    // With the input rate given, Omega_L = 2*rho*Omega_I/(1 + rho^2); without,
    // from the beat. Both are the exact relation.
    let lock_in = if given {
        2.0 * rho * omega_i.abs() / (1.0 + rho * rho)
    } else {
        2.0 * rho / g * fk
    };
    let dl_drho = if given {
        2.0 * omega_i.abs() * (1.0 - rho * rho) / (1.0 + rho * rho).powi(2)
    } else {
        2.0 * (1.0 + rho * rho) / (g * g) * fk
    };
    let std = dl_drho * rho_std;
    let amp = fits.iter().map(|f| f.amplitude).sum::<f64>() / nf;
    let resid = fits.iter().map(|f| f.residual_rms).sum::<f64>() / nf;
    let noise = fits.iter().map(|f| f.noise_rms).sum::<f64>() / nf;
    let n = t.len();
    let mut r = LockIn {
        lock_in_dps: lock_in,
        lock_in_std_dps: std,
        input_rate_dps: omega_i,
        input_rate_given: given,
        input_rate_est_dps: omega_i_est,
        beat_hz: beat,
        harmonic_ratio: rho,
        lock_in_approx_dps: omega_i.abs() / (1.0 + (1.0 / (2.0 * a21)).powi(2)).sqrt(),
        a2_over_a1: a21,
        channels: fits.len(),
        lock_in_ci_dps: [lock_in - 1.96 * std, lock_in + 1.96 * std],
        rate_ratio: omega_i.abs() / lock_in,
        lock_in_rel_std: std / lock_in,
        cramer_rao_rel: cramer_rao_rel(resid / amp, n, rho, fits.len()),
        residual_rms: resid,
        noise_rms: noise,
        samples: n,
        duration_s: t.last().copied().unwrap_or(0.0) - t.first().copied().unwrap_or(0.0),
        warnings: vec![],
        channel_fits: fits,
    };
    r.warnings = lockin_warnings(&r);
    Ok(r)
}
