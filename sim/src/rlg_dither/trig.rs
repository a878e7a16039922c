//! The fringe phase's trigonometry, in f64 or fast in the inner loops'
//! float.

use core::f64::consts::PI;
use num_traits::float::Float;

/// sin and cos of `x` (|x| below a few pi): libm's in f64, or with
/// `fast` ([`Accuracy::fast_trig`]) [`sin_small`] in F.
pub(super) fn sin_cos_in<F: Float>(x: f64, fast: bool) -> (f64, f64) {
    if !fast {
        return x.sin_cos();
    }
    let c = |v: f64| F::from(v).unwrap_or(F::zero());
    let xf = c(x);
    let to = |v: F| v.to_f64().unwrap_or(0.0);
    (to(sin_small(xf)), to(sin_small(xf + c(0.5 * PI))))
}

/// sin for |x| below a few pi (the inner loop's reduced phase): quadrant
/// reduction and the Taylor series on [-pi/4, pi/4] (error below 1e-15;
/// libm's general argument reduction took most of the simulator's time).
pub(super) fn sin_small<F: Float>(x: F) -> F {
    let c = |v: f64| F::from(v).unwrap_or(F::zero());
    let q = (x * c(2.0 / PI)).round();
    let r = x - q * c(PI / 2.0);
    let r2 = r * r;
    let sin = || {
        r * (F::one()
            + r2 * (c(-1.0 / 6.0)
                + r2 * (c(1.0 / 120.0)
                    + r2 * (c(-1.0 / 5040.0)
                        + r2 * (c(1.0 / 362_880.0)
                            + r2 * (c(-1.0 / 39_916_800.0) + r2 * c(1.0 / 6_227_020_800.0)))))))
    };
    let cos = || {
        F::one()
            + r2 * (c(-0.5)
                + r2 * (c(1.0 / 24.0)
                    + r2 * (c(-1.0 / 720.0)
                        + r2 * (c(1.0 / 40_320.0)
                            + r2 * (c(-1.0 / 3_628_800.0)
                                + r2 * (c(1.0 / 479_001_600.0)
                                    + r2 * c(-1.0 / 87_178_291_200.0)))))))
    };
    match q.to_i64().unwrap_or(0).rem_euclid(4) {
        0 => sin(),
        1 => cos(),
        2 => -sin(),
        _ => -cos(),
    }
}

pub(super) fn frac(x: f64) -> f64 {
    x - x.floor()
}
