//! Equivalent degrees of freedom of the overlapping Allan variance for a
//! power-law noise, by Greenhall's algorithm (C. A. Greenhall and W. J.
//! Riley, "Uncertainty of stability variances based on finite
//! differences", PTTI 2003), and the chi-square interval it gives.
//!
//! Noise types by the exponent alpha of the rate's PSD (S_y ~ f^alpha):
//! angle quantization 2, angle random walk 0, bias instability (flicker
//! rate) -1, rate random walk -2 (a rate ramp is not noise: it is given
//! -2's degrees of freedom, the fewest).

use crate::numerics::stats::chi2_quantile;

/// Allan variance: second differences.
const D: f64 = 2.0;
/// Largest sum evaluated term by term before the asymptotic form.
const J_MAX: f64 = 100.0;

/// Greenhall's sw(t): the structure-function kernel of each noise type.
fn sw(t: f64, alpha: i32) -> f64 {
    let lg = |p: i32| {
        if t == 0.0 {
            0.0
        } else {
            t.powi(p) * t.abs().ln()
        }
    };
    match alpha {
        2 => -t.abs(),
        1 => lg(2),
        0 => t.abs().powi(3),
        -1 => lg(4),
        -2 => t.abs().powi(5),
        -3 => lg(6),
        _ => t.abs().powi(7),
    }
}

/// sx(t): the averaging filter of length 1/F applied (F infinite: the
/// limit, sw of alpha + 2).
fn sx(t: f64, f: f64, alpha: i32) -> f64 {
    if f.is_infinite() {
        return sw(t, alpha + 2);
    }
    f * f * (2.0 * sw(t, alpha) - sw(t - 1.0 / f, alpha) - sw(t + 1.0 / f, alpha))
}

/// sz(t): the second difference (d = 2).
fn sz(t: f64, f: f64, alpha: i32) -> f64 {
    6.0 * sx(t, f, alpha) - 4.0 * sx(t - 1.0, f, alpha) - 4.0 * sx(t + 1.0, f, alpha)
        + sx(t - 2.0, f, alpha)
        + sx(t + 2.0, f, alpha)
}

fn basic_sum(j: f64, m: f64, s: f64, f: f64, alpha: i32) -> f64 {
    let mut sum = sz(0.0, f, alpha).powi(2) + (1.0 - j / m) * sz(j / s, f, alpha).powi(2);
    for i in 1..j as usize {
        let i = i as f64;
        sum += 2.0 * (1.0 - i / m) * sz(i / s, f, alpha).powi(2);
    }
    sum
}

/// EDF of the overlapping Allan variance at averaging factor `m` of a
/// record of `n_phase` angle points (rate samples + 1), noise type `alpha`.
pub fn edf_oavar(alpha: i32, m: usize, n_phase: usize) -> f64 {
    let (mf, nf) = (m as f64, n_phase as f64);
    // Overlapping, unmodified: filter factor F = m, stride S = m.
    let (s, f) = (mf, mf);
    let l = mf / f + mf * D;
    let big_m = 1.0 + (s * (nf - l) / mf).floor();
    if big_m < 1.0 {
        return 1.0;
    }
    let j = big_m.min((D + 1.0) * s);
    let r = big_m / s;
    let inv = match alpha {
        a if a <= 0 => {
            if j <= J_MAX {
                // F infinite: a gyro's rate samples are means over their
                // interval, so its angle samples are exact points (Greenhall's
                // F = m models phase read through an averaging filter and
                // gives 8 % fewer degrees of freedom for white rate noise at
                // m = 10 than the exact sum, which the Monte Carlo below
                // confirms).
                let fp = f64::INFINITY;
                basic_sum(j, big_m, s, fp, a) / (sz(0.0, fp, a).powi(2) * big_m)
            } else if r > D + 1.0 {
                // Greenhall's table 2 (d = 2).
                let (a0, a1) = match a {
                    0 => (2.0 / 3.0, 1.0 / 3.0),
                    -1 => (0.852, 0.375),
                    _ => (1.079, 0.368),
                };
                (a0 - a1 / r) / r
            } else {
                let mp = J_MAX / r;
                basic_sum(J_MAX, J_MAX, mp, f64::INFINITY, a)
                    / (sz(0.0, f64::INFINITY, a).powi(2) * J_MAX)
            }
        }
        _ => {
            // White angle noise (alpha 2): Greenhall's closed form where
            // the record holds more than d strides, else NIST SP 1065's
            // (N+1)(N-2m)/(2(N-m)).
            if r.ceil() > D {
                let a0 = 70.0 / 36.0; // C(4d, 2d) / C(2d, d)^2
                let a1 = D / 2.0;
                (a0 - a1 / r) / big_m
            } else {
                2.0 * (nf - mf) / ((nf + 1.0) * (nf - 2.0 * mf))
            }
        }
    };
    if inv.is_finite() && inv > 0.0 {
        (1.0 / inv).max(1.0)
    } else {
        1.0
    }
}

