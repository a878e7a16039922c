//! The likelihood of a noise model for what a fit leaves of the residual
//! (docs/discovery.md): restricted (REML) to estimate the slow noise
//! levels given a fit's columns, plain (ML) to compare fits of different
//! columns (confirm.rs); and the searches on it: the levels refined
//! ([`refine`], [`profile`]) and raised to the largest the record cannot
//! exclude ([`slow_bounds`]).
//!
//! The slow levels (flicker, random walk, Markov) live at averaging times
//! of minutes to hours. A record of more than [`MAX_BLOCKS`] windows is
//! taken here as the means of blocks of consecutive windows, at most that
//! many blocks (noise_model.rs's `Whitener::averaged` gives each process
//! its block mean's variance): the cost of a likelihood no longer grows
//! with the record, and the dozens of likelihoods each search takes stop
//! being what a day-long record's discovery spends its time on (issue 31:
//! 24 h at 1 Hz took 48 s, four fifths of it here). The selection and the
//! intervals keep the 1 s windows.

use super::noise_model::{NoiseModel, Whitener};
use super::windows::Windows;

/// Most observations a likelihood is taken on: blocks of up to 21 s on a
/// day at 1 Hz. Fewer, longer blocks bias the slow levels (a fast Markov
/// or flicker process's block means are a first-order process only
/// approximately): 1024 blocks of 8 s read a MEMS gyro's flicker 2.4
/// times too high.
pub const MAX_BLOCKS: usize = 4096;

/// The problem a likelihood is taken on: the residual less the fit's fixed
/// parts and the fit's raw columns, as window means or as block means of
/// them.
pub struct Problem {
    win: Windows,
    keep: Vec<bool>,
    y: Vec<f64>,
    cols: Vec<Vec<f64>>,
    /// Length of a block, s (0: the windows themselves).
    block_s: f64,
    /// A full window's white variance to a full block's.
    white_ratio: f64,
}

impl Problem {
    /// The problem of `y` (window means) and `cols` over windows `win`,
    /// the windows `keep` marks: in blocks of consecutive windows when
    /// there are more than [`MAX_BLOCKS`] (a block's mean over the windows
    /// it keeps, its rows the sum of theirs).
    pub fn new(win: &Windows, keep: &[bool], y: &[f64], cols: &[Vec<f64>]) -> Self {
        let n = win.len();
        let b = n.div_ceil(MAX_BLOCKS).max(1);
        if b == 1 {
            return Self {
                win: Windows {
                    idx: vec![],
                    count: win.count.clone(),
                    t: win.t.clone(),
                },
                keep: keep.to_vec(),
                y: y.to_vec(),
                cols: cols.to_vec(),
                block_s: 0.0,
                white_ratio: 1.0,
            };
        }
        let nb = n.div_ceil(b);
        let mut count = vec![0.0; nb];
        let mut tsum = vec![0.0; nb];
        let mut ys = vec![0.0; nb];
        let mut cs = vec![vec![0.0; nb]; cols.len()];
        for k in (0..n).filter(|&k| keep[k]) {
            let j = k / b;
            let c = win.count[k];
            count[j] += c;
            tsum[j] += c * win.t[k];
            ys[j] += c * y[k];
            for (a, col) in cs.iter_mut().zip(cols) {
                a[j] += c * col[k];
            }
        }
        let kept: Vec<bool> = count.iter().map(|c| *c > 0.0).collect();
        let div = |v: &mut Vec<f64>| {
            for (a, c) in v.iter_mut().zip(&count) {
                if *c > 0.0 {
                    *a /= c;
                }
            }
        };
        div(&mut ys);
        for c in cs.iter_mut() {
            div(c);
        }
        // Blocks with nothing kept sit at their neighbours' time.
        let mut t: Vec<f64> = (0..nb)
            .map(|j| {
                if count[j] > 0.0 {
                    tsum[j] / count[j]
                } else {
                    f64::NAN
                }
            })
            .collect();
        for j in 0..nb {
            if t[j].is_nan() {
                t[j] = win.t[(j * b).min(n - 1)];
            }
        }
        let median = |v: &[f64]| {
            let mut s: Vec<f64> = v.iter().copied().filter(|c| *c > 0.0).collect();
            s.sort_by(f64::total_cmp);
            s.get(s.len() / 2).copied().unwrap_or(1.0)
        };
        let nominal_win = median(&win.count);
        let nominal_block = median(&count);
        let spacing = if n > 1 {
            (win.t[n - 1] - win.t[0]) / (n - 1) as f64
        } else {
            1.0
        };
        Self {
            win: Windows {
                idx: vec![],
                count,
                t,
            },
            keep: kept,
            y: ys,
            cols: cs,
            block_s: b as f64 * spacing,
            white_ratio: nominal_win / nominal_block,
        }
    }

