//! The third generator's temperatures: chamber air profiles, thermal lags
//! in series (air -> housing -> coil for a FOG; air and self-heating ->
//! case -> two monoblocks for an RLG; a die heating itself for a MEMS
//! gyro), each with its exact first and second time derivatives, and the
//! sensors that read them (their own lag, noise and quantisation).

use super::rng::Rng;

/// A temperature over the rows and its exact first and second derivatives
/// (degC, degC/s, degC/s^2).
#[derive(Clone, Debug, Default)]
pub struct Temp {
    pub v: Vec<f64>,
    pub d1: Vec<f64>,
    pub d2: Vec<f64>,
}

/// A first-order lag of time constant `tau` driven by `u` (with its
/// derivatives), from `y0`: y' = (u - y)/tau, integrated exactly between
/// rows for an input moving linearly there; y'' = (u' - y')/tau.
pub fn lag(t: &[f64], u: &Temp, tau: f64, y0: f64) -> Temp {
    let n = t.len();
    let mut out = Temp {
        v: Vec::with_capacity(n),
        d1: Vec::with_capacity(n),
        d2: Vec::with_capacity(n),
    };
    let mut y = y0;
    for k in 0..n {
        if k > 0 {
            let h = t[k] - t[k - 1];
            let a = (u.v[k] - u.v[k - 1]) / h.max(1e-12);
            // With x = y - u + a tau: x' = -x/tau over the step.
            let x0 = y - u.v[k - 1] + a * tau;
            y = u.v[k] - a * tau + x0 * (-h / tau).exp();
        }
        let d1 = (u.v[k] - y) / tau;
        out.v.push(y);
        out.d1.push(d1);
        out.d2.push((u.d1[k] - d1) / tau);
    }
    out
}

/// Piecewise-linear air through `(time, degC)` corners, with its slope.
pub fn air(t: &[f64], corners: &[(f64, f64)]) -> Temp {
    let at = |s: f64| -> (f64, f64) {
        if s <= corners[0].0 {
            return (corners[0].1, 0.0);
        }
        for w in corners.windows(2) {
            if s <= w[1].0 {
                let slope = (w[1].1 - w[0].1) / (w[1].0 - w[0].0).max(1e-9);
                return (w[0].1 + slope * (s - w[0].0), slope);
            }
        }
        (corners[corners.len() - 1].1, 0.0)
    };
    let (v, d1): (Vec<f64>, Vec<f64>) = t.iter().map(|&s| at(s)).unzip();
    let n = t.len();
    Temp {
        v,
        d1,
        d2: vec![0.0; n],
    }
}

/// `base` plus a self-heating rise `h (1 - exp(-t/tau))`.
pub fn plus_heating(t: &[f64], base: &Temp, h: f64, tau: f64) -> Temp {
    let mut o = base.clone();
    for (k, &s) in t.iter().enumerate() {
        let e = (-s / tau).exp();
        o.v[k] += h * (1.0 - e);
        o.d1[k] += h * e / tau;
        o.d2[k] -= h * e / (tau * tau);
    }
    o
}

/// A chamber that soaks at `levels` (degC), moving between them at `rate`
/// degC/min, each soak `soak_s`, after `start_s` at the first.
pub fn soaks(levels: &[f64], rate: f64, soak_s: &[f64], start_s: f64) -> Vec<(f64, f64)> {
    let mut c = vec![(0.0, levels[0]), (start_s, levels[0])];
    let mut s = start_s;
    for (i, w) in levels.windows(2).enumerate() {
        s += (w[1] - w[0]).abs() / rate * 60.0;
        c.push((s, w[1]));
        s += soak_s[i % soak_s.len()];
        c.push((s, w[1]));
    }
    c
}

/// A temperature sensor: its own lag, white noise and quantisation step.
#[derive(Clone, Copy, Debug)]
pub struct Sensor {
    pub lag_s: f64,
    pub noise_c: f64,
    pub step_c: f64,
}

impl Sensor {
    /// One of the sensors a rig carries: a 0.01 degC digital sensor, a
    /// 1/16 degC one, a 0.1 degC one.
    pub fn draw(rng: &mut Rng) -> Self {
        let step = [0.01, 0.0625, 0.1][rng.pick(3)];
        Self {
            lag_s: rng.between(2.0, 20.0),
            noise_c: rng.between(0.002, 0.02),
            step_c: step,
        }
    }

    /// What it reads of `x` at the rows `t`.
    pub fn read(&self, t: &[f64], x: &Temp, rng: &mut Rng) -> Vec<f64> {
        let y0 = x.v.first().copied().unwrap_or(0.0);
        let lagged = lag(t, x, self.lag_s, y0);
        lagged
            .v
            .iter()
            .map(|v| ((v + self.noise_c * rng.normal()) / self.step_c).round() * self.step_c)
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lag_of_a_ramp_matches_the_closed_form() {
        // u = c t, y(0) = 0: y = c (t - tau (1 - e^(-t/tau))),
        // y' = c (1 - e^(-t/tau)), y'' = c e^(-t/tau)/tau.
        let t: Vec<f64> = (0..500).map(|k| k as f64 * 2.0).collect();
        let c = 0.02;
        let u = Temp {
            v: t.iter().map(|s| c * s).collect(),
            d1: vec![c; t.len()],
            d2: vec![0.0; t.len()],
        };
        let tau = 150.0;
        let y = lag(&t, &u, tau, 0.0);
        for k in [0, 1, 37, 250, 499] {
            let e = (-t[k] / tau).exp();
            assert!((y.v[k] - c * (t[k] - tau * (1.0 - e))).abs() < 1e-9);
            assert!((y.d1[k] - c * (1.0 - e)).abs() < 1e-12);
            assert!((y.d2[k] - c * e / tau).abs() < 1e-12);
        }
    }
}
