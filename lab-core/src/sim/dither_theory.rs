//! What the physics predicts for a dithered RLG (physics.md 2.4,
//! docs/notes/issue-33-dither.md): the random walk the lock-in crossings
//! leave, and the mean rate error, from the crossing map.
//!
//! Each crossing of the lock-in band (a dither turnaround, rate slope
//! `Omega_dot = 2 pi f_d Omega_d sqrt(1 - (Omega/Omega_d)^2)`) kicks the
//! fringe phase by `-c sin(phi_n - s_n Y_n)` (Fresnel): `c = 2 pi K Omega_L
//! sqrt(1/(K Omega_dot))`, K in fringes per degree; `phi_n` the phase of
//! the input angle and the errors so far; `s_n` = +-1 alternating;
//! `Y_n = 2 pi K A_n - pi/4`, `A_n` the turnaround's amplitude (deg).
//! With the amplitude noise (relative rms `eps`, drawn per turnaround)
//! `Y_n` spreads by `sigma = 2 pi K A eps`:
//! - the kicks' random part has variance `c^2/2 (1 - e^(-sigma^2))` per
//!   crossing, two crossings per dither period: with `sigma` large,
//!   Killpatrick's `ARW^2 = Omega_L^2/(2 pi K Omega_d)` (deg^2/s, K fringes
//!   per degree) exactly;
//! - the kicks' mean part, `e^(-sigma^2/2)` of a pair's sum, is coherent
//!   where the input moves the phase a whole multiple of pi per crossing
//!   (`Omega = m f_d/K`: the dynamic lock-in zones), with strength
//!   `|cos Y|` (m even) or `|sin Y|` (m odd); near a zone the pair map is a
//!   Brownian particle on a tilted washboard: drift
//!   `f (delta - a sin phi)`, `a = 2 c e^(-sigma^2/2) g_m`, tilt `delta`
//!   the input's phase per pair off the zone, diffusion `f c^2 (1 -
//!   e^(-sigma^2))/2`. Its mean velocity and effective diffusion are exact
//!   integrals (Stratonovich; Reimann et al., PRL 87, 010602, 2001): the
//!   mean rate error and the long-time ARW. Far from a zone (or with sigma
//!   of a few radians) they are Killpatrick's; in a zone with little noise
//!   the phase is held (a residual lock-in: Tehrani and Soltanieh 2020).

use gyro_sim::DitherParams;
use std::f64::consts::PI;

/// The prediction for one set of parameters and input rate.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Prediction {
    /// The crossings' random walk, deg/sqrt(s): Killpatrick's times
    /// `sqrt(1 - e^(-sigma^2))` (the kicks' random part). What the Allan
    /// deviation shows at averaging times below the zone's relaxation time
    /// (all of them where the zone does not hold the phase).
    pub arw_dps_rts: f64,
    /// The long-time random walk (the washboard's effective diffusion),
    /// deg/sqrt(s): below the former where a zone holds the phase.
    pub arw_long_dps_rts: f64,
    /// The zone's relaxation time `1/(a f)`, s (infinite without a pull).
    pub relaxation_s: f64,
    /// Killpatrick's `Omega_L/sqrt(2 pi K Omega_d)` (K in fringes per
    /// degree), deg/sqrt(s).
    pub killpatrick_dps_rts: f64,
    /// Mean rate error (the nearest zone's pull, exact, and the others'
    /// tails), deg/s.
    pub rate_error_dps: f64,
    /// RMS of the fringe phase at a turnaround from the amplitude noise, rad.
    pub sigma_rad: f64,
    /// Nearest dynamic lock-in zone (input rate m f_d / K).
    pub zone: i64,
    /// The zone's residual lock-in rate (half width, deg/s): the pull's
    /// amplitude `a f / (2 pi K)`.
    pub residual_lock_in_dps: f64,
    /// Barrier over diffusion, `a f / D`: above about 1 the zone holds the phase.
    pub kappa: f64,
}

