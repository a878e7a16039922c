//! One-dimensional searches the fits share: the minimum of a cost over a
//! parameter (a grid, then golden section) and the profile-likelihood
//! interval around it. Used for knee temperatures, sensor lags, warm-up time
//! constants and lock-in rates (scale_factor::fit, discover).

/// Minimum of `f` on [a, b] by golden section: (x, f(x)).
pub fn golden(mut f: impl FnMut(f64) -> f64, mut a: f64, mut b: f64, iters: usize) -> (f64, f64) {
    let g = 0.618_033_988_749_895;
    let (mut c, mut e) = (b - g * (b - a), a + g * (b - a));
    let (mut fc, mut fe) = (f(c), f(e));
    for _ in 0..iters {
        if fc < fe {
            b = e;
            e = c;
            fe = fc;
            c = b - g * (b - a);
            fc = f(c);
        } else {
            a = c;
            c = e;
            fc = fe;
            e = a + g * (b - a);
            fe = f(e);
        }
    }
    let ends = [(a, f(a)), (b, f(b)), (c, fc), (e, fe)];
    ends.into_iter()
        .min_by(|x, y| x.1.total_cmp(&y.1))
        .unwrap_or((a, f64::INFINITY))
}

/// Minimum of `f` over `grid` (sorted), refined by golden section between
/// the best point's neighbours: (x, f(x)).
pub fn grid_then_golden(mut f: impl FnMut(f64) -> f64, grid: &[f64], iters: usize) -> (f64, f64) {
    if grid.is_empty() {
        return (f64::NAN, f64::INFINITY);
    }
    let vals: Vec<f64> = grid.iter().map(|&x| f(x)).collect();
    let i = (0..grid.len())
        .min_by(|&x, &y| vals[x].total_cmp(&vals[y]))
        .unwrap_or(0);
    let (a, b) = (grid[i.saturating_sub(1)], grid[(i + 1).min(grid.len() - 1)]);
    let (x, fx) = golden(&mut f, a, b, iters);
    if fx <= vals[i] {
        (x, fx)
    } else {
        (grid[i], vals[i])
    }
}

/// Profile interval of a scalar: scans from `x0` in steps of `step` each
/// way until `prof(x) - cost_min` exceeds `thr` or a bound is reached;
/// linear interpolation at the crossing.
pub fn profile_interval(
    prof: impl Fn(f64) -> f64,
    x0: f64,
    cost_min: f64,
    thr: f64,
    step: f64,
    (lo, hi): (f64, f64),
) -> (f64, f64) {
    let side = |dir: f64, bound: f64| {
        let (mut x, mut dprev) = (x0, 0.0);
        loop {
            let nx = x + dir * step;
            if (dir > 0.0 && nx > bound) || (dir < 0.0 && nx < bound) {
                return bound;
            }
            let dv = prof(nx) - cost_min;
            if dv > thr {
                let f = ((thr - dprev) / (dv - dprev)).clamp(0.0, 1.0);
                return x + dir * step * f;
            }
            x = nx;
            dprev = dv.max(0.0);
        }
    };
    (side(-1.0, lo), side(1.0, hi))
}

/// 95 % point of chi-square with one degree of freedom (profile intervals).
pub const CHI2_1_95: f64 = 3.841_458_820_694_124;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finds_a_parabola_and_its_interval() {
        let f = |x: f64| (x - 1.3).powi(2);
        let (x, _) = grid_then_golden(f, &[-5.0, -2.0, 0.0, 2.0, 5.0], 40);
        assert!((x - 1.3).abs() < 1e-6);
        // (x - 1.3)^2 <= 0.25: [0.8, 1.8].
        let (lo, hi) = profile_interval(f, 1.3, 0.0, 0.25, 0.01, (-10.0, 10.0));
        assert!(
            (lo - 0.8).abs() < 1e-3 && (hi - 1.8).abs() < 1e-3,
            "{lo} {hi}"
        );
        let (_, hi) = profile_interval(f, 1.3, 0.0, 0.25, 0.01, (-10.0, 1.5));
        assert_eq!(hi, 1.5);
    }
}
