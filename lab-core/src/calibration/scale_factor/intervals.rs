//! The 95 % intervals of the continuous fit's non-linear parameters, by
//! profile likelihood: each knee with the lag re-fitted (the rate noise),
//! widened in quadrature by the coil-temperature estimate's own noise; the
//! lag with the knees re-fitted locally.

use super::continuous_model::{knee_bounds, Candidate, Model};
use super::input::{zero_phase_derivative, SfInput};
use super::result::Interval;
use crate::numerics::search::{golden, profile_interval};
use gyro_sp::fog::scale_factor::LEAD_FILTER_TAU_S;

/// Standard deviation of the coil-temperature estimate's noise, degC: the
/// sensor's white noise (from its second differences, robustly: the
/// chamber's own curvature is far below it) through `T_s + lag * D`, whose
/// impulse response is taken from the same filters.
fn coil_estimate_noise(inp: &SfInput, lag: f64) -> f64 {
    let n = inp.t.len();
    if n < 10 {
        return 0.0;
    }
    let mut d2: Vec<f64> = (1..n - 1)
        .map(|k| (inp.ts[k + 1] - 2.0 * inp.ts[k] + inp.ts[k - 1]).abs())
        .collect();
    d2.sort_by(f64::total_cmp);
    let sigma_s = 1.4826 * d2[d2.len() / 2] / 6f64.sqrt();
    let mut h: Vec<f64> = inp.t.windows(2).map(|w| w[1] - w[0]).collect();
    h.sort_by(f64::total_cmp);
    let dt = h[h.len() / 2];
    let m = ((20.0 * LEAD_FILTER_TAU_S / dt) as usize).clamp(50, 20_001) | 1;
    let t: Vec<f64> = (0..m).map(|k| k as f64 * dt).collect();
    let mut x = vec![0.0; m];
    x[m / 2] = 1.0;
    let d = zero_phase_derivative(&t, &x);
    let energy: f64 = (0..m).map(|k| (x[k] + lag * d[k]).powi(2)).sum();
    sigma_s * energy.sqrt()
}

/// How often the bins' coil temperature at `lag` crosses `knee` (a 1 degC
/// dead band around it), at least once.
fn crossings(m: &Model, lag: f64, knee: f64) -> usize {
    let mut side: Option<bool> = None;
    let mut count = 0usize;
    for i in 0..m.b.w.len() {
        let t = m.tc(lag, i);
        let s = if t > knee + 0.5 {
            Some(true)
        } else if t < knee - 0.5 {
            Some(false)
        } else {
            None
        };
        if let (Some(a), Some(b)) = (side, s) {
            if a != b {
                count += 1;
            }
        }
        if s.is_some() {
            side = s;
        }
    }
    count.max(1)
}

/// Each knee of `c` with its interval: the profile over the knee (cost
/// threshold `thr`) within the knee's bounds in `range`, widened by the
/// coil-temperature estimate's noise. That noise is correlated over about a
/// minute: it moves the knee as a whole at each crossing, so it averages
/// only over the crossings.
pub fn knee_intervals(
    inp: &SfInput,
    m: &Model,
    c: &Candidate,
    thr: f64,
    (lo, hi): (f64, f64),
) -> Vec<Interval> {
    let sigma_tc = coil_estimate_noise(inp, c.lag);
    let mut knees = vec![];
    for j in 0..c.knees.len() {
        let prof = |t: f64| {
            let mut k = c.knees.clone();
            k[j] = t;
            golden(
                |l| m.sse(l, c.degree, &k),
                (c.lag - 15.0).max(0.0),
                c.lag + 15.0,
                14,
            )
            .1
        };
        let k = c.knees[j];
        let (ci_lo, ci_hi) =
            profile_interval(prof, k, c.sse, thr, 0.01, knee_bounds(&c.knees, j, lo, hi));
        let z = 1.96 * sigma_tc / (crossings(m, c.lag, k) as f64).sqrt();
        knees.push(Interval {
            value: k,
            lo: k - (k - ci_lo).hypot(z),
            hi: k + (ci_hi - k).hypot(z),
        });
    }
    knees
}

/// The lag's interval (cost threshold `thr`), the knees re-fitted locally
/// within their bounds in `range` at each lag.
pub fn lag_interval(m: &Model, c: &Candidate, thr: f64, (lo, hi): (f64, f64)) -> (f64, f64) {
    let prof_lag = |l: f64| {
        let mut cand = Candidate {
            degree: c.degree,
            knees: c.knees.clone(),
            lag: l,
            sse: 0.0,
        };
        for j in 0..cand.knees.len() {
            let (bl, br) = knee_bounds(&cand.knees, j, lo, hi);
            let (a, b) = ((cand.knees[j] - 0.5).max(bl), (cand.knees[j] + 0.5).min(br));
            let mut k = cand.knees.clone();
            cand.knees[j] = golden(
                |t| {
                    k[j] = t;
                    m.sse(l, c.degree, &k)
                },
                a,
                b,
                10,
            )
            .0;
        }
        m.sse(l, c.degree, &cand.knees)
    };
    profile_interval(prof_lag, c.lag, c.sse, thr, 0.5, (0.0, 1000.0))
}
