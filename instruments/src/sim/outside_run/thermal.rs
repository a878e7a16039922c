//! The outside generator's temperatures: air programs whose transitions
//! are cosine-eased (smooth to the second derivative, unlike the straight
//! ramps of the other generators), thermal networks integrated by
//! classical Runge-Kutta (RK4) in sub-steps (the others integrate each lag
//! in closed form), the true temperatures with their first and second
//! derivatives taken from the network's own equations, and sensors (their
//! own lag inside the network, white noise, quantisation).

use super::rng::Rng;

/// A true temperature over the rows and its first and second time
/// derivatives (degC, degC/s, degC/s^2).
#[derive(Clone, Debug, Default)]
pub struct Temp {
    pub v: Vec<f64>,
    pub d1: Vec<f64>,
    pub d2: Vec<f64>,
}

/// An air temperature program: levels at corner times, with a
/// cosine-eased move from each corner's level to the next one's.
#[derive(Clone, Debug)]
pub struct Program {
    pub corners: Vec<(f64, f64)>,
}

impl Program {
    /// Value, first and second derivative at `t`.
    pub fn at(&self, t: f64) -> (f64, f64, f64) {
        let c = &self.corners;
        if c.is_empty() {
            return (20.0, 0.0, 0.0);
        }
        if t <= c[0].0 {
            return (c[0].1, 0.0, 0.0);
        }
        for w in c.windows(2) {
            let ((t0, a), (t1, b)) = (w[0], w[1]);
            if t <= t1 {
                let d = (t1 - t0).max(1e-9);
                let s = (t - t0) / d;
                let pi = std::f64::consts::PI;
                let h = b - a;
                return (
                    a + h * 0.5 * (1.0 - (pi * s).cos()),
                    h * pi / (2.0 * d) * (pi * s).sin(),
                    h * pi * pi / (2.0 * d * d) * (pi * s).cos(),
                );
            }
        }
        (c[c.len() - 1].1, 0.0, 0.0)
    }

    /// A chamber: a soak at `start`, then moves at `rate` degC/s (drawn
    /// per move within the range) to levels in [lo, hi] at least 8 degC
    /// apart, each followed by a soak, until `span` s.
    pub fn chamber(
        rng: &mut Rng,
        span: f64,
        start: f64,
        (lo, hi): (f64, f64),
        rate: (f64, f64),
        soak: (f64, f64),
    ) -> Self {
        let mut corners = vec![(0.0, start)];
        let mut t = rng.uniform(soak.0, soak.1) * 0.5;
        let mut level = start;
        corners.push((t, level));
        while t < span {
            let mut next = rng.uniform(lo, hi);
            for _ in 0..20 {
                if (next - level).abs() >= 8.0 {
                    break;
                }
                next = rng.uniform(lo, hi);
            }
            // The eased move's mean slope is the drawn rate.
            t += (next - level).abs() / rng.uniform(rate.0, rate.1);
            corners.push((t, next));
            level = next;
            t += rng.uniform(soak.0, soak.1);
            corners.push((t, level));
        }
        Self { corners }
    }

    /// A laboratory room: wandering by `amp` degC about `base`, a new
    /// level every 40 .. 100 min.
    pub fn room(rng: &mut Rng, span: f64, base: f64, amp: f64) -> Self {
        let mut corners = vec![(0.0, base)];
        let mut t = 0.0;
        while t < span {
            t += rng.uniform(2400.0, 6000.0);
            corners.push((t, base + rng.uniform(-amp, amp)));
        }
        Self { corners }
    }
}

/// States of the network dx/dt = f(t, x) at the rows t_k = k dt, by RK4
/// in `sub` steps per row.
pub fn integrate(
    n: usize,
    dt: f64,
    sub: usize,
    x0: &[f64],
    f: impl Fn(f64, &[f64], &mut [f64]),
) -> Vec<Vec<f64>> {
    let m = x0.len();
    let h = dt / sub.max(1) as f64;
    let mut x = x0.to_vec();
    let (mut k1, mut k2, mut k3, mut k4, mut y) = (
        vec![0.0; m],
        vec![0.0; m],
        vec![0.0; m],
        vec![0.0; m],
        vec![0.0; m],
    );
    let mut out = Vec::with_capacity(n);
    for k in 0..n {
        out.push(x.clone());
        for j in 0..sub.max(1) {
            let t = k as f64 * dt + j as f64 * h;
            f(t, &x, &mut k1);
            for i in 0..m {
                y[i] = x[i] + 0.5 * h * k1[i];
            }
            f(t + 0.5 * h, &y, &mut k2);
            for i in 0..m {
                y[i] = x[i] + 0.5 * h * k2[i];
            }
            f(t + 0.5 * h, &y, &mut k3);
            for i in 0..m {
                y[i] = x[i] + h * k3[i];
            }
            f(t + h, &y, &mut k4);
            for i in 0..m {
                x[i] += h / 6.0 * (k1[i] + 2.0 * k2[i] + 2.0 * k3[i] + k4[i]);
            }
        }
    }
    out
}

/// A sensor's reading: its lagged value plus white noise `sd`, quantised
/// to `step` degC.
pub fn read(lagged: &[f64], sd: f64, step: f64, rng: &mut Rng) -> Vec<f64> {
    lagged
        .iter()
        .map(|v| {
            let x = v + sd * rng.gauss();
            if step > 0.0 {
                (x / step).round() * step
            } else {
                x
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rk4_lag_matches_the_closed_form() {
        // y' = (u - y)/tau from 0 with u = 1: y = 1 - exp(-t/tau).
        let tau = 30.0;
        let xs = integrate(200, 1.0, 4, &[0.0], |_, x, d| d[0] = (1.0 - x[0]) / tau);
        for (k, x) in xs.iter().enumerate() {
            let want = 1.0 - (-(k as f64) / tau).exp();
            assert!((x[0] - want).abs() < 1e-9, "{k}");
        }
    }

    #[test]
    fn program_derivatives_are_those_of_its_values() {
        let mut rng = Rng::new(4, 4);
        let p = Program::chamber(
            &mut rng,
            20_000.0,
            22.0,
            (-10.0, 40.0),
            (0.01, 0.02),
            (900.0, 1800.0),
        );
        let h = 0.01;
        for k in 1..1000 {
            let t = k as f64 * 19.7;
            let (_, d1, d2) = p.at(t);
            let num1 = (p.at(t + h).0 - p.at(t - h).0) / (2.0 * h);
            let num2 = (p.at(t + h).1 - p.at(t - h).1) / (2.0 * h);
            assert!((d1 - num1).abs() < 1e-6, "{t}");
            assert!((d2 - num2).abs() < 1e-7, "{t}");
        }
    }
}
