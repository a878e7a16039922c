//! The outside generator's own random numbers: PCG-XSL-RR 128/64 words
//! (a 128-bit LCG with a xorshift-rotate output), uniforms from their top
//! 53 bits, and normals by inverting the normal CDF (Acklam's rational
//! approximation, relative error below 1.2e-9). The project's generators
//! use xoshiro with Box-Muller (model_run.rs, heldout_run/) and SplitMix64
//! with Marsaglia's polar method (third_run/): none shares a stream or a
//! transform with this one.

const MUL: u128 = 0x2360_ED05_1FC6_5DA4_4385_DF64_9FCC_F645;

/// PCG64 (XSL-RR output).
pub struct Rng {
    state: u128,
    inc: u128,
}

impl Rng {
    /// A stream from a seed and a stream number (any two differ).
    pub fn new(seed: u64, stream: u64) -> Self {
        let inc = (((u128::from(stream) << 1) | 1) ^ (0x5851_F42D_4C95_7F2D_u128 << 64)) | 1;
        let mut r = Self { state: 0, inc };
        r.step();
        r.state = r
            .state
            .wrapping_add(u128::from(seed) ^ (0xDA3E_39CB_94B9_5BDB_u128 << 17));
        r.step();
        r
    }

    fn step(&mut self) {
        self.state = self.state.wrapping_mul(MUL).wrapping_add(self.inc);
    }

    pub fn word(&mut self) -> u64 {
        self.step();
        let s = self.state;
        let x = ((s >> 64) as u64) ^ (s as u64);
        x.rotate_right((s >> 122) as u32)
    }

    /// Uniform in (0, 1), never 0 or 1.
    pub fn unit(&mut self) -> f64 {
        ((self.word() >> 11) as f64 + 0.5) / (1u64 << 53) as f64
    }

    /// Uniform in [a, b].
    pub fn uniform(&mut self, a: f64, b: f64) -> f64 {
        a + (b - a) * self.unit()
    }

    /// Uniform in [a, b] with a random sign.
    pub fn either_sign(&mut self, a: f64, b: f64) -> f64 {
        let v = self.uniform(a, b);
        if self.word() >> 63 == 0 {
            v
        } else {
            -v
        }
    }

    /// An index below `n`.
    pub fn index(&mut self, n: usize) -> usize {
        (self.unit() * n.max(1) as f64) as usize % n.max(1)
    }

    /// A standard normal, by the inverse CDF of a uniform.
    pub fn gauss(&mut self) -> f64 {
        inverse_normal_cdf(self.unit())
    }
}

/// Acklam's approximation to the standard normal quantile, p in (0, 1).
pub fn inverse_normal_cdf(p: f64) -> f64 {
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
    const LOW: f64 = 0.02425;
    let tail = |q: f64| {
        (((((C[0] * q + C[1]) * q + C[2]) * q + C[3]) * q + C[4]) * q + C[5])
            / ((((D[0] * q + D[1]) * q + D[2]) * q + D[3]) * q + 1.0)
    };
    if p < LOW {
        tail((-2.0 * p.ln()).sqrt())
    } else if p > 1.0 - LOW {
        -tail((-2.0 * (1.0 - p).ln()).sqrt())
    } else {
        let q = p - 0.5;
        let r = q * q;
        (((((A[0] * r + A[1]) * r + A[2]) * r + A[3]) * r + A[4]) * r + A[5]) * q
            / (((((B[0] * r + B[1]) * r + B[2]) * r + B[3]) * r + B[4]) * r + 1.0)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quantiles_match_the_normal_table() {
        // Published quantiles of the standard normal.
        for (p, z) in [
            (0.5, 0.0),
            (0.975, 1.959_963_985),
            (0.841_344_746, 1.0),
            (0.001, -3.090_232_306),
            (0.01, -2.326_347_874),
        ] {
            assert!((inverse_normal_cdf(p) - z).abs() < 1e-7, "{p}");
        }
    }

    #[test]
    fn normals_have_unit_variance_and_normal_tails() {
        let mut r = Rng::new(3, 1);
        let n = 400_000;
        let (mut s, mut s2, mut beyond2) = (0.0, 0.0, 0usize);
        for _ in 0..n {
            let x = r.gauss();
            s += x;
            s2 += x * x;
            beyond2 += usize::from(x.abs() > 2.0);
        }
        let m = s / n as f64;
        assert!(m.abs() < 0.006, "{m}");
        assert!((s2 / n as f64 - 1.0).abs() < 0.01);
        // P(|z| > 2) = 0.0455; its standard error here is 3.3e-4.
        let f = beyond2 as f64 / n as f64;
        assert!((f - 0.0455).abs() < 0.0015, "{f}");
    }

    #[test]
    fn streams_differ() {
        let a: Vec<u64> = (0..4).map(|_| Rng::new(1, 1).word()).collect();
        let mut r1 = Rng::new(1, 1);
        let mut r2 = Rng::new(1, 2);
        let mut r3 = Rng::new(2, 1);
        let x: Vec<u64> = (0..4).map(|_| r1.word()).collect();
        let y: Vec<u64> = (0..4).map(|_| r2.word()).collect();
        let z: Vec<u64> = (0..4).map(|_| r3.word()).collect();
        assert_eq!(a[0], x[0]);
        assert!(x != y && x != z && y != z);
    }
}
