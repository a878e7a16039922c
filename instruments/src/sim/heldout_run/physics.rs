//! The second generator's physics: its profiles (a rate table with ramps
//! between plateaus in a staircase chamber, a FOG at rest in a sinusoidal
//! chamber, an RLG at rest with its own monoblock thermal model, a rate
//! swept through lock-in, vibration at 35 Hz), with the true temperatures
//! and their exact rates and curvatures.

use super::noise::Rng;
use rand_core::RngCore;

/// Earth rate, deg/s.
pub const EARTH_DPS: f64 = 15.041_07 / 3600.0;

/// The physical state over a run, before noise: true temperatures and
/// rates, row by row.
#[derive(Default, Clone)]
pub struct Physics {
    pub t: Vec<f64>,
    /// Mean input rate over each row, deg/s.
    pub w: Vec<f64>,
    /// Mean of w^2, w^3 and |w| over each row (the rate moves within a row
    /// on the ramps), and the mean squared acceleration.
    pub w2: Vec<f64>,
    pub w3: Vec<f64>,
    pub wabs: Vec<f64>,
    pub acc2: Vec<f64>,
    pub acc: Option<Vec<f64>>,
    /// True coil (FOG) or case (RLG) temperature and its exact rate and
    /// curvature; monoblocks A and B and the difference's exact rate.
    pub temp: Vec<f64>,
    pub temp_rate: Vec<f64>,
    pub temp_curv: Vec<f64>,
    pub mono: Option<(Vec<f64>, Vec<f64>, Vec<f64>)>,
}

/// A first-order lag driven by `u`, starting at `y0` at the first row,
/// exact for an input moving linearly between rows: (output, rate,
/// curvature) per row.
pub fn lag(t: &[f64], u: &[f64], tau: f64, y0: f64) -> (Vec<f64>, Vec<f64>, Vec<f64>) {
    let n = t.len();
    let mut y = vec![0.0; n];
    let mut yp = vec![0.0; n];
    let mut ypp = vec![0.0; n];
    let mut s = y0;
    for k in 0..n {
        let slope = if k == 0 {
            0.0
        } else {
            let dt = t[k] - t[k - 1];
            let e = (-dt / tau).exp();
            let slope = (u[k] - u[k - 1]) / dt.max(1e-12);
            // y' = (u - y)/tau with u = u0 + slope s over the step.
            s = u[k] - slope * tau + (s - u[k - 1] + slope * tau) * e;
            slope
        };
        y[k] = s;
        yp[k] = (u[k] - s) / tau;
        ypp[k] = (slope - yp[k]) / tau;
    }
    (y, yp, ypp)
}

/// Piecewise-linear profile through (time, value) corners.
pub fn corners(t: f64, pts: &[(f64, f64)]) -> f64 {
    if t <= pts[0].0 {
        return pts[0].1;
    }
    for w in pts.windows(2) {
        if t <= w[1].0 {
            let f = (t - w[0].0) / (w[1].0 - w[0].0);
            return w[0].1 + f * (w[1].1 - w[0].1);
        }
    }
    pts[pts.len() - 1].1
}

/// Staircase chamber air: `levels` degC, ramps at `rate` degC/min, soaks of
/// `soak` s, starting after 10 min at the first level.
pub fn staircase(levels: &[f64], rate: f64, soak: f64) -> Vec<(f64, f64)> {
    let mut p = vec![(0.0, levels[0]), (600.0, levels[0])];
    let mut t = 600.0;
    for w in levels.windows(2) {
        t += (w[1] - w[0]).abs() / rate * 60.0;
        p.push((t, w[1]));
        t += soak;
        p.push((t, w[1]));
    }
    p
}

/// Rows every `dt` over `dur`.
pub fn times(dt: f64, dur: f64) -> Vec<f64> {
    (1..=(dur / dt).round() as usize)
        .map(|k| k as f64 * dt)
        .collect()
}

