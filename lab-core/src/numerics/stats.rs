//! Small statistics the lab's estimates share: chi-square quantiles (for
//! intervals from equivalent degrees of freedom) and the standard error of
//! a mean of correlated samples by batch means.

use statrs::function::gamma::gamma_lr;

/// The two-sided 95 % quantile of Student's t with `dof` degrees of
/// freedom (NaN below one: no scatter left to measure a variance from).
pub fn t_975(dof: f64) -> f64 {
    use statrs::distribution::{ContinuousCDF, StudentsT};
    if dof.is_nan() || dof < 1.0 {
        return f64::NAN;
    }
    if dof > 1e7 {
        return 1.959_963_984_540_054;
    }
    StudentsT::new(0.0, 1.0, dof).map_or(f64::NAN, |t| t.inverse_cdf(0.975))
}

/// The `p` quantile of chi-square with `k` degrees of freedom (k > 0).
/// Bisection on the regularized incomplete gamma function; above 10^4
/// degrees of freedom the Wilson-Hilferty cube (relative error below 1e-6
/// there).
pub fn chi2_quantile(p: f64, k: f64) -> f64 {
    let p = p.clamp(1e-12, 1.0 - 1e-12);
    if k > 1e4 {
        wilson_hilferty(p, k)
    } else {
        chi2_bisect(p, k)
    }
}

fn wilson_hilferty(p: f64, k: f64) -> f64 {
    let z = normal_quantile(p);
    let a = 2.0 / (9.0 * k);
    k * (1.0 - a + z * a.sqrt()).powi(3)
}

fn chi2_bisect(p: f64, k: f64) -> f64 {
    let cdf = |x: f64| gamma_lr(k / 2.0, x / 2.0);
    let (mut lo, mut hi) = (0.0, k + 40.0 * (2.0 * k).sqrt() + 100.0);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if cdf(mid) < p {
            lo = mid;
        } else {
            hi = mid;
        }
        if hi - lo <= 1e-12 * hi {
            break;
        }
    }
    0.5 * (lo + hi)
}

/// Standard normal quantile (Acklam's rational approximation, relative
/// error below 1.2e-9, refined by one Halley step).
pub fn normal_quantile(p: f64) -> f64 {
    const A: [f64; 6] = [
        -3.969_683_028_665_376e1,
        2.209_460_984_245_205e2,
        -2.759_285_104_469_687e2,
        1.383_577_518_672_69e2,
        -3.066_479_806_614_716e1,
        2.506_628_277_459_239,
    ];
    const B: [f64; 5] = [
        -5.447_609_879_822_406e1,
        1.615_858_368_580_409e2,
        -1.556_989_798_598_866e2,
        6.680_131_188_771_972e1,
        -1.328_068_155_288_572e1,
    ];
    const C: [f64; 6] = [
        -7.784_894_002_430_293e-3,
        -3.223_964_580_411_365e-1,
        -2.400_758_277_161_838,
        -2.549_732_539_343_734,
        4.374_664_141_464_968,
        2.938_163_982_698_783,
    ];
    const D: [f64; 4] = [
        7.784_695_709_041_462e-3,
        3.224_671_290_700_398e-1,
        2.445_134_137_142_996,
        3.754_408_661_907_416,
    ];
    let p = p.clamp(1e-300, 1.0 - 1e-16);
    let x = if p < 0.02425 {
        let q = (-2.0 * p.ln()).sqrt();
        (((((C[0] * q + C[1]) * q + C[2]) * q + C[3]) * q + C[4]) * q + C[5])
            / ((((D[0] * q + D[1]) * q + D[2]) * q + D[3]) * q + 1.0)
    } else if p <= 1.0 - 0.02425 {
        let q = p - 0.5;
        let r = q * q;
        (((((A[0] * r + A[1]) * r + A[2]) * r + A[3]) * r + A[4]) * r + A[5]) * q
            / (((((B[0] * r + B[1]) * r + B[2]) * r + B[3]) * r + B[4]) * r + 1.0)
    } else {
        let q = (-2.0 * (1.0 - p).ln()).sqrt();
        -(((((C[0] * q + C[1]) * q + C[2]) * q + C[3]) * q + C[4]) * q + C[5])
            / ((((D[0] * q + D[1]) * q + D[2]) * q + D[3]) * q + 1.0)
    };
    let e = 0.5 * statrs::function::erf::erfc(-x / std::f64::consts::SQRT_2) - p;
    let u = e * (2.0 * std::f64::consts::PI).sqrt() * (x * x / 2.0).exp();
    x - u / (1.0 + x * u / 2.0)
}

/// Mean and its standard error by batch means: the samples cut into
/// `batches` consecutive batches of equal length (the tail dropped), the
/// scatter of the batch means over sqrt(batches). Holds for correlated
/// noise as long as a batch is longer than the correlation time. None
/// with fewer than 2 batches' worth of samples.
pub fn batch_mean_se(x: &[f64], batches: usize) -> Option<(f64, f64)> {
    let b = batches.min(x.len());
    if b < 2 {
        return None;
    }
    let len = x.len() / b;
    let means: Vec<f64> = (0..b)
        .map(|i| x[i * len..(i + 1) * len].iter().sum::<f64>() / len as f64)
        .collect();
    let m = means.iter().sum::<f64>() / b as f64;
    let var = means.iter().map(|v| (v - m).powi(2)).sum::<f64>() / (b - 1) as f64;
    Some((m, (var / b as f64).sqrt()))
}