    /// The Kalman filter of noise model `m` on this problem's observations.
    pub fn whitener(&self, m: &NoiseModel) -> Whitener {
        let mut mb = *m;
        mb.white *= self.white_ratio;
        Whitener::averaged(&mb, &self.win, &self.keep, self.block_s)
    }

    /// Observations (windows or blocks).
    pub fn len(&self) -> usize {
        self.y.len()
    }

    pub fn is_empty(&self) -> bool {
        self.y.is_empty()
    }
}

/// The restricted log-likelihood of noise model `m` for the residual
/// less fixed parts `y` and a fit's raw columns `cols` (window means), the
/// white level profiled out as the common scale.
fn reml(m: &NoiseModel, p: &Problem) -> f64 {
    loglik(m, p, true)
}

/// The log-likelihood of noise model `m` for `y` less the fit of `cols`:
/// restricted ([`reml`]) or plain maximum likelihood (n in place of n - p,
/// no Gram determinant: the one that compares fits of different columns).
pub fn loglik(m: &NoiseModel, p: &Problem, restricted: bool) -> f64 {
    let w = p.whitener(m);
    let mut all: Vec<&[f64]> = vec![&p.y];
    all.extend(p.cols.iter().map(Vec::as_slice));
    let mut cw = w.whiten_many(&all);
    let yw = cw.remove(0);
    let sse = match super::normal::normal_solve(&cw, &yw) {
        Some(b) if !cw.is_empty() => {
            let mut r = yw.clone();
            for (c, bj) in cw.iter().zip(&b) {
                for (a, v) in r.iter_mut().zip(c) {
                    *a -= bj * v;
                }
            }
            r.iter().map(|v| v * v).sum::<f64>()
        }
        _ => yw.iter().map(|v| v * v).sum::<f64>(),
    };
    // The restricted likelihood (REML): the fit's p columns take p
    // degrees of freedom of the residual, and their Gram determinant
    // weighs how much of each slow noise level they can absorb. Plain
    // maximum likelihood (n in place of n - p, no determinant) reads the
    // slow noise the fitted shapes soaked up as absent, and the slow
    // levels, and with them the intervals, came out too small.
    let n = w.used() as f64;
    if !restricted {
        return -0.5 * (n * (sse / n.max(1.0)).max(1e-300).ln() + w.log_det());
    }
    let np = cw.len() as f64;
    let gram = if cw.is_empty() {
        Some(0.0)
    } else {
        gram_log_det(&cw)
    };
    let Some(gram) = gram else {
        return f64::NEG_INFINITY;
    };
    let m = (n - np).max(1.0);
    -0.5 * (m * (sse / m).max(1e-300).ln() + w.log_det() + gram)
}

/// Half the chi-square(1) 95 % quantile: the fall of the log-likelihood
/// at a level's 95 % profile bound.
const HALF_CHI2_1_95: f64 = 1.920_729_410_347_062;

/// The noise model with, in turn, its flicker and its random walk raised
/// to the largest level the record cannot exclude (restricted likelihood
/// within [`HALF_CHI2_1_95`] of `m`'s, the level scanned up in eighths of
/// a decade from `m`'s, or a ten-thousandth of the white level, to a
/// thousand times that): the slow noise a fit's intervals must allow for
/// when the Allan curve and the likelihood cannot tell it from none.
pub fn slow_bounds(m: &NoiseModel, p: &Problem) -> Vec<NoiseModel> {
    let l0 = reml(m, p);
    let floor = m.white * 1e-4;
    (0..2)
        .map(|which| {
            let base = if which == 0 {
                m.flicker.max(floor)
            } else {
                m.random_walk.max(floor * 1e-3)
            };
            let mut best = l0;
            let mut up = *m;
            for k in 1..=24 {
                let mut c = *m;
                let v = base * 10f64.powf(0.125 * k as f64);
                if which == 0 {
                    c.flicker = v;
                } else {
                    c.random_walk = v;
                }
                let l = reml(&c, p);
                best = best.max(l);
                if l < best - HALF_CHI2_1_95 {
                    break;
                }
                up = c;
            }
            up
        })
        .collect()
}