/// Rate table: plateaus of `dwell` s at shuffled rates, joined by 2 s
/// linear transitions, a rest every fourth plateau; the coil in a
/// staircase chamber (lag 450 s). Row means of w, w^2, w^3, |w| from 8
/// sub-samples.
pub fn table(rng: &mut Rng, dt: f64, dur: f64) -> Physics {
    let mut rates = vec![3.0, 15.0, 45.0, 120.0, 250.0, 400.0];
    rates.extend(rates.clone().iter().map(|r| -r));
    for i in (1..rates.len()).rev() {
        let j = (rng.0.next_u64() % (i as u64 + 1)) as usize;
        rates.swap(i, j);
    }
    let dwell = 75.0;
    let mut plan = vec![];
    for (i, r) in rates
        .iter()
        .cycle()
        .take((dur / dwell) as usize + 2)
        .enumerate()
    {
        plan.push(if i % 4 == 3 { 0.0 } else { *r });
    }
    let rate_at = |s: f64| {
        let i = (s / dwell) as usize;
        let into = s - i as f64 * dwell;
        let prev = if i == 0 { 0.0 } else { plan[i - 1] };
        if into < 2.0 {
            prev + (plan[i] - prev) * into / 2.0
        } else {
            plan[i]
        }
    };
    let t = times(dt, dur);
    let mut ph = Physics {
        t: t.clone(),
        ..Default::default()
    };
    for &tk in &t {
        let (mut m1, mut m2, mut m3, mut ma) = (0.0, 0.0, 0.0, 0.0);
        for j in 0..8 {
            let w = rate_at(tk - dt + (j as f64 + 0.5) * dt / 8.0);
            m1 += w / 8.0;
            m2 += w * w / 8.0;
            m3 += w * w * w / 8.0;
            ma += w.abs() / 8.0;
        }
        ph.w.push(m1);
        ph.w2.push(m2);
        ph.w3.push(m3);
        ph.wabs.push(ma);
    }
    // Earth component on a vertical axis at 35 deg latitude.
    let e = EARTH_DPS * 35f64.to_radians().sin();
    for v in ph.w.iter_mut() {
        *v += e;
    }
    ph.acc2 = vec![0.0; t.len()];
    let air = staircase(&[-30.0, -5.0, 20.0, 45.0, 60.0], 1.5, 1200.0);
    let u: Vec<f64> = t.iter().map(|&x| corners(x, &air)).collect();
    let (y, yp, ypp) = lag(&t, &u, 450.0, -30.0);
    ph.temp = y;
    ph.temp_rate = yp;
    ph.temp_curv = ypp;
    ph
}

/// FOG at rest, the chamber swinging 25 +- 22 degC over 3 h (coil lag
/// 500 s); the axis at 35 deg latitude, 30 deg elevation.
pub fn fog_rest(dt: f64, dur: f64) -> Physics {
    let t = times(dt, dur);
    let u: Vec<f64> = t
        .iter()
        .map(|&x| 25.0 + 22.0 * (std::f64::consts::TAU * x / 10_800.0 - 1.0).sin())
        .collect();
    let y0 = u[0];
    let (y, yp, ypp) = lag(&t, &u, 500.0, y0);
    let e = EARTH_DPS
        * (30f64.to_radians().sin() * 35f64.to_radians().sin()
            + 30f64.to_radians().cos() * 35f64.to_radians().cos() * 0.5);
    let n = t.len();
    Physics {
        w: vec![e; n],
        w2: vec![e * e; n],
        w3: vec![e * e * e; n],
        wabs: vec![e.abs(); n],
        acc2: vec![0.0; n],
        t,
        temp: y,
        temp_rate: yp,
        temp_curv: ypp,
        ..Default::default()
    }
}

