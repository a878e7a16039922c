//! Least squares by the normal equations, for the many small fits of the
//! selection (the columns few, the rows many): cheaper than a QR per
//! candidate, and exact enough with the columns scaled to unit norm; the
//! final estimates and their covariance use the QR of numerics/lsq.rs.

use crate::numerics::dot::{dots, sum_sq};

/// Least squares by the normal equations of the columns scaled to unit
/// norm (Cholesky); None when a pivot falls below 1e-10 of the diagonal
/// (collinear columns, or a column of zeros).
pub fn normal_solve<C: AsRef<[f64]>>(cols: &[C], y: &[f64]) -> Option<Vec<f64>> {
    let m = cols.len();
    let norms: Vec<f64> = cols.iter().map(|c| sum_sq(c.as_ref()).sqrt()).collect();
    if norms.iter().any(|n| !(n.is_finite() && *n > 0.0)) {
        return None;
    }
    let mut a = vec![0.0; m * m];
    let mut b = vec![0.0; m];
    for i in 0..m {
        // Column i against the columns before it and y, in one pass.
        let mut others: Vec<&[f64]> = cols[..=i].iter().map(|c| c.as_ref()).collect();
        others.push(y);
        let p = dots(cols[i].as_ref(), &others);
        for j in 0..=i {
            a[i * m + j] = p[j] / (norms[i] * norms[j]);
            a[j * m + i] = a[i * m + j];
        }
        b[i] = p[i + 1] / norms[i];
    }
    let z = cholesky_solve(a, &b, m)?;
    Some(z.iter().zip(&norms).map(|(v, n)| v / n).collect())
}

/// Solves the symmetric positive definite `a` (m x m, row-major) z = b by
/// Cholesky in place (a = L L'); None when a pivot falls below 1e-10 (the
/// columns scaled to unit norm: collinear, or a column of zeros).
pub fn cholesky_solve(mut a: Vec<f64>, b: &[f64], m: usize) -> Option<Vec<f64>> {
    for j in 0..m {
        let mut d = a[j * m + j];
        for k in 0..j {
            d -= a[j * m + k] * a[j * m + k];
        }
        if d.is_nan() || d <= 1e-10 {
            return None;
        }
        let d = d.sqrt();
        a[j * m + j] = d;
        for i in j + 1..m {
            let mut s = a[i * m + j];
            for k in 0..j {
                s -= a[i * m + k] * a[j * m + k];
            }
            a[i * m + j] = s / d;
        }
    }
    let mut z = b.to_vec();
    for i in 0..m {
        for k in 0..i {
            z[i] -= a[i * m + k] * z[k];
        }
        z[i] /= a[i * m + i];
    }
    for i in (0..m).rev() {
        for k in i + 1..m {
            z[i] -= a[k * m + i] * z[k];
        }
        z[i] /= a[i * m + i];
    }
    Some(z)
}

#[cfg(test)]
mod tests {
    use super::normal_solve;

    #[test]
    fn normal_equations_solve_and_refuse_collinear_columns() {
        let x1: Vec<f64> = (0..50).map(|k| k as f64).collect();
        let x2: Vec<f64> = (0..50).map(|k| ((k as f64) * 0.3).sin()).collect();
        let y: Vec<f64> = x1.iter().zip(&x2).map(|(a, b)| 2.0 * a - 3.0 * b).collect();
        let c = normal_solve(&[x1.clone(), x2], &y).unwrap();
        assert!((c[0] - 2.0).abs() < 1e-9 && (c[1] + 3.0).abs() < 1e-9);
        let x3: Vec<f64> = x1.iter().map(|v| 2.0 * v).collect();
        assert!(normal_solve(&[x1, x3], &y).is_none());
    }
}
