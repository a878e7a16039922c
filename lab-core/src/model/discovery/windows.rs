//! The averaging windows of discovery: the residual and every regressor
//! are averaged over the same windows (1 s: the gap's averaging), so the
//! fit is of what the gap measures and the noise of a window mean is close
//! to white.

/// Windows of the run: row -> window, rows per window, window mid time.
pub struct Windows {
    pub idx: Vec<usize>,
    pub count: Vec<f64>,
    pub t: Vec<f64>,
}

impl Windows {
    /// Windows of `len_s` seconds from the first row (a row every `len_s`
    /// or slower is a window of its own).
    pub fn new(t: &[f64], len_s: f64) -> Self {
        let mut idx = Vec::with_capacity(t.len());
        let (mut count, mut tsum): (Vec<f64>, Vec<f64>) = (vec![], vec![]);
        let t0 = t.first().copied().unwrap_or(0.0);
        let mut last: Option<i64> = None;
        for &tk in t {
            let w = ((tk - t0) / len_s).floor() as i64;
            if last != Some(w) {
                count.push(0.0);
                tsum.push(0.0);
                last = Some(w);
            }
            let i = count.len() - 1;
            count[i] += 1.0;
            tsum[i] += tk;
            idx.push(i);
        }
        let t = tsum.iter().zip(&count).map(|(s, c)| s / c).collect();
        Self { idx, count, t }
    }

    pub fn len(&self) -> usize {
        self.count.len()
    }

    pub fn is_empty(&self) -> bool {
        self.count.is_empty()
    }

    pub fn mean(&self, x: &[f64]) -> Vec<f64> {
        let mut s = vec![0.0; self.len()];
        for (k, &v) in x.iter().enumerate() {
            s[self.idx[k]] += v;
        }
        s.iter().zip(&self.count).map(|(a, c)| a / c).collect()
    }
}
