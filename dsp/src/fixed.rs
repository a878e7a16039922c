//! Fixed-point helpers the blocks share: each compiles to one or two
//! Cortex-M4 instructions, so the formats can be chosen for range without
//! 64-bit clamps in the interrupt.

/// `x >> S` saturated to the signed `B`-bit range (`S + B` in 33..=64, `B` <= 32).
/// The high word alone decides whether it fits, so this is one `ssat`, a compare
/// and a select on the M4, not a 64-bit clamp.
#[inline(always)]
pub fn shr_saturate<const S: u32, const B: u32>(x: i64) -> i32 {
    let hi = (x >> 32) as i32;
    let lim = 1i32 << (S + B - 33);
    if hi.clamp(-lim, lim - 1) == hi {
        (x >> S) as i32
    } else {
        (hi >> 31) ^ (i32::MAX >> (32 - B))
    }
}

/// High word of the signed 64-bit product: a Q32 multiply (`smmul`).
#[inline(always)]
pub fn smmul(a: i32, b: i32) -> i32 {
    ((a as i64 * b as i64) >> 32) as i32
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// `x >> S` clamped to `B` signed bits, the slow way.
    fn shr_clamp(x: i64, s: u32, b: u32) -> i32 {
        (x >> s).clamp(-(1i64 << (b - 1)), (1i64 << (b - 1)) - 1) as i32
    }

    proptest! {
        /// The closure's high-word saturation equals a plain clamp, for the
        /// (shift, width) pairs the closure and the 2*pi loop use, at any input
        /// and at the range edges.
        #[test]
        fn shr_saturate_matches_clamp(x in any::<i64>(), edge in -3i64..3, scale in 0u32..63) {
            let y = (x >> scale) + edge;
            let edges = [47, 43, 36].map(|k| [(1i64 << k) + edge, -(1i64 << k) + edge]);
            for v in [x, y].into_iter().chain(edges.into_iter().flatten()) {
                prop_assert_eq!(shr_saturate::<16, 32>(v), shr_clamp(v, 16, 32));
                prop_assert_eq!(shr_saturate::<12, 32>(v), shr_clamp(v, 12, 32));
                prop_assert_eq!(shr_saturate::<12, 29>(v), shr_clamp(v, 12, 29));
                prop_assert_eq!(shr_saturate::<23, 21>(v), shr_clamp(v, 23, 21));
                prop_assert_eq!(shr_saturate::<8, 29>(v), shr_clamp(v, 8, 29));
            }
        }

        /// smmul is floor(a*b / 2^32): the product lies in [h, h + 1) * 2^32.
        #[test]
        fn smmul_is_the_floored_high_word(a in any::<i32>(), b in any::<i32>()) {
            let (h, p) = (smmul(a, b) as i128, a as i128 * b as i128);
            prop_assert!(h << 32 <= p && p < (h + 1) << 32);
        }
    }
}