/// RLG at rest in a chamber (-30 -> 45 -> 10 degC at 1 degC/min, 40 min
/// soaks): the case 900 s behind the air and 4 degC of self-heating
/// (1200 s), monoblock A 1500 s behind the case plus 6 degC, B 2100 s
/// plus 4.5 degC.
pub fn rlg_chamber(dt: f64, dur: f64) -> Physics {
    let t = times(dt, dur);
    let air = staircase(&[-30.0, 45.0, 10.0], 1.0, 2400.0);
    let heat = |x: f64, a: f64, tau: f64| a * (1.0 - (-x / tau).exp());
    let u: Vec<f64> = t
        .iter()
        .map(|&x| corners(x, &air) + heat(x, 4.0, 1200.0))
        .collect();
    let (case, cp, cpp) = lag(&t, &u, 900.0, -30.0);
    let ua: Vec<f64> = t
        .iter()
        .zip(&case)
        .map(|(&x, c)| c + heat(x, 6.0, 1500.0))
        .collect();
    let ub: Vec<f64> = t
        .iter()
        .zip(&case)
        .map(|(&x, c)| c + heat(x, 4.5, 2100.0))
        .collect();
    let (a, ap, _) = lag(&t, &ua, 1500.0, -30.0);
    let (b, bp, _) = lag(&t, &ub, 2100.0, -30.0);
    let drate: Vec<f64> = ap.iter().zip(&bp).map(|(x, y)| x - y).collect();
    let e = EARTH_DPS * 35f64.to_radians().sin();
    let n = t.len();
    Physics {
        w: vec![e; n],
        w2: vec![e * e; n],
        w3: vec![e * e * e; n],
        wabs: vec![e; n],
        acc2: vec![0.0; n],
        t,
        temp: case,
        temp_rate: cp,
        temp_curv: cpp,
        mono: Some((a, b, drate)),
        ..Default::default()
    }
}

/// RLG rate swept continuously through lock-in: -2.5 -> +2.5 deg/s and
/// back over 300 s, twice; 20 Hz rows.
pub fn sweep(dt: f64, dur: f64) -> Physics {
    let t = times(dt, dur);
    let tri = |s: f64| {
        let p = (s / 300.0).fract();
        2.5 * (if p < 0.5 {
            4.0 * p - 1.0
        } else {
            3.0 - 4.0 * p
        })
    };
    let n = t.len();
    let mut ph = Physics {
        t: t.clone(),
        acc2: vec![0.0; n],
        ..Default::default()
    };
    for &tk in &t {
        let w = tri(tk - dt / 2.0);
        ph.w.push(w);
        ph.w2.push(w * w);
        ph.w3.push(w * w * w);
        ph.wabs.push(w.abs());
    }
    ph
}

/// FOG at rest under 35 Hz vibration switched between peak accelerations
/// every 40 s; 140 Hz rows (four a period): the rate's exact mean over
/// each, the acceleration sampled at its end, the rectification from the
/// exact mean of its square.
pub fn vibration(dt: f64, dur: f64) -> Physics {
    let t = times(dt, dur);
    let f = 35.0;
    let om = std::f64::consts::TAU * f;
    let levels = [0.0, 1500.0, 4000.0, 8000.0, 3000.0];
    let n = t.len();
    let mut ph = Physics {
        t: t.clone(),
        ..Default::default()
    };
    let mut acc = vec![];
    for &tk in &t {
        let eps = levels[((tk - dt / 2.0) / 40.0) as usize % levels.len()];
        let (a, b) = (tk - dt, tk);
        // Rate eps/om sin(om s): its mean; acceleration eps cos(om s): its
        // mean and the mean of its square.
        let wm = eps / om * ((om * a).cos() - (om * b).cos()) / (om * dt);
        // The acceleration as a sensor samples it, at the row's end.
        let am = eps * (om * b).cos();
        let a2 =
            eps * eps * (0.5 + ((2.0 * om * b).sin() - (2.0 * om * a).sin()) / (4.0 * om * dt));
        ph.w.push(wm);
        ph.w2.push(wm * wm);
        ph.w3.push(wm * wm * wm);
        ph.wabs.push(wm.abs());
        ph.acc2.push(a2);
        acc.push(am);
    }
    ph.acc = Some(acc);
    let _ = n;
    ph
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lag_is_exact_for_a_ramp() {
        // y' = (u - y)/tau, u = c t, y(0) = 0: y = c (t - tau (1 - e^(-t/tau))).
        let t: Vec<f64> = (0..100).map(|k| k as f64 * 3.0).collect();
        let u: Vec<f64> = t.iter().map(|x| 0.5 * x).collect();
        let (y, yp, _) = lag(&t, &u, 40.0, 0.0);
        for k in 0..100 {
            let want = 0.5 * (t[k] - 40.0 * (1.0 - (-t[k] / 40.0).exp()));
            assert!((y[k] - want).abs() < 1e-9, "{} {}", y[k], want);
            let wp = 0.5 * (1.0 - (-t[k] / 40.0).exp());
            assert!((yp[k] - wp).abs() < 1e-9);
        }
    }
}
