//! The IEEE 952 noise terms (docs/noise.md, physics.md section 3) and their
//! Allan variances:
//!
//! - five power laws, linear in c = (Q^2, N^2, B^2, K^2, R^2) >= 0:
//!   `3Q^2/tau^2 + N^2/tau + (2 ln2/pi) B^2 + K^2 tau/3 + R^2 tau^2/2`;
//! - a sinusoid of amplitude Omega0 and frequency f0:
//!   `Omega0^2 (sin^2(pi f0 tau) / (pi f0 tau))^2`, linear in Omega0^2;
//! - first-order Markov (exponentially correlated) noise of driving density
//!   q_c and correlation time T_c: `(q_c T_c)^2/tau (1 - T_c/(2 tau) (3 -
//!   4 e^(-tau/T_c) + e^(-2 tau/T_c)))`, linear in q_c^2; its stationary
//!   sigma is q_c sqrt(T_c/2), its white-noise limit (tau >> T_c) is an
//!   angle random walk N = q_c T_c, its short-tau limit a rate random walk
//!   K = q_c.
//!
//! The fit (fit.rs) works on the seven shapes by index: the five power laws
//! 0..4, [`SIN`] and [`MARKOV`], the last two at a frequency / correlation
//! time it searches.

/// The power-law terms.
pub const COUNT: usize = 5;
/// Index of the sinusoid and of the Markov term among the shapes.
pub const SIN: usize = 5;
pub const MARKOV: usize = 6;
/// All shapes.
pub const ALL: usize = 7;
/// JSON names (docs/interfaces.md) of the power-law terms.
pub const NAMES: [&str; COUNT] = [
    "quantization",
    "angle_random_walk_dpsh",
    "bias_instability_dph",
    "rate_random_walk",
    "rate_ramp",
];
/// The power-law terms as a person names them.
pub const PLAIN: [&str; COUNT] = [
    "quantization",
    "angle random walk",
    "bias instability",
    "rate random walk",
    "rate ramp",
];
/// JSON names of the two other terms.
pub const SIN_NAME: &str = "sinusoid";
pub const MARKOV_NAME: &str = "correlated";
/// Units of the reported values.
pub const UNITS: [&str; COUNT] = ["arcsec", "deg/sqrt(h)", "deg/h", "deg/h/sqrt(h)", "deg/h^2"];
/// Slopes of each term on the log-log Allan deviation.
pub const SLOPES: [&str; COUNT] = ["-1", "-1/2", "0", "+1/2", "+1"];
/// PSD exponent of the rate for the degrees of freedom.
pub const ALPHA: [i32; COUNT] = [2, 0, -1, -2, -2];
/// Confidence of every interval.
pub const CONF: f64 = 0.95;

/// The name of shape `j` (the noise type of an averaging time).
pub fn shape_name(j: usize) -> &'static str {
    match j {
        SIN => SIN_NAME,
        MARKOV => MARKOV_NAME,
        j => NAMES[j.min(COUNT - 1)],
    }
}

/// AVAR of power-law term j at tau for a unit coefficient (rate in deg/s,
/// tau in s).
pub fn basis(j: usize, tau: f64) -> f64 {
    match j {
        0 => 3.0 / (tau * tau),
        1 => 1.0 / tau,
        2 => 2.0 * std::f64::consts::LN_2 / std::f64::consts::PI,
        3 => tau / 3.0,
        _ => tau * tau / 2.0,
    }
}

/// AVAR of a sinusoid of unit amplitude (deg/s) at frequency `f` Hz.
pub fn sin_basis(f: f64, tau: f64) -> f64 {
    let x = std::f64::consts::PI * f * tau;
    if x < 1e-4 {
        // sin^2(x)/x -> x - x^3/3.
        let v = x - x * x * x / 3.0;
        return v * v;
    }
    let s = x.sin();
    let v = s * s / x;
    v * v
}

/// AVAR of first-order Markov noise of unit driving density (q_c = 1
/// deg/s/sqrt(s)) and correlation time `t` s.
pub fn markov_basis(t: f64, tau: f64) -> f64 {
    let x = tau / t;
    // 1 - (3 - 4e^-x + e^-2x)/(2x) = x^2/3 - x^3/4 + 7x^4/60 - x^5/24 + ...
    let g = if x < 1e-2 {
        x * x / 3.0 - x * x * x / 4.0 + 7.0 * x.powi(4) / 60.0 - x.powi(5) / 24.0
    } else {
        let a = (-x).exp_m1();
        let b = (-2.0 * x).exp_m1();
        1.0 - (-4.0 * a + b) / (2.0 * x)
    };
    t * t / tau * g
}

