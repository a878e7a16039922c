//! Dot products of long columns (a day of 1 s windows is 86 400 rows),
//! the inner loop of discovery's many small fits. A single running sum
//! waits on each addition before the next (four cycles a row, whatever
//! the vector unit); eight independent partial sums, added pairwise at
//! the end, keep the unit busy and round no worse than the running sum.

/// Independent partial sums.
const LANES: usize = 8;

/// Pairwise sum of the partial sums.
fn reduce(s: [f64; LANES]) -> f64 {
    ((s[0] + s[4]) + (s[2] + s[6])) + ((s[1] + s[5]) + (s[3] + s[7]))
}

/// Adds `x . y` lane by lane into `s` (the groups of LANES whole).
#[inline(always)]
fn accumulate(s: &mut [f64; LANES], x: &[f64], y: &[f64]) {
    // A local copy: the partial sums stay in registers.
    let mut acc = *s;
    for (x, y) in x.chunks_exact(LANES).zip(y.chunks_exact(LANES)) {
        let x: &[f64; LANES] = x.try_into().expect("a whole group");
        let y: &[f64; LANES] = y.try_into().expect("a whole group");
        for i in 0..LANES {
            acc[i] += x[i] * y[i];
        }
    }
    *s = acc;
}

/// `a . b` over the shorter length.
pub fn dot(a: &[f64], b: &[f64]) -> f64 {
    let n = a.len().min(b.len());
    let whole = n / LANES * LANES;
    let mut s = [0.0; LANES];
    accumulate(&mut s, &a[..whole], &b[..whole]);
    let mut tail = 0.0;
    for k in whole..n {
        tail += a[k] * b[k];
    }
    reduce(s) + tail
}

/// `a . a`.
pub fn sum_sq(a: &[f64]) -> f64 {
    dot(a, a)
}

/// `a . b` for each `b` of `bs` (equal to [`dot`]'s, bit for bit), `a`
/// read once per stretch of rows that stays in the first-level cache.
pub fn dots(a: &[f64], bs: &[&[f64]]) -> Vec<f64> {
    /// Rows per stretch (8 KiB of `a`).
    const BLOCK: usize = 1024;
    let n = bs.iter().fold(a.len(), |m, b| m.min(b.len()));
    let whole = n / LANES * LANES;
    let mut s = vec![[0.0; LANES]; bs.len()];
    let mut tail = vec![0.0; bs.len()];
    let mut start = 0;
    while start < whole {
        let end = (start + BLOCK).min(whole);
        for (sj, b) in s.iter_mut().zip(bs) {
            accumulate(sj, &a[start..end], &b[start..end]);
        }
        start = end;
    }
    // The rows past the last whole group of LANES, as `dot` adds them.
    for (tj, b) in tail.iter_mut().zip(bs) {
        for k in whole..n {
            *tj += a[k] * b[k];
        }
    }
    s.into_iter()
        .zip(tail)
        .map(|(sj, t)| reduce(sj) + t)
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dots_agree_with_a_running_sum_and_with_each_other() {
        for n in [0usize, 1, 7, 8, 9, 1023, 1024, 1025, 5000] {
            let a: Vec<f64> = (0..n)
                .map(|k| ((k * 7919 % 1013) as f64 - 506.0) / 97.0)
                .collect();
            let b: Vec<f64> = (0..n).map(|k| (k as f64 * 0.37).sin()).collect();
            let c: Vec<f64> = (0..n).map(|k| 1.0 + (k % 3) as f64).collect();
            let naive: f64 = a.iter().zip(&b).map(|(x, y)| x * y).sum();
            let scale: f64 = a.iter().zip(&b).map(|(x, y)| (x * y).abs()).sum();
            assert!((dot(&a, &b) - naive).abs() <= 1e-13 * scale.max(1.0), "{n}");
            let v = dots(&a, &[&b, &c]);
            assert_eq!(v[0].to_bits(), dot(&a, &b).to_bits(), "{n}");
            assert_eq!(v[1].to_bits(), dot(&a, &c).to_bits(), "{n}");
        }
        assert_eq!(sum_sq(&[3.0, 4.0]), 25.0);
    }
}