/// Asymptotic degrees of freedom of the overlapping AVAR of first-order
/// Markov noise at tau = x T_c, per record length over tau (white noise
/// 3/2, a random walk 1/1.079): 2 AVAR^2 / Var with AVAR = 1/2 int S |H|^2
/// df and Var = (1/4T) int S^2 |H|^4 df (the spectral form that the
/// correlation of the estimates uses, uncertainty.rs), S = 1/(1 + (2 pi f
/// T_c)^2), |H|^2 = 4 sin^4(pi f tau)/(pi f tau)^2; scaled so that white
/// noise gives Greenhall's 3/2. It moves from the random walk's value to
/// white noise's slowly: 0.93 at x = 0.1, 0.98 at 1, 1.10 at 4, 1.23 at
/// 10, 1.42 at 50 (a share-weighted mix of the two, s = 1/(1 + x), gave up
/// to 23 % more near the Markov hump, intervals too narrow there).
pub fn markov_edf_per_length(x: f64) -> f64 {
    static TABLE: std::sync::OnceLock<Vec<f64>> = std::sync::OnceLock::new();
    const LO: f64 = -3.0;
    const STEPS: usize = 60;
    let table = TABLE.get_or_init(|| {
        let integrals = |tc: Option<f64>| {
            // tau = 1: frequencies 1e-6 .. 1e3, 80 a decade, |H|^2 by its
            // mean past x = 3 pi.
            let (k, dl) = (720usize, 10f64.ln() / 80.0);
            let (mut a, mut b) = (0.0, 0.0);
            for i in 0..=k {
                let f = 1e-6 * (dl * i as f64).exp();
                let sp = tc.map_or(1.0, |t| {
                    1.0 / (1.0 + (std::f64::consts::TAU * f * t).powi(2))
                });
                let x = std::f64::consts::PI * f;
                let (h2, h4) = if x > 3.0 * std::f64::consts::PI {
                    (1.5 / (x * x), 16.0 * 35.0 / 128.0 / x.powi(4))
                } else {
                    let v = 4.0 * x.sin().powi(4) / (x * x);
                    (v, v * v)
                };
                a += sp * h2 * f * dl;
                b += sp * sp * h4 * f * dl;
            }
            a * a / b
        };
        let white = integrals(None);
        (0..=STEPS)
            .map(|i| {
                let x = 10f64.powf(LO + 6.0 * i as f64 / STEPS as f64);
                1.5 * integrals(Some(1.0 / x)) / white
            })
            .collect()
    });
    let u = ((x.max(1e-300).log10() - LO) / 6.0 * STEPS as f64).clamp(0.0, STEPS as f64);
    let i = (u.floor() as usize).min(STEPS - 1);
    let t = u - i as f64;
    table[i] * (1.0 - t) + table[i + 1] * t
}

/// Two-sided `conf` interval of a deviation with `edf` degrees of freedom:
/// `dev * sqrt(edf / chi2(1 - a/2))` .. `dev * sqrt(edf / chi2(a/2))`.
pub fn interval(dev: f64, edf: f64, conf: f64) -> (f64, f64) {
    let a = 1.0 - conf;
    let lo = chi2_quantile(1.0 - a / 2.0, edf);
    let hi = chi2_quantile(a / 2.0, edf);
    (dev * (edf / lo).sqrt(), dev * (edf / hi).sqrt())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn markov_degrees_of_freedom_move_from_random_walk_to_white() {
        // Independent numerical integration (200 000-point grid, exact
        // |H|^2): 0.927 at x = 0.1, 0.983 at 1, 1.228 at 10, 1.419 at 50.
        for (x, want) in [(0.1, 0.927), (1.0, 0.983), (10.0, 1.228), (50.0, 1.419)] {
            let v = markov_edf_per_length(x);
            assert!((v / want - 1.0).abs() < 0.02, "{x}: {v} vs {want}");
        }
        assert!((markov_edf_per_length(1e-4) - 1.0 / 1.079).abs() < 0.01);
        assert!((markov_edf_per_length(1e4) - 1.5).abs() < 0.02);
    }

    /// Monte Carlo: the EDF of the estimator is 2 E[V]^2 / Var[V] over many
    /// records of exactly generated noise (white rate and rate random walk
    /// as the project's generator makes them, means over each sample
    /// interval; white angle): Greenhall's value within the Monte Carlo's
    /// 3 sigma.
    #[test]
    fn monte_carlo_degrees_of_freedom() {
        use rand_core::SeedableRng;
        use rand_distr::{Distribution, StandardNormal};
        let mut rng = rand_xoshiro::Xoshiro256PlusPlus::seed_from_u64(7);
        let mut seed = 0;
        let (n, seeds) = (1000usize, 3000usize);
        for alpha in [0, -2, 2] {
            for m in [2usize, 10, 50, 300] {
                let mut v = Vec::with_capacity(seeds);
                for _ in 0..seeds {
                    let w: Vec<f64> = (0..n + 1)
                        .map(|_| StandardNormal.sample(&mut rng))
                        .collect();
                    seed += 1;
                    let gen = |p: gyro_sim::NoiseParams| {
                        let mut g = gyro_sim::RateNoise::new(p, 1.0, seed);
                        (0..n).map(|_| g.sample()).collect::<Vec<f64>>()
                    };
                    let y: Vec<f64> = match alpha {
                        0 => gen(gyro_sim::NoiseParams {
                            n_dps_rts: 1.0,
                            ..Default::default()
                        }),
                        -2 => gen(gyro_sim::NoiseParams {
                            k_dps_rts: 1.0,
                            ..Default::default()
                        }),
                        _ => w.windows(2).map(|p| p[1] - p[0]).collect(),
                    };
                    v.push(super::super::adev::oavar(&y, &[m])[0]);
                }
                let mean = v.iter().sum::<f64>() / seeds as f64;
                let var = v.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (seeds - 1) as f64;
                let mc = 2.0 * mean * mean / var;
                let g = edf_oavar(alpha, m, n + 1);
                // The estimate of 2 mu^2/var from `seeds` draws: relative
                // standard error about sqrt(2/seeds) (plus kurtosis).
                let tol = 3.0 * (2.0 / seeds as f64).sqrt() * 1.5;
                eprintln!("alpha {alpha} m {m}: Greenhall {g:.2}, Monte Carlo {mc:.2}");
                assert!(
                    (g / mc - 1.0).abs() < tol,
                    "alpha {alpha} m {m}: {g} vs {mc}"
                );
            }
        }
    }
}
