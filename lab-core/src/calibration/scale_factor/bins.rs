//! The continuous fit works on bin means of consecutive rows at one rate:
//! the temperature moves slowly, and the noise of the means is close to
//! white.

use super::input::SfInput;

/// Bin length of the continuous fit, s.
pub const BIN_S: f64 = 10.0;

/// Bin means of the continuous fit.
pub struct Bins {
    pub w: Vec<f64>,
    /// Mean of output minus reference, deg/s.
    pub r: Vec<f64>,
    pub ts: Vec<f64>,
    pub d: Vec<f64>,
    /// Rows per bin.
    pub n: Vec<f64>,
    /// Bins of one constant-rate stretch share a group number.
    pub group: Vec<usize>,
}

/// The bins of `rows`: runs of consecutive rows at one rate, cut every
/// [`BIN_S`].
pub fn bin(inp: &SfInput, rows: &[usize]) -> Bins {
    let mut b = Bins {
        w: vec![],
        r: vec![],
        ts: vec![],
        d: vec![],
        n: vec![],
        group: vec![],
    };
    let mut group = 0;
    let mut i = 0;
    while i < rows.len() {
        let k0 = rows[i];
        if i > 0 && (rows[i - 1] + 1 != k0 || inp.w[rows[i - 1]] != inp.w[k0]) {
            group += 1;
        }
        let t_end = inp.t[k0] + BIN_S - 1e-9;
        let (mut r, mut ts, mut d, mut n) = (0.0, 0.0, 0.0, 0.0);
        let mut j = i;
        while j < rows.len()
            && inp.t[rows[j]] < t_end
            && inp.w[rows[j]] == inp.w[k0]
            && (j == i || rows[j - 1] + 1 == rows[j])
        {
            let k = rows[j];
            r += inp.y[k] - inp.w[k];
            ts += inp.ts[k];
            d += inp.d[k];
            n += 1.0;
            j += 1;
        }
        b.w.push(inp.w[k0]);
        b.r.push(r / n);
        b.ts.push(ts / n);
        b.d.push(d / n);
        b.n.push(n);
        b.group.push(group);
        i = j;
    }
    b
}