/// The noise model, given the terms of a fit (their raw columns `cols`
/// and the residual less their fixed parts `y`, window means), with its
/// random walk, flicker and Markov levels refined by restricted maximum
/// likelihood (REML: the likelihood of the residual's contrasts the fit's
/// columns leave; each scaled by a factor searched over 1/100 .. 100 and zero, in turn,
/// twice; the white level profiled out as the common scale).
pub fn refine(start: &NoiseModel, p: &Problem) -> NoiseModel {
    profile(start, p, true).0
}

/// The noise model searched as [`refine`] does, by the restricted or the
/// plain likelihood, and that likelihood at its best.
pub fn profile(start: &NoiseModel, p: &Problem, restricted: bool) -> (NoiseModel, f64) {
    let loglik = |m: &NoiseModel| loglik(m, p, restricted);
    let mut m = *start;
    let floor = m.white * 1e-4;
    let mut best = loglik(&m);
    let factors: Vec<f64> = std::iter::once(0.0)
        .chain((0..=16).map(|i| 10f64.powf(-2.0 + 0.25 * i as f64)))
        .collect();
    for _ in 0..2 {
        for which in 0..3 {
            let base = match which {
                0 => m.random_walk.max(floor * 1e-3),
                1 => m.flicker.max(floor),
                _ => m.markov.max(floor),
            };
            for &f in &factors {
                let mut c = m;
                match which {
                    0 => c.random_walk = base * f,
                    1 => c.flicker = base * f,
                    _ => c.markov = base * f,
                }
                let l = loglik(&c);
                if l > best + 1e-9 {
                    best = l;
                    m = c;
                }
            }
        }
    }
    (m, best)
}

/// ln det of the Gram matrix of `cols` (None when it is singular).
fn gram_log_det(cols: &[Vec<f64>]) -> Option<f64> {
    let m = cols.len();
    let g = nalgebra::DMatrix::from_fn(m, m, |i, j| {
        cols[i]
            .iter()
            .zip(&cols[j])
            .map(|(a, b)| a * b)
            .sum::<f64>()
    });
    let c = g.cholesky()?;
    let l = c.l_dirty();
    let s: f64 = (0..m).map(|i| 2.0 * l[(i, i)].ln()).sum();
    s.is_finite().then_some(s)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn windows(n: usize) -> Windows {
        let t: Vec<f64> = (0..n).map(|k| k as f64 + 0.5).collect();
        Windows::new(&t, 1.0)
    }

    #[test]
    fn block_means_read_the_slow_levels_the_windows_do() {
        // White plus flicker (the project's generator): the restricted
        // likelihood's flicker level from 2048-block means is the one from
        // the windows themselves, within the estimates' own scatter.
        for seed in [3u64, 4] {
            let n = 12_000;
            let b = 2e-3;
            let mut g = gyro_sim::RateNoise::new(
                gyro_sim::NoiseParams {
                    n_dps_rts: 6e-3,
                    b_dps: b,
                    flicker_max_tau_s: n as f64,
                    ..Default::default()
                },
                1.0,
                seed,
            );
            let x: Vec<f64> = (0..n).map(|_| g.sample()).collect();
            let win = windows(n);
            let keep = vec![true; n];
            let ones = vec![vec![1.0; n]];
            let start = NoiseModel::from_residual(&x, &keep, 1.0);
            let fine = {
                let mut p = Problem::new(&win, &keep, &x, &ones);
                // The windows themselves: no blocks.
                p.block_s = 0.0;
                p
            };
            let _ = fine.len();
            let whole = refine(
                &start,
                &Problem {
                    win: Windows {
                        idx: vec![],
                        count: win.count.clone(),
                        t: win.t.clone(),
                    },
                    keep: keep.clone(),
                    y: x.clone(),
                    cols: ones.clone(),
                    block_s: 0.0,
                    white_ratio: 1.0,
                },
            );
            let blocked = refine(&start, &Problem::new(&win, &keep, &x, &ones));
            let r = (blocked.flicker / whole.flicker).sqrt();
            assert!((0.6..1.6).contains(&r), "{seed}: {whole:?} vs {blocked:?}");
        }
    }
}
