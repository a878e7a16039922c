//! The FOG core's building blocks against plain reference implementations.

use gyro_sp::fog::demod::{demodulate, DemodSums};
use gyro_sp::fog::modulator::{Carries, Modulator};
use proptest::prelude::*;

/// Straightforward demodulation, half period by half period.
fn reference(adc: &[u16], n: usize, skip: usize, halves: usize, c: &Carries) -> DemodSums {
    let mut d = DemodSums::default();
    for (j, half) in adc.chunks(n).take(halves).enumerate() {
        let h: u32 = half[skip..].iter().map(|&x| x as u32).sum();
        let s = if j % 2 == 0 { h as i32 } else { -(h as i32) };
        if j < halves / 2 {
            d.first += s
        } else {
            d.second += s
        }
        d.dc += h;
        let pair_bit = halves / 2 - 1 - j / 2;
        if j % 2 == 0 && c.plus >> pair_bit & 1 == 1 {
            d.carried += h as i32;
        }
        if j % 2 == 1 && c.minus >> pair_bit & 1 == 1 {
            d.carried -= h as i32;
        }
    }
    d
}

/// The table-based count and index moment of carry masks against the plain
/// bit loop, every 8- and 16-bit mask; bits above the step's pairs ignored.
#[test]
fn mask_moment_matches_bit_loop() {
    use gyro_sp::fog::gain_loop::moment;
    let naive = |m: u32, pairs: u32| {
        let m = m & ((1u64 << pairs) - 1) as u32;
        let weighted: u32 = (0..32).filter(|b| (m >> b) & 1 == 1).sum();
        (m.count_ones(), weighted)
    };
    for m in 0..65_536u32 {
        for pairs in [2, 4, 6, 8, 10, 16, 32] {
            let mask = m | (m << 16) | 0x8000_0000;
            let got = moment(mask, pairs as i32);
            assert_eq!(
                (got.count, got.weighted),
                naive(mask, pairs),
                "mask {mask:#x} pairs {pairs}"
            );
        }
    }
}

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
        use gyro_sp::fog::shr_saturate;
        let y = (x >> scale) + edge;
        let edges = [47, 43, 36].map(|k| [(1i64 << k) + edge, -(1i64 << k) + edge]);
        for v in [x, y].into_iter().chain(edges.into_iter().flatten()) {
            prop_assert_eq!(shr_saturate::<16, 32>(v), shr_clamp(v, 16, 32));
            prop_assert_eq!(shr_saturate::<23, 21>(v), shr_clamp(v, 23, 21));
            prop_assert_eq!(shr_saturate::<8, 29>(v), shr_clamp(v, 8, 29));
        }
    }

    /// Every sample layout (the unrolled ones and the runtime fallback) gives
    /// the reference sums.
    #[test]
    fn demodulation_matches_reference(
        adc in proptest::collection::vec(any::<u16>(), 32 * 8),
        plus in any::<u32>(),
        minus in any::<u32>(),
        layout in prop::sample::select(vec![(4usize, 1usize), (4, 2), (2, 1), (8, 2), (4, 0), (8, 3), (3, 1)]),
        halves in prop::sample::select(vec![4usize, 16, 32]),
    ) {
        let (n, skip) = layout;
        let a = &adc[..halves * n];
        let keep = u32::MAX >> (32 - halves / 2);
        let c = Carries { plus: plus & keep, minus: minus & keep, ..Carries::default() };
        prop_assert_eq!(demodulate(a, n, skip, halves, &c), reference(a, n, skip, halves, &c));
    }

    /// The reset weights mark exactly the half periods whose DAC code jumps by
    /// more than half a turn, with the jump's direction times the modulation sign.
    #[test]
    fn modulator_weights_mark_the_resets(step in any::<u32>(), depth in 0x1000_0000u32..0x7000_0000) {
        // A DAC jump tells a reset from a plain increment only while increments
        // stay clear of half a turn.
        let clear = |d: u32| (d as i32).unsigned_abs() < 0x7000_0000;
        prop_assume!(clear(depth.wrapping_sub(step)) && clear(0u32.wrapping_sub(depth).wrapping_sub(step)));
        let cpt_q8 = 49_152u32 << 8;
        let mut m = Modulator::default();
        let mut dac = [0u16; 16];
        let mut prev = 0i32;
        for _ in 0..10 {
            let c = m.write_step(step, depth, cpt_q8, &mut dac);
            for (j, &d) in dac.iter().enumerate() {
                let jump = d as i32 - prev;
                prev = d as i32;
                let r = if jump < -24_576 { 1 } else if jump > 24_576 { -1 } else { 0 };
                let sign = if j % 2 == 0 { 1 } else { -1 };
                prop_assert_eq!(c.weight(j, 16), r * sign, "half {}", j);
            }
        }
    }
}
