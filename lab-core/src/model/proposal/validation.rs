//! Validation by prediction, not in-sample fit: blocked cross-validation
//! over the record's whitened rows.
//!
//! The rows are the residual's window means whitened by the noise model
//! (discovery's), so under that model they are independent with one
//! variance, and a held-out block is judged by what the term predicts
//! there against predicting nothing (the noise's own best guess of a
//! whitened row is zero). Each of `K` folds (short contiguous segments
//! dealt in turn, [`block_of`]) is held out in turn; the term's coefficients, and its searched parameter, are fitted
//! on the other blocks only (sufficient statistics per block, so a fold
//! costs O(K m^2), not a pass over the record). The columns are first made
//! orthogonal to what the fit already carries (the library's columns and
//! the constant): a candidate is judged on what only it can explain.
//!
//! The statistic is the held-out reduction of the sum of squares in units
//! of the whitened noise's variance. With no term present each fold's
//! reduction has a negative mean (a coefficient fitted to noise predicts
//! worse than zero), so noise pays only through the search; the threshold
//! [`THRESHOLD`] covers the whole candidate space at once (tests below:
//! white nulls, the search's maximum).

/// Blocks of the record held out in turn.
pub const FOLDS: usize = 8;

/// The held-out reduction (in noise variances) a term must reach: the
/// largest the whole candidate space reached on white nulls (the test
/// below) was under half of it.
pub const THRESHOLD: f64 = 25.0;

/// The held-out gain a candidate must reach in a space of `m` candidate
/// columns: [`THRESHOLD`] for the space it was set on, growing as 4 ln m
/// beyond (the largest of m chance gains grows as twice the log of m,
/// and the threshold keeps twice that: nulls' largest gains, in the tests
/// below and the bench, stay under half of it).
pub fn threshold(m: usize) -> f64 {
    (4.0 * (m.max(1) as f64).ln()).max(THRESHOLD)
}

/// How a proposed term was checked on data it was not fitted on.
#[derive(Clone, Debug, PartialEq)]
pub struct Validation {
    pub folds: usize,
    /// Held-out reduction of the sum of squares over all folds, in
    /// variances of the whitened noise, and per fold.
    pub held_out_gain: f64,
    pub fold_gains: Vec<f64>,
    pub threshold: f64,
    /// The share of the whitened residual the term predicts out of sample.
    pub held_out_share: f64,
}

/// One fold's statistics of a column set: X'X, X'y, per block.
#[derive(Clone, Debug)]
pub struct BlockStats {
    pub m: usize,
    /// Per block: X'X (row-major m x m) and X'y.
    pub xx: Vec<Vec<f64>>,
    pub xy: Vec<Vec<f64>>,
}

/// Rows per contiguous segment of a fold: long against what whitening
/// leaves correlated (a few rows), short against the record, so a held-out
/// segment is predicted from both sides (interpolation, as a model is
/// used) rather than extrapolated past the record's end.
pub const SEGMENT_ROWS: usize = 60;

/// The fold of each of `n` rows: segments of [`SEGMENT_ROWS`] dealt to
/// the `k` folds in turn (fewer rows: `k` contiguous blocks).
pub fn block_of(n: usize, k: usize) -> impl Fn(usize) -> usize {
    let seg = SEGMENT_ROWS.min((n / k).max(1));
    move |i| (i / seg) % k
}

/// The statistics of `cols` (already orthogonal to the fit's columns)
/// against `y`, per block.
pub fn stats(cols: &[Vec<f64>], y: &[f64], k: usize) -> BlockStats {
    let m = cols.len();
    let n = y.len();
    let b = block_of(n, k);
    let mut xx = vec![vec![0.0; m * m]; k];
    let mut xy = vec![vec![0.0; m]; k];
    for i in 0..n {
        let bi = b(i);
        for p in 0..m {
            let xp = cols[p][i];
            xy[bi][p] += xp * y[i];
            for q in 0..m {
                xx[bi][p * m + q] += xp * cols[q][i];
            }
        }
    }
    BlockStats { m, xx, xy }
}

/// Solves the m x m (m <= 3) system a x = c; None when singular.
pub fn solve(a: &[f64], c: &[f64]) -> Option<Vec<f64>> {
    let m = c.len();
    let mut a = a.to_vec();
    let mut c = c.to_vec();
    for i in 0..m {
        let p = (i..m).max_by(|&u, &v| a[u * m + i].abs().total_cmp(&a[v * m + i].abs()))?;
        if a[p * m + i].abs() < 1e-12 * (1.0 + a[i * m + i].abs()) {
            return None;
        }
        for j in 0..m {
            a.swap(i * m + j, p * m + j);
        }
        c.swap(i, p);
        for r in 0..m {
            if r != i {
                let f = a[r * m + i] / a[i * m + i];
                for j in 0..m {
                    a[r * m + j] -= f * a[i * m + j];
                }
                c[r] -= f * c[i];
            }
        }
    }
    Some((0..m).map(|i| c[i] / a[i * m + i]).collect())
}

impl BlockStats {
    /// X'X and X'y over the blocks but `out` (None: all).
    pub fn sums(&self, out: Option<usize>) -> (Vec<f64>, Vec<f64>) {
        let m = self.m;
        let mut a = vec![0.0; m * m];
        let mut c = vec![0.0; m];
        for b in 0..self.xx.len() {
            if Some(b) == out {
                continue;
            }
            a.iter_mut().zip(&self.xx[b]).for_each(|(s, v)| *s += v);
            c.iter_mut().zip(&self.xy[b]).for_each(|(s, v)| *s += v);
        }
        (a, c)
    }