/// The prediction at input rate `rate_dps`.
pub fn predict(p: &DitherParams, rate_dps: f64) -> Prediction {
    let k = p.fringes_per_deg();
    let f = p.dither_hz;
    let amp = p.amplitude_deg();
    let sigma = p.crossing_phase_rms_rad();
    let slope = p.omega_dot() * (1.0 - (rate_dps / p.dither_dps).powi(2)).max(1e-6).sqrt();
    let c = 2.0 * PI * k * p.lock_in_dps * (1.0 / (k * slope)).sqrt();
    let nu = PI * k * rate_dps / f;
    let zone = (nu / PI).round();
    let delta = 2.0 * (nu - zone * PI);
    let y = 2.0 * PI * k * amp - PI / 4.0;
    let g = if (zone as i64).rem_euclid(2) == 0 {
        y.cos().abs()
    } else {
        y.sin().abs()
    };
    let coherent = (-sigma * sigma / 2.0).exp();
    let random = 1.0 - (-sigma * sigma).exp();
    // Per second: pull amplitude, tilt, diffusion (rad, rad/s, rad^2/s).
    let a = 2.0 * c * coherent * g * f;
    let tilt = delta * f;
    let d = f * c * c * random / 2.0;
    let (v, d_eff) = washboard(a, tilt, d);
    // The other zones pull too, each by its second-order tail (a noisy
    // Adler far from lock: -(a^2/2) F/(F^2 + D^2)); summed in pairs
    // either side, the sum converges.
    let mut far = 0.0;
    for j in 1..=64 {
        for m in [zone - j as f64, zone + j as f64] {
            let gm = if (m as i64).rem_euclid(2) == 0 {
                y.cos().abs()
            } else {
                y.sin().abs()
            };
            let am = 2.0 * c * coherent * gm * f;
            let fm = 2.0 * (nu - m * PI) * f;
            far -= 0.5 * am * am * fm / (fm * fm + d * d);
        }
    }
    let to_deg = 1.0 / (2.0 * PI * k);
    Prediction {
        arw_dps_rts: (2.0 * d).max(0.0).sqrt() * to_deg,
        arw_long_dps_rts: (2.0 * d_eff).max(0.0).sqrt() * to_deg,
        relaxation_s: if a > 0.0 { 1.0 / a } else { f64::INFINITY },
        killpatrick_dps_rts: p.killpatrick_arw_dps_rts(),
        rate_error_dps: (v - tilt + far) * to_deg,
        sigma_rad: sigma,
        zone: zone as i64,
        residual_lock_in_dps: a * to_deg,
        kappa: if d > 0.0 { a / d } else { f64::INFINITY },
    }
}

