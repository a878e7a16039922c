//! Non-negative weighted least squares (Lawson and Hanson's active-set
//! algorithm, "Solving Least Squares Problems", 1974, ch. 23): min
//! sum_i w_i (y_i - sum_j c_j x_ij)^2 over c >= 0. The terms fit solves
//! one per trial frequency or correlation time, so it works on a handful of
//! columns through their Gram matrix, each column scaled to unit weighted
//! norm.

use nalgebra::{DMatrix, DVector};

/// The solution and its weighted sum of squared residuals.
pub struct Nnls {
    pub coef: Vec<f64>,
    pub sse: f64,
}

/// Solves the problem for columns `cols` (each of `y`'s length) and
/// weights `w`. Columns that are zero, or that add nothing the others do
/// not already give, keep a zero coefficient.
pub fn nnls(cols: &[Vec<f64>], y: &[f64], w: &[f64]) -> Nnls {
    let n = y.len();
    let p = cols.len();
    let sw: Vec<f64> = w.iter().map(|v| v.max(0.0).sqrt()).collect();
    let scale: Vec<f64> = cols
        .iter()
        .map(|c| (0..n).map(|i| (sw[i] * c[i]).powi(2)).sum::<f64>().sqrt())
        .collect();
    let a: Vec<Vec<f64>> = (0..p)
        .map(|j| {
            (0..n)
                .map(|i| {
                    if scale[j] > 0.0 && scale[j].is_finite() {
                        sw[i] * cols[j][i] / scale[j]
                    } else {
                        0.0
                    }
                })
                .collect()
        })
        .collect();
    let b: Vec<f64> = (0..n).map(|i| sw[i] * y[i]).collect();
    let dot = |u: &[f64], v: &[f64]| u.iter().zip(v).map(|(a, b)| a * b).sum::<f64>();
    let gram = DMatrix::from_fn(p, p, |j, k| dot(&a[j], &a[k]));
    let atb: Vec<f64> = (0..p).map(|j| dot(&a[j], &b)).collect();
    let mut x = vec![0.0; p];
    let mut passive = vec![false; p];
    let usable: Vec<bool> = (0..p)
        .map(|j| scale[j] > 0.0 && scale[j].is_finite())
        .collect();
    let solve = |set: &[bool]| -> Option<Vec<f64>> {
        let idx: Vec<usize> = (0..p).filter(|&j| set[j]).collect();
        let g = DMatrix::from_fn(idx.len(), idx.len(), |r, c| gram[(idx[r], idx[c])]);
        let rhs = DVector::from_fn(idx.len(), |r, _| atb[idx[r]]);
        let ch = g.cholesky()?;
        let z = ch.solve(&rhs);
        let mut out = vec![0.0; p];
        for (r, &j) in idx.iter().enumerate() {
            out[j] = z[r];
        }
        Some(out)
    };
    for _outer in 0..3 * p + 3 {
        // Gradient of the (halved) objective: A'(b - A x).
        let grad: Vec<f64> = (0..p)
            .map(|j| atb[j] - (0..p).map(|k| gram[(j, k)] * x[k]).sum::<f64>())
            .collect();
        let cand = (0..p)
            .filter(|&j| !passive[j] && usable[j])
            .max_by(|&u, &v| grad[u].total_cmp(&grad[v]));
        let Some(j) = cand else { break };
        if grad[j] <= 1e-12 * atb.iter().map(|v| v.abs()).fold(1e-300, f64::max) {
            break;
        }
        passive[j] = true;
        let mut added = false;
        for _inner in 0..3 * p + 3 {
            let Some(z) = solve(&passive) else {
                // The new column adds nothing new (collinear): leave it.
                passive[j] = false;
                break;
            };
            if (0..p).filter(|&k| passive[k]).all(|k| z[k] > 0.0) {
                x = z;
                added = true;
                break;
            }
            // Step back toward x until the first coefficient reaches zero.
            let mut alpha = 1.0f64;
            for k in (0..p).filter(|&k| passive[k] && z[k] <= 0.0) {
                let d = x[k] - z[k];
                if d > 0.0 {
                    alpha = alpha.min(x[k] / d);
                }
            }
            for k in 0..p {
                if passive[k] {
                    x[k] += alpha * (z[k] - x[k]);
                    if x[k] <= 1e-15 {
                        x[k] = 0.0;
                        passive[k] = false;
                    }
                }
            }
            if !passive.iter().any(|&v| v) {
                break;
            }
        }
        if !added && !passive[j] {
            break;
        }
    }
    let coef: Vec<f64> = (0..p)
        .map(|j| {
            if usable[j] {
                x[j].max(0.0) / scale[j]
            } else {
                0.0
            }
        })
        .collect();
    let sse = (0..n)
        .map(|i| {
            let f: f64 = (0..p).map(|j| coef[j] * cols[j][i]).sum();
            w[i] * (y[i] - f).powi(2)
        })
        .sum();
    Nnls { coef, sse }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn matches_the_best_non_negative_subset() {
        // y = 2 x0 + 0 x1 + 3 x2 - 1 x3 exactly: the unconstrained solution
        // has a negative coefficient; the non-negative one is the best of
        // the subsets without x3, found by enumeration.
        let n = 40;
        let t: Vec<f64> = (0..n).map(|i| 0.1 + i as f64 * 0.3).collect();
        let cols: Vec<Vec<f64>> = vec![
            t.iter().map(|t| 1.0 / t).collect(),
            t.iter().map(|_| 1.0).collect(),
            t.to_vec(),
            t.iter().map(|t| t * t).collect(),
        ];
        let y: Vec<f64> = (0..n)
            .map(|i| 2.0 * cols[0][i] + 3.0 * cols[2][i] - 0.05 * cols[3][i])
            .collect();
        let w: Vec<f64> = (0..n).map(|i| 1.0 / (1.0 + i as f64)).collect();
        let got = nnls(&cols, &y, &w);
        let mut best = f64::INFINITY;
        for mask in 1u32..16 {
            let sub: Vec<Vec<f64>> = (0..4)
                .filter(|b| mask & (1 << b) != 0)
                .map(|b| cols[b].clone())
                .collect();
            if let Some(f) = crate::numerics::lsq::wls(&sub, &y, Some(&w)) {
                if f.coef.iter().all(|&c| c >= 0.0) {
                    best = best.min(f.sse);
                }
            }
        }
        assert!(got.coef.iter().all(|&c| c >= 0.0));
        assert!(
            (got.sse - best).abs() <= 1e-9 * best.max(1e-12),
            "{} vs {best}",
            got.sse
        );
    }
}