    /// The fit on the blocks but `out`: coefficients and the reduction of
    /// the sum of squares they make there (c' beta).
    pub fn fit(&self, out: Option<usize>) -> Option<(Vec<f64>, f64)> {
        let (a, c) = self.sums(out);
        let beta = solve(&a, &c)?;
        let red = beta.iter().zip(&c).map(|(b, c)| b * c).sum();
        Some((beta, red))
    }

    /// What `beta` predicts in block `b`: its reduction of that block's
    /// sum of squares (2 beta' X'y - beta' X'X beta; negative when it
    /// predicts worse than nothing).
    pub fn held_out(&self, b: usize, beta: &[f64]) -> f64 {
        let m = self.m;
        let mut r = 0.0;
        for p in 0..m {
            r += 2.0 * beta[p] * self.xy[b][p];
            for q in 0..m {
                r -= beta[p] * self.xx[b][p * m + q] * beta[q];
            }
        }
        r
    }
}

/// A candidate's cross-validation: the statistics at each value of its
/// searched parameter (one entry when it has none). In each fold the
/// parameter is chosen on the training blocks alone.
pub fn cross_validate(grid: &[BlockStats], folds: usize) -> (f64, Vec<f64>) {
    let mut per_fold = vec![];
    for b in 0..folds {
        let best = grid
            .iter()
            .filter_map(|s| s.fit(Some(b)).map(|(beta, red)| (s, beta, red)))
            .max_by(|x, y| x.2.total_cmp(&y.2));
        per_fold.push(best.map_or(0.0, |(s, beta, _)| s.held_out(b, &beta)));
    }
    (per_fold.iter().sum(), per_fold)
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand_core::SeedableRng;
    use rand_distr::{Distribution, StandardNormal};

    fn normal(n: usize, seed: u64) -> Vec<f64> {
        let mut r = rand_xoshiro::Xoshiro256PlusPlus::seed_from_u64(seed);
        (0..n).map(|_| StandardNormal.sample(&mut r)).collect()
    }

    /// A step searched over 96 places, a sinusoid over 80 periods and a
    /// settling over 96 onsets x 10 time constants, on white noise: what
    /// the search alone makes of noise stays well under the threshold.
    #[test]
    fn the_search_does_not_pay_on_white_noise() {
        let n = 4000;
        let mut worst: f64 = f64::NEG_INFINITY;
        for seed in 0..20 {
            let y = normal(n, seed);
            let steps: Vec<BlockStats> = (0..96)
                .map(|k| {
                    let t0 = n as f64 * (0.05 + 0.9 * k as f64 / 95.0);
                    let mut x: Vec<f64> = (0..n)
                        .map(|i| f64::from(u8::from(i as f64 >= t0)))
                        .collect();
                    let mean = x.iter().sum::<f64>() / n as f64;
                    x.iter_mut().for_each(|v| *v -= mean);
                    stats(&[x], &y, FOLDS)
                })
                .collect();
            let sines: Vec<BlockStats> = (0..80)
                .map(|k| {
                    let p = 20.0 * (n as f64 / 40.0).powf(k as f64 / 79.0);
                    let s: Vec<f64> = (0..n)
                        .map(|i| (2.0 * std::f64::consts::PI * i as f64 / p).sin())
                        .collect();
                    let c: Vec<f64> = (0..n)
                        .map(|i| (2.0 * std::f64::consts::PI * i as f64 / p).cos())
                        .collect();
                    stats(&[s, c], &y, FOLDS)
                })
                .collect();
            // The settling from a time: the same onsets, ten time
            // constants from n/60 to n/3 (the candidate's 2 min to a
            // third of the record at 1 row/s).
            let settlings: Vec<BlockStats> = (0..96)
                .flat_map(|k| {
                    let t1 = n as f64 * (0.05 + 0.9 * k as f64 / 95.0);
                    (0..10).map(move |j| {
                        let tau = n as f64 / 60.0 * 20f64.powf(j as f64 / 9.0);
                        (t1, tau)
                    })
                })
                .map(|(t1, tau)| {
                    let mut x: Vec<f64> = (0..n)
                        .map(|i| {
                            let d = (i as f64 - t1).max(0.0);
                            1.0 - (-d / tau).exp()
                        })
                        .collect();
                    let mean = x.iter().sum::<f64>() / n as f64;
                    x.iter_mut().for_each(|v| *v -= mean);
                    stats(&[x], &y, FOLDS)
                })
                .collect();
            for g in [&steps, &sines, &settlings] {
                worst = worst.max(cross_validate(g, FOLDS).0);
            }
        }
        assert!(
            worst < THRESHOLD / 2.0,
            "the search made {worst} of white noise"
        );
    }

    /// A term at a tenth of the noise per row over 4000 rows is found
    /// (its in-sample chi-square is 40), and its held-out reduction is
    /// close to the in-sample one less the fitting's cost.
    #[test]
    fn a_small_term_pays_out_of_sample() {
        let n = 4000;
        let x: Vec<f64> = (0..n).map(|i| ((i as f64) / 300.0).sin()).collect();
        let mut got = vec![];
        for seed in 0..20 {
            let e = normal(n, 100 + seed);
            let y: Vec<f64> = x.iter().zip(&e).map(|(x, e)| 0.14 * x + e).collect();
            got.push(cross_validate(&[stats(std::slice::from_ref(&x), &y, FOLDS)], FOLDS).0);
        }
        let mean = got.iter().sum::<f64>() / got.len() as f64;
        // Expected: 0.14^2 * sum(x^2) = 39 less about one variance per fold.
        assert!((mean - 31.0).abs() < 8.0, "{mean}: {got:?}");
    }
}
