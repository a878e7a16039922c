//! Overlapping Allan variance of a rate record (docs/noise.md).
//!
//! With theta the angle (cumulative sum of the rate, its mean removed so
//! the sums stay small), the overlapping estimator at averaging factor m is
//! `AVAR(m tau0) = sum_k (theta[k+2m] - 2 theta[k+m] + theta[k])^2 /
//! (2 m^2 (N - 2m + 1))` over the N - 2m + 1 second differences: O(N) per
//! averaging time, summed block by block for every averaging time (the
//! record streamed from memory once, not once per averaging time), the
//! blocks shared out over the cores.

/// Averaging factors up to a third of the record (`n` rate samples): every
/// integer 1..9 (the first decade has no more to offer), then log-spaced at
/// `per_decade` per decade, rounded.
pub fn averaging_factors(n: usize, per_decade: usize) -> Vec<usize> {
    let max = n / 3;
    let mut out: Vec<usize> = (1..10.min(max + 1)).collect();
    let mut i = per_decade as u32;
    loop {
        let m = 10f64.powf(i as f64 / per_decade as f64).round() as usize;
        if m > max {
            break;
        }
        if out.last() != Some(&m) {
            out.push(m);
        }
        i += 1;
    }
    out
}

/// The angle, in rate x samples, with the mean rate removed: theta[0] = 0,
/// theta[k] = sum_{j<k} (y_j - mean).
fn angle(y: &[f64]) -> Vec<f64> {
    let mean = y.iter().sum::<f64>() / y.len().max(1) as f64;
    let mut theta = Vec::with_capacity(y.len() + 1);
    let mut acc = 0.0;
    theta.push(0.0);
    for v in y {
        acc += v - mean;
        theta.push(acc);
    }
    theta
}

/// The second differences are summed in blocks of this many k: for every
/// averaging factor in turn over one block, so the block's angles stay in
/// the core's caches and small factors read their shifted angles from
/// there too (one pass over the record per factor would stream it from
/// memory 58 times for 2e6 samples).
const BLOCK: usize = 4096;

/// Independent partial sums of the second differences: four vectors of
/// four (an add's latency is four cycles; one accumulator would wait on
/// itself every step).
const LANES: usize = 16;

/// Sum over k in lo..hi of (theta[k+2m] - 2 theta[k+m] + theta[k])^2, in
/// [`LANES`] lanes (the compiler vectorizes them), added at the end.
#[inline(always)]
fn second_differences(theta: &[f64], m: usize, lo: usize, hi: usize) -> f64 {
    let len = hi - lo;
    // Three slices of one length, in arrays of LANES: no bounds checks
    // in the loop.
    let t0 = &theta[lo..hi];
    let t1 = &theta[lo + m..lo + m + len];
    let t2 = &theta[lo + 2 * m..lo + 2 * m + len];
    let (a, ra) = t0.as_chunks::<LANES>();
    let (b, rb) = t1.as_chunks::<LANES>();
    let (c, rc) = t2.as_chunks::<LANES>();
    let mut s = [0.0f64; LANES];
    for ((a, b), c) in a.iter().zip(b).zip(c) {
        for l in 0..LANES {
            let d = c[l] - 2.0 * b[l] + a[l];
            s[l] += d * d;
        }
    }
    // The lanes added pairwise, in a fixed order.
    let mut w = LANES;
    while w > 1 {
        w /= 2;
        for l in 0..w {
            s[l] += s[l + w];
        }
    }
    let mut sum = s[0];
    for ((a, b), c) in ra.iter().zip(rb).zip(rc) {
        let d = c - 2.0 * b + a;
        sum += d * d;
    }
    sum
}