/// Pearson correlation; 0 where either side does not vary (or is not
/// finite).
pub fn pearson(a: &[f64], b: &[f64]) -> f64 {
    let n = a.len().min(b.len());
    if n < 2 {
        return 0.0;
    }
    let ma = a[..n].iter().sum::<f64>() / n as f64;
    let mb = b[..n].iter().sum::<f64>() / n as f64;
    let (mut sab, mut saa, mut sbb) = (0.0, 0.0, 0.0);
    for k in 0..n {
        let (x, y) = (a[k] - ma, b[k] - mb);
        sab += x * y;
        saa += x * x;
        sbb += y * y;
    }
    let r = sab / (saa * sbb).sqrt();
    if r.is_finite() {
        r
    } else {
        0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn chi2_quantiles_match_tables() {
        // Published table values (Abramowitz & Stegun 26.8).
        for (p, k, want) in [
            (0.025, 1.0, 0.000_982_069),
            (0.975, 1.0, 5.023_886),
            (0.025, 2.0, 0.050_635_6),
            (0.975, 10.0, 20.483_18),
            (0.025, 100.0, 74.221_9),
            (0.975, 100.0, 129.561_2),
        ] {
            let got = chi2_quantile(p, k);
            assert!(
                (got - want).abs() < 1e-4 * want.max(1.0),
                "{p} {k}: {got} vs {want}"
            );
        }
        // The large-k form against the exact one at the threshold.
        for p in [0.025, 0.5, 0.975] {
            let a = chi2_bisect(p, 1e4);
            let b = wilson_hilferty(p, 1e4);
            assert!((a - b).abs() / a < 1e-6, "{a} {b}");
        }
        assert!((normal_quantile(0.975) - 1.959_963_985).abs() < 1e-9);
    }

    #[test]
    fn batch_means_of_white_noise() {
        // 1, -1, 1, -1 ...: batch means of 2 are all 0.
        let x: Vec<f64> = (0..100)
            .map(|k| if k % 2 == 0 { 1.0 } else { -1.0 })
            .collect();
        let (m, se) = batch_mean_se(&x, 50).unwrap();
        assert_eq!((m, se), (0.0, 0.0));
        assert!(batch_mean_se(&[1.0], 10).is_none());
    }
}

/// The median of `v`: the element at index len/2 of the sorted values
/// (by `total_cmp`), selected in linear time on a copy. NaN for an empty
/// slice.
pub fn median(v: &[f64]) -> f64 {
    median_mut(&mut v.to_vec())
}

/// The median interval of `t`, s (1 where it has fewer than two rows).
pub fn median_interval(t: &[f64]) -> f64 {
    let mut d: Vec<f64> = t.windows(2).map(|w| w[1] - w[0]).collect();
    if d.is_empty() {
        return 1.0;
    }
    median_mut(&mut d)
}

/// [`median`] of values the caller owns and no longer needs in order:
/// reordered in place, no copy.
pub fn median_mut(v: &mut [f64]) -> f64 {
    if v.is_empty() {
        return f64::NAN;
    }
    let k = v.len() / 2;
    // Selected as integers: `f64::total_cmp`'s order is that of these
    // keys, and integer compares partition about twice as fast (a 2e6-row
    // record takes three medians in its checks). The map is its own
    // inverse, so the values come back as they were, reordered.
    let keys = total_order_keys(v);
    let m = *keys.select_nth_unstable(k).1;
    for x in keys.iter_mut() {
        *x = total_order_key(*x);
    }
    f64::from_bits(total_order_key(m) as u64)
}

/// `x`'s bits as an integer in `f64::total_cmp`'s order (and back again).
#[inline]
fn total_order_key(b: i64) -> i64 {
    b ^ ((((b >> 63) as u64) >> 1) as i64)
}

/// The values as their total-order keys, in place.
fn total_order_keys(v: &mut [f64]) -> &mut [i64] {
    // SAFETY: f64 and i64 have one size and alignment, and every bit
    // pattern is a valid i64; the slice is borrowed mutably, so no f64
    // view of it is alive while the keys are.
    let keys = unsafe { std::slice::from_raw_parts_mut(v.as_mut_ptr().cast::<i64>(), v.len()) };
    for x in keys.iter_mut() {
        *x = total_order_key(*x);
    }
    keys
}

#[cfg(test)]
mod median_tests {
    use super::median;

    #[test]
    fn the_median_is_the_middle_element_of_the_sorted_values() {
        let mut s: u64 = 7;
        let mut r = || {
            s ^= s << 13;
            s ^= s >> 7;
            s ^= s << 17;
            s
        };
        for n in [1usize, 2, 3, 10, 1001, 4096, 20_000, 70_001] {
            for kind in 0..4 {
                let v: Vec<f64> = (0..n)
                    .map(|_| match kind {
                        // Nearly equal intervals, as a clock's.
                        0 => 0.01 + (r() % 5) as f64 * 1e-17,
                        1 => (r() % 1000) as f64 - 500.0,
                        2 => f64::from_bits(r() >> 2) * if r() % 2 == 0 { -1.0 } else { 1.0 },
                        _ => -0.0,
                    })
                    .collect();
                let mut w = v.clone();
                w.sort_by(f64::total_cmp);
                assert_eq!(
                    median(&v).to_bits(),
                    w[n / 2].to_bits(),
                    "n {n} kind {kind}"
                );
            }
        }
        assert!(median(&[]).is_nan());
    }
}
