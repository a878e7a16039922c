//! The sum of squares of a fit with one term's columns added to a fixed
//! set, for the searches of a term's non-linear parameter (design.rs's
//! `optimize` and `refine`): the fixed set's Gram matrix and its products
//! with the residual are formed once, and each trial value of the
//! parameter costs its own column's products (O(n) per column) and a
//! small solve, not the whole fit again. Same scaling and pivot rule as
//! normal.rs, so a degenerate trial is refused the same way.

/// The fixed part of a family of fits: its whitened columns and residual
/// and their products.
pub struct Projection {
    cols: Vec<Vec<f64>>,
    y: Vec<f64>,
    norms: Vec<f64>,
    /// Gram matrix of the columns scaled to unit norm (row-major) and
    /// their scaled products with y.
    gram: Vec<f64>,
    xy: Vec<f64>,
    yy: f64,
}

use super::normal::cholesky_solve;
use crate::numerics::dot::{dot, dots};

impl Projection {
    /// The fixed set: whitened columns `cols` and whitened residual `y`
    /// (less the fixed parts). None when a column is zero or not finite.
    pub fn new(cols: Vec<Vec<f64>>, y: Vec<f64>) -> Option<Self> {
        let norms: Vec<f64> = cols.iter().map(|c| dot(c, c).sqrt()).collect();
        if norms.iter().any(|n| !(n.is_finite() && *n > 0.0)) {
            return None;
        }
        let p = cols.len();
        let mut gram = vec![0.0; p * p];
        let mut xy = vec![0.0; p];
        for i in 0..p {
            // Column i against those before it and y, in one pass.
            let mut others: Vec<&[f64]> = cols[..=i].iter().map(Vec::as_slice).collect();
            others.push(&y);
            let d = dots(&cols[i], &others);
            for j in 0..=i {
                let v = d[j] / (norms[i] * norms[j]);
                gram[i * p + j] = v;
                gram[j * p + i] = v;
            }
            xy[i] = d[i + 1] / norms[i];
        }
        let yy = dot(&y, &y);
        Some(Self {
            cols,
            y,
            norms,
            gram,
            xy,
            yy,
        })
    }

    /// The whitened sum of squares with columns `extra` added and the
    /// residual less `offset`; infinite when the fit is degenerate.
    pub fn sse_with(&self, extra: &[Vec<f64>], offset: Option<&[f64]>) -> f64 {
        let p = self.cols.len();
        let k = extra.len();
        let m = p + k;
        let fixed: Vec<&[f64]> = self.cols.iter().map(Vec::as_slice).collect();
        // y' = y - o: its products with the fixed columns and itself.
        let (mut xy, yy) = match offset {
            Some(o) => {
                let mut with = fixed.clone();
                with.push(&self.y);
                with.push(o);
                let d = dots(o, &with);
                let xy: Vec<f64> = (0..p).map(|i| self.xy[i] - d[i] / self.norms[i]).collect();
                (xy, self.yy - 2.0 * d[p] + d[p + 1])
            }
            None => (self.xy.clone(), self.yy),
        };
        let mut a = vec![0.0; m * m];
        for i in 0..p {
            a[i * m..i * m + p].copy_from_slice(&self.gram[i * p..(i + 1) * p]);
        }
        let mut en = vec![0.0; k];
        for (q, c) in extra.iter().enumerate() {
            // Its products with the fixed columns, y, the offset and the
            // extra columns up to itself, in one pass over the rows.
            let mut with = fixed.clone();
            with.push(&self.y);
            with.extend(offset);
            with.extend(extra[..=q].iter().map(Vec::as_slice));
            let d = dots(c, &with);
            let e0 = p + 1 + usize::from(offset.is_some());
            let cc = d[e0 + q];
            en[q] = cc.sqrt();
            if !(en[q].is_finite() && en[q] > 0.0) {
                return f64::INFINITY;
            }
            let r = p + q;
            for i in 0..p {
                let v = d[i] / (en[q] * self.norms[i]);
                a[r * m + i] = v;
                a[i * m + r] = v;
            }
            for q2 in 0..=q {
                let v = d[e0 + q2] / (en[q] * en[q2]);
                a[r * m + p + q2] = v;
                a[(p + q2) * m + r] = v;
            }
            let cy = match offset {
                Some(_) => d[p] - d[p + 1],
                None => d[p],
            };
            xy.push(cy / en[q]);
        }
        if m == 0 {
            return yy.max(0.0);
        }
        match cholesky_solve(a, &xy, m) {
            Some(z) => (yy - dot(&z, &xy)).max(0.0),
            None => f64::INFINITY,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::discovery::normal::normal_solve;

    #[test]
    fn the_projection_gives_the_full_fit_s_sum_of_squares() {
        let n = 300;
        let x1: Vec<f64> = (0..n).map(|k| 1.0 + 0.0 * k as f64).collect();
        let x2: Vec<f64> = (0..n).map(|k| (k as f64 * 0.01).sin()).collect();
        let x3: Vec<f64> = (0..n).map(|k| ((k as f64) * 0.037).cos().powi(3)).collect();
        let o: Vec<f64> = (0..n).map(|k| 0.3 * (k as f64 * 0.05).sin()).collect();
        let y: Vec<f64> = (0..n)
            .map(|k| {
                2.0 * x1[k] - x2[k]
                    + 0.5 * x3[k]
                    + o[k]
                    + 0.1 * ((k * 7919 % 101) as f64 / 50.0 - 1.0)
            })
            .collect();
        let pr = Projection::new(vec![x1.clone(), x2.clone()], y.clone()).unwrap();
        let got = pr.sse_with(std::slice::from_ref(&x3), Some(&o));
        let yo: Vec<f64> = y.iter().zip(&o).map(|(a, b)| a - b).collect();
        let cols = [x1, x2, x3];
        let b = normal_solve(&cols, &yo).unwrap();
        let want: f64 = (0..n)
            .map(|k| {
                let f: f64 = (0..3).map(|j| b[j] * cols[j][k]).sum();
                (yo[k] - f).powi(2)
            })
            .sum();
        assert!((got / want - 1.0).abs() < 1e-8, "{got} vs {want}");
        // A column the fixed ones already span is refused.
        let dup = vec![cols[0].iter().map(|v| 3.0 * v).collect::<Vec<f64>>()];
        assert!(pr.sse_with(&dup, None).is_infinite());
    }
}
