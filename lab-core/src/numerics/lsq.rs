//! Weighted linear least squares (nalgebra), the one solver of the lab's
//! fits. Columns are scaled to unit weighted RMS before solving, so
//! regressors in different units (deg/s, deg/s x degC) stay well conditioned.

use nalgebra::{DMatrix, DVector};

pub struct LsFit {
    pub coef: Vec<f64>,
    /// y - X*coef (unweighted).
    pub resid: Vec<f64>,
    /// Weighted sum of squared residuals.
    pub sse: f64,
    /// (X'WX)^-1 in the original units: the coefficients' covariance is
    /// this times the residual variance.
    pub cov_unscaled: DMatrix<f64>,
}

impl LsFit {
    /// Standard error of coefficient `j` with residual variance `var`.
    pub fn se(&self, j: usize, var: f64) -> f64 {
        (self.cov_unscaled[(j, j)] * var).max(0.0).sqrt()
    }

    /// Standard error of the linear combination `a . coef`.
    pub fn se_of(&self, a: &[f64], var: f64) -> f64 {
        let m = a.len().min(self.coef.len());
        let mut v = 0.0;
        for i in 0..m {
            for j in 0..m {
                v += a[i] * self.cov_unscaled[(i, j)] * a[j];
            }
        }
        (v * var).max(0.0).sqrt()
    }
}

/// Solves min sum w_i (y_i - sum_j c_j x_ij)^2 (`w` None: unit weights).
/// None when the columns are degenerate (a column all zero, or collinear).
pub fn wls(cols: &[Vec<f64>], y: &[f64], w: Option<&[f64]>) -> Option<LsFit> {
    let n = y.len();
    let m = cols.len();
    if m == 0 || n < m || cols.iter().any(|c| c.len() != n) {
        return None;
    }
    let weight = |i: usize| w.map_or(1.0, |w| w[i]);
    let scale: Vec<f64> = cols
        .iter()
        .map(|c| {
            let r = (c
                .iter()
                .enumerate()
                .map(|(i, v)| weight(i) * v * v)
                .sum::<f64>()
                / n as f64)
                .sqrt();
            if r > 0.0 && r.is_finite() {
                r
            } else {
                0.0
            }
        })
        .collect();
    if scale.contains(&0.0) {
        return None;
    }
    // Householder QR of the weighted, scaled design (as stable as an SVD
    // for a full-rank design, and cheaper in the fits' search loops).
    let sw: Vec<f64> = (0..n).map(|i| weight(i).max(0.0).sqrt()).collect();
    let x = DMatrix::from_fn(n, m, |i, j| sw[i] * cols[j][i] / scale[j]);
    let yv = DVector::from_fn(n, |i, _| sw[i] * y[i]);
    let qr = x.qr();
    let r = qr.r();
    let rmax = (0..m).map(|j| r[(j, j)].abs()).fold(0.0, f64::max);
    // Condition beyond 1e10: collinear columns.
    if rmax.is_nan() || rmax <= 0.0 || (0..m).any(|j| r[(j, j)].abs() < rmax * 1e-10) {
        return None;
    }
    // Q'y without forming Q (n x m).
    let mut qty = yv;
    qr.q_tr_mul(&mut qty);
    let qty = DVector::from_fn(m, |i, _| qty[i]);
    let sol = r.solve_upper_triangular(&qty)?;
    let rinv = r.solve_upper_triangular(&DMatrix::identity(m, m))?;
    let inv = &rinv * rinv.transpose();
    let coef: Vec<f64> = (0..m).map(|j| sol[j] / scale[j]).collect();
    let mut resid = Vec::with_capacity(n);
    let mut sse = 0.0;
    for i in 0..n {
        let f: f64 = (0..m).map(|j| coef[j] * cols[j][i]).sum();
        let r = y[i] - f;
        sse += weight(i) * r * r;
        resid.push(r);
    }
    let cov_unscaled = DMatrix::from_fn(m, m, |j, k| inv[(j, k)] / (scale[j] * scale[k]));
    Some(LsFit {
        coef,
        resid,
        sse,
        cov_unscaled,
    })
}
