//! Columns made orthogonal to what a fit already carries: a candidate, or
//! a term's Jacobian, is judged on what only it can explain.

/// Unit vectors spanning `cols` (modified Gram-Schmidt; dependent columns
/// dropped).
pub fn basis(cols: &[Vec<f64>]) -> Vec<Vec<f64>> {
    let mut q: Vec<Vec<f64>> = vec![];
    for c in cols {
        let mut v = c.clone();
        let n0 = dot(&v, &v).sqrt();
        for u in &q {
            let p = dot(u, &v);
            v.iter_mut().zip(u).for_each(|(a, b)| *a -= p * b);
        }
        let n = dot(&v, &v).sqrt();
        if n > 1e-9 * n0.max(1e-300) {
            v.iter_mut().for_each(|a| *a /= n);
            q.push(v);
        }
    }
    q
}

pub fn dot(a: &[f64], b: &[f64]) -> f64 {
    a.iter().zip(b).map(|(x, y)| x * y).sum()
}

/// `x` less its projection on the orthonormal `q`.
pub fn orthogonal(mut x: Vec<f64>, q: &[Vec<f64>]) -> Vec<f64> {
    for u in q {
        let d = dot(u, &x);
        x.iter_mut().zip(u).for_each(|(a, b)| *a -= d * b);
    }
    x
}