/// AVAR of shape j at tau for a unit coefficient, `f` and `t` the
/// sinusoid's frequency and the Markov correlation time, `tf` the time
/// constant of the filter that bands the white rate noise (0: none).
///
/// White noise through a first-order low-pass of time constant tf is
/// Markov noise of correlation time tf and q_c = N/tf: N^2/tau at tau >> tf,
/// less at the few shortest averaging times, where a sensor's output filter
/// shows.
pub fn shape(j: usize, tau: f64, f: f64, t: f64, tf: f64) -> f64 {
    match j {
        SIN => sin_basis(f, tau),
        MARKOV => markov_basis(t, tau),
        1 if tf > 0.0 => markov_basis(tf, tau) / (tf * tf),
        j => basis(j, tau),
    }
}

/// A coefficient c_j (deg^2, deg^2/s, (deg/s)^2, (deg/s)^2/s, (deg/s^2)^2)
/// in the reported unit.
pub fn to_units(j: usize, c: f64) -> f64 {
    let f = match j {
        0 => 3600.0,
        1 => 60.0,
        2 => 3600.0,
        3 => 3600.0 * 60.0,
        _ => 3600.0 * 3600.0,
    };
    c.max(0.0).sqrt() * f
}

/// The inverse of [`to_units`].
pub fn from_units(j: usize, v: f64) -> f64 {
    (v / to_units(j, 1.0)).powi(2)
}

/// Stationary sigma of the Markov term, deg/h, from q_c^2 ((deg/s)^2/s)
/// and T_c (s).
pub fn markov_sigma_dph(q2: f64, t: f64) -> f64 {
    (q2.max(0.0) * t / 2.0).sqrt() * 3600.0
}

/// q_c^2 from the stationary sigma (deg/h) and T_c (s).
pub fn markov_q2(sigma_dph: f64, t: f64) -> f64 {
    let s = sigma_dph / 3600.0;
    2.0 * s * s / t
}

/// The Markov term's white-noise limit N = q_c T_c, deg/sqrt(h).
pub fn markov_white_dpsh(q2: f64, t: f64) -> f64 {
    q2.max(0.0).sqrt() * t * 60.0
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn markov_limits_are_rate_random_walk_and_white_noise() {
        // tau << T: K^2 tau/3 with K = q_c; tau >> T: N^2/tau with N =
        // q_c T_c (IEEE 952 annex C).
        let t = 10.0;
        for tau in [1e-4, 1e-3, 1e-2] {
            let r = markov_basis(t, tau) / (tau / 3.0);
            assert!((r - 1.0).abs() < 1.0 * tau / t, "{tau}: {r}");
        }
        for tau in [1e4, 1e5] {
            let r = markov_basis(t, tau) / (t * t / tau);
            assert!((r - 1.0).abs() < 2.0 * t / tau, "{tau}: {r}");
        }
        // The series and the closed form meet at x = 0.01.
        let (a, b) = (markov_basis(1.0, 0.00999999), markov_basis(1.0, 0.01000001));
        assert!((a / b - 1.0).abs() < 1e-5, "{a} {b}");
    }

    #[test]
    fn sinusoid_bump_peaks_near_0_37_over_f() {
        // The bump's maximum: d/dx (sin^2 x / x) = 0 at x = 1.1656 (tan x =
        // 2x), tau = x/(pi f) = 0.371/f, where the ADEV is 0.7246 Omega0.
        let f = 2.0;
        let taus: Vec<f64> = (1..20000).map(|i| i as f64 * 1e-5).collect();
        let (i, v) = taus
            .iter()
            .map(|&t| sin_basis(f, t))
            .enumerate()
            .fold((0, 0.0), |b, (i, v)| if v > b.1 { (i, v) } else { b });
        assert!((taus[i] * f - 0.371).abs() < 1e-3, "{}", taus[i] * f);
        assert!((v.sqrt() - 0.7246).abs() < 1e-3, "{}", v.sqrt());
        // Zeros at whole periods.
        assert!(sin_basis(f, 1.0 / f) < 1e-20);
    }
}