/// One block's sums, every averaging factor.
#[inline(always)]
fn block_sums_generic(theta: &[f64], ms: &[usize], b: usize, out: &mut [f64]) {
    let n = theta.len() - 1;
    for (o, &m) in out.iter_mut().zip(ms) {
        let terms = n + 1 - 2 * m;
        let (lo, hi) = (b * BLOCK, ((b + 1) * BLOCK).min(terms));
        *o = if lo < hi {
            second_differences(theta, m, lo, hi)
        } else {
            0.0
        };
    }
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
unsafe fn block_sums_avx2(theta: &[f64], ms: &[usize], b: usize, out: &mut [f64]) {
    block_sums_generic(theta, ms, b, out)
}

/// [`block_sums_generic`], compiled for AVX2 where the processor has it
/// (four lanes a vector instead of SSE2's two; no FMA, so the same
/// roundings and the same sums to the last bit on every machine).
fn block_sums(theta: &[f64], ms: &[usize], b: usize, out: &mut [f64]) {
    #[cfg(target_arch = "x86_64")]
    if std::arch::is_x86_feature_detected!("avx2") {
        // SAFETY: the feature is present (detected just above).
        return unsafe { block_sums_avx2(theta, ms, b, out) };
    }
    block_sums_generic(theta, ms, b, out)
}

/// Overlapping Allan variance of the rate record `y` at the averaging
/// factors `ms` (each at most (len - 1)/2), in the rate's units squared.
/// The blocks are shared out over the cores; their sums are added in the
/// blocks' order, so the answer does not depend on how many there are.
pub fn oavar(y: &[f64], ms: &[usize]) -> Vec<f64> {
    let theta = angle(y);
    let n = y.len();
    let ms: Vec<usize> = ms.iter().map(|&m| m.clamp(1, (n.max(3) - 1) / 2)).collect();
    let blocks = (n + 1).div_ceil(BLOCK).max(1);
    let mut sums = vec![0.0; blocks * ms.len()];
    let threads = std::thread::available_parallelism()
        .map_or(1, |p| p.get())
        .min(blocks);
    if threads <= 1 || n < 100_000 {
        for (b, out) in sums.chunks_mut(ms.len().max(1)).enumerate() {
            block_sums(&theta, &ms, b, out);
        }
    } else {
        // Contiguous runs of blocks per thread: each streams its part of
        // the record once.
        let per = blocks.div_ceil(threads) * ms.len();
        std::thread::scope(|sc| {
            for (t, part) in sums.chunks_mut(per).enumerate() {
                let (theta, ms) = (&theta, &ms);
                sc.spawn(move || {
                    let first = t * per / ms.len();
                    for (j, out) in part.chunks_mut(ms.len()).enumerate() {
                        block_sums(theta, ms, first + j, out);
                    }
                });
            }
        });
    }
    ms.iter()
        .enumerate()
        .map(|(i, &m)| {
            let total: f64 = (0..blocks).map(|b| sums[b * ms.len() + i]).sum();
            let terms = n + 1 - 2 * m;
            total / (2.0 * (m * m) as f64 * terms as f64)
        })
        .collect()
}

/// The definition itself, for cross-checks: cluster averages of m samples
/// summed directly (O(N m) per averaging time), the overlapping differences
/// of consecutive clusters.
pub fn oavar_reference(y: &[f64], ms: &[usize]) -> Vec<f64> {
    let n = y.len();
    let mean = y.iter().sum::<f64>() / n.max(1) as f64;
    ms.iter()
        .map(|&m| {
            let avg = |k: usize| y[k..k + m].iter().map(|v| v - mean).sum::<f64>() / m as f64;
            let terms = n + 1 - 2 * m;
            let s: f64 = (0..terms).map(|k| (avg(k + m) - avg(k)).powi(2)).sum();
            s / (2.0 * terms as f64)
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The NBS 1000-point test suite (NIST SP 1065, section 12.3; Riley):
    /// n[i+1] = 16807 n[i] mod 2147483647 from 1234567890, divided by
    /// 2147483647, as frequency data at tau0 = 1.
    fn nbs_1000() -> Vec<f64> {
        let mut n = 1_234_567_890u64;
        let mut v = Vec::with_capacity(1000);
        for _ in 0..1000 {
            v.push(n as f64 / 2_147_483_647.0);
            n = 16_807 * n % 2_147_483_647;
        }
        v
    }

    #[test]
    fn published_overlapping_adev_of_the_nbs_test_suite() {
        let y = nbs_1000();
        // Published overlapping ADEV at tau = 1, 10, 100 (NIST SP 1065
        // table of the 1000-point test suite).
        let want = [2.922_319e-1, 9.159_953e-2, 3.241_343e-2];
        let got = oavar(&y, &[1, 10, 100]);
        for (g, w) in got.iter().zip(want) {
            assert!((g.sqrt() - w).abs() / w < 5e-7, "{} vs {w}", g.sqrt());
        }
    }

    #[test]
    fn agrees_with_the_definition() {
        // A random walk on white noise (a large mean too): the fast
        // estimator and the definition agree to 1e-9 relative.
        let mut x = 0.5f64;
        let mut walk = 0.0;
        let y: Vec<f64> = (0..5000)
            .map(|_| {
                x = (x * 16_807.0) % 1.0 + 1e-7;
                walk += (x - 0.5) * 0.01;
                50.0 + (x - 0.5) + walk
            })
            .collect();
        let ms = averaging_factors(y.len(), 10);
        assert_eq!(*ms.last().unwrap(), *ms.iter().max().unwrap());
        assert!(*ms.last().unwrap() <= y.len() / 3);
        let a = oavar(&y, &ms);
        let b = oavar_reference(&y, &ms);
        for ((a, b), m) in a.iter().zip(&b).zip(&ms) {
            assert!((a - b).abs() / b < 1e-9, "m {m}: {a} vs {b}");
        }
    }

    #[test]
    fn factors_are_log_spaced() {
        let ms = averaging_factors(30_000, 10);
        assert_eq!(&ms[..9], &[1, 2, 3, 4, 5, 6, 7, 8, 9]);
        // From the second decade on, 10 per decade.
        assert_eq!(ms.iter().filter(|&&m| (10..100).contains(&m)).count(), 10);
        assert_eq!(*ms.last().unwrap(), 10_000);
    }
}