/// Mean velocity and effective diffusion of `dx/dt = -a sin x + F +
/// sqrt(2 D) xi` (period 2 pi): `v = 2 pi (1 - e^(-2 pi F/D)) / int I+`,
/// `D_eff = D <I+^2 I-> / <I+>^3` with `I+(x) = (1/D) int_0^2pi
/// exp((V(x) - V(x-y) - F y)/D) dy`, `I-(x) = (1/D) int_0^2pi
/// exp((V(x+y) - V(x) - F y)/D) dy`, `V = -a cos x`. Exponents are taken relative to
/// their largest (the integrals' ratio is scale free); without noise the
/// deterministic Adler answer.
pub fn washboard(a: f64, tilt: f64, d: f64) -> (f64, f64) {
    if a == 0.0 {
        return (tilt, d);
    }
    if d <= 0.0 || !(a / d).is_finite() {
        let v = if tilt.abs() > a.abs() {
            tilt.signum() * (tilt * tilt - a * a).sqrt()
        } else {
            0.0
        };
        return (v, 0.0);
    }
    // Enough points across the wells' width sqrt(D/a).
    let n = (32.0 * (a.abs() / d).sqrt()).clamp(256.0, 2048.0) as usize;
    let h = 2.0 * PI / n as f64;
    let pot = |x: f64| -a * x.cos();
    // The exponents at (x_i, y_j), their largest first (one scale for all).
    let e_plus = |i: usize, j: usize| {
        let (x, y) = (i as f64 * h, j as f64 * h);
        (pot(x) - pot(x - y) - tilt * y) / d
    };
    let e_minus = |i: usize, j: usize| {
        let (x, y) = (i as f64 * h, j as f64 * h);
        (pot(x + y) - pot(x) - tilt * y) / d
    };
    let mut top = f64::NEG_INFINITY;
    for i in 0..n {
        for j in 0..=n {
            top = top.max(e_plus(i, j)).max(e_minus(i, j));
        }
    }
    // In y the exponent is taken linear across each cell and integrated
    // exactly (the integrand is not periodic in y with a tilt, and a tilt
    // far above D makes it fall by many e-folds within one cell, where a
    // trapezoid fails), scaled by e^-top; the sums in x are periodic
    // (spectral).
    let integral = |e: &dyn Fn(usize, usize) -> f64, i: usize| {
        let mut s = 0.0;
        let mut e0 = e(i, 0) - top;
        for j in 1..=n {
            let e1 = e(i, j) - top;
            let de = e1 - e0;
            s += if de.abs() < 1e-6 {
                0.5 * (e0.exp() + e1.exp())
            } else {
                (e1.exp() - e0.exp()) / de
            };
            e0 = e1;
        }
        s * h / d
    };
    let ip: Vec<f64> = (0..n).map(|i| integral(&e_plus, i)).collect();
    let im: Vec<f64> = (0..n).map(|i| integral(&e_minus, i)).collect();
    let mean_ip = ip.iter().sum::<f64>() / n as f64;
    let mean_ip2im = ip.iter().zip(&im).map(|(p, m)| p * p * m).sum::<f64>() / n as f64;
    // The scale e^-top cancels in D_eff (3 factors over 3); v needs it
    // back: v = (1 - e^(-2 pi F/D)) / <I+> with <I+> unscaled.
    let d_eff = d * mean_ip2im / mean_ip.powi(3);
    let log_mean_ip = mean_ip.ln() + top;
    // v = (1 - e^x) e^(-log <I+>), x = -2 pi F/D: |1 - e^x| in logs (x
    // reaches thousands far from a zone, where e^x overflows).
    let x = -2.0 * PI * tilt / d;
    let ln_abs_numer = if x > 0.0 {
        x + (-(-x).exp()).ln_1p()
    } else {
        (-x.exp_m1()).ln()
    };
    let v = if tilt == 0.0 {
        0.0
    } else {
        tilt.signum() * (ln_abs_numer - log_mean_ip).exp()
    };
    (v, d_eff)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Free diffusion with drift; the Lifson-Jackson result at zero tilt
    /// (`D_eff = D / I0(a/D)^2`); the Stratonovich velocity of a weakly
    /// tilted, strongly held washboard is tiny, far above the barrier it is
    /// the Adler beat.
    #[test]
    fn washboard_limits() {
        let (v, de) = washboard(0.0, 3.0, 0.7);
        assert!((v - 3.0).abs() < 1e-12 && (de - 0.7).abs() < 1e-12);
        for &(a, d) in &[(1.0, 1.0), (2.0, 0.5), (0.3, 1.0)] {
            let (_, de) = washboard(a, 0.0, d);
            // I0 by its series.
            let z = a / d;
            let mut i0 = 0.0;
            let mut term = 1.0;
            for k in 0..60 {
                if k > 0 {
                    term *= (z / 2.0).powi(2) / (k * k) as f64;
                }
                i0 += term;
            }
            let want = d / (i0 * i0);
            assert!((de - want).abs() < 1e-6 * want, "{a} {d}: {de} vs {want}");
        }
        let (v, _) = washboard(1.0, 0.2, 0.01);
        assert!(v.abs() < 1e-6, "held: {v}");
        let adler = (25.0f64 - 1.0).sqrt();
        for sign in [1.0, -1.0] {
            // Either way, and at 10^4 e-folds of the tilt over D.
            for d in [0.01, 0.001] {
                let (v, _) = washboard(1.0, 5.0 * sign, d);
                assert!(
                    (v - sign * adler).abs() < 1e-3 * adler,
                    "{d}: {v} vs {adler}"
                );
            }
        }
    }

    /// With the crossings randomised the prediction is Killpatrick's.
    #[test]
    fn randomised_is_killpatrick() {
        let p = DitherParams {
            counts_per_deg: 4000.0,
            lock_in_dps: 0.1,
            dither_dps: 200.0,
            dither_hz: 400.0,
            noise_frac: 0.05,
            ..Default::default()
        };
        let q = predict(&p, 0.0);
        assert!(q.sigma_rad > 10.0);
        assert!((q.arw_dps_rts / q.killpatrick_dps_rts - 1.0).abs() < 1e-9);
        assert!((q.arw_long_dps_rts / q.killpatrick_dps_rts - 1.0).abs() < 1e-9);
        assert!(q.rate_error_dps.abs() < 1e-12);
    }
}
