//! Synchronous demodulation of one closure of ADC samples.
//!
//! Half period j has modulation sign +1 for even j, -1 for odd j (each closure starts
//! on +phi0, the convention the epsilon-squared derivation uses). The first
//! `skip` samples after each edge carry the detector transient and are dropped.
//! The same pass sums the half periods where the modulator's drive phase
//! carried (the 2*pi loop's input), so no per-half array is kept.
//!
//! ADC over-range is not searched for here: the ADC's analog watchdog flags any
//! conversion outside [`AWD_LOW`, `AWD_HIGH`] in hardware (STM32 ADC_SR.AWD;
//! the simulator models the same window), and the caller passes that flag in.

use super::modulator::Resets;

/// Analog-watchdog window on the left-aligned 16-bit code (12-bit ADC: 0x10 is
/// one code above zero, 0xFFE0 two codes below full scale).
pub const AWD_LOW: u16 = 0x0010;
pub const AWD_HIGH: u16 = 0xFFE0;

/// Sums of one closure; units are ADC LSB summed over the kept samples.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(crate) struct DemodSums {
    /// sum(sign_j * h_j) over the first half of the closure.
    pub first: i32,
    /// sum(sign_j * h_j) over the second half of the closure.
    pub second: i32,
    /// sum(h_j): the detector DC over the closure.
    pub dc: u32,
    /// sum(h_j) over the plus half periods whose drive phase carried, less
    /// the same over the minus half periods (the 2*pi loop needs only the
    /// difference; one accumulator less in the unrolled loop).
    pub carried: i32,
}

/// Demodulates `adc` (`n_half` half periods of `samples_per_half` samples,
/// `skip` skipped after each edge); `resets` as [`Resets`]. `n_half` must
/// be a multiple of 4 and at most 64 (config checks it). With `H` non-zero
/// the layout is `H` half periods of `S` samples, `SKIP` skipped, known at
/// compile time (the closure's kernel chooses): the loop unrolls.
#[inline(always)]
pub(crate) fn demodulate<const H: usize, const S: usize, const SKIP: usize>(
    adc: &[u16],
    samples_per_half: usize,
    skip: usize,
    n_half: usize,
    resets: &Resets,
) -> DemodSums {
    // Align the masks so pair 0's bit is bit 31.
    let shift = 32u32.saturating_sub((n_half / 2) as u32);
    let masks = (
        resets.plus.checked_shl(shift).unwrap_or(0),
        resets.minus.checked_shl(shift).unwrap_or(0),
    );
    if H != 0 {
        if let Some(d) = fixed::<H, S, SKIP>(adc, masks) {
            return d;
        }
    }
    let adc = adc.get(..n_half * samples_per_half).unwrap_or(adc);
    any(adc, samples_per_half, skip, n_half, masks)
}

/// Sum of the kept samples of one half period.
#[inline(always)]
fn kept<const S: usize>(half: &[u16]) -> u32 {
    half.iter().skip(S).map(|&x| x as u32).sum()
}

/// Plus- and minus-half sums of one half of a closure (`N`-sample halves), with
/// the carried halves' sums; pair k's carry bits are bit `31 - first - k` of
/// the masks. The carry selects by multiplying with the mask bit (no branch;
/// LLVM turns it into a conditional add, three instructions per half).
#[inline(always)]
fn half_step<const N: usize, const S: usize>(
    adc: &[u16],
    d: &mut DemodSums,
    (mp, mm): (u32, u32),
    first: usize,
) -> (u32, u32) {
    let (mut p, mut m) = (0u32, 0u32);
    for (k, pair) in adc.chunks_exact(2 * N).enumerate() {
        let (plus, minus) = pair.split_at(N);
        let (hp, hm) = (kept::<S>(plus), kept::<S>(minus));
        p += hp;
        m += hm;
        let bit = 31 - ((first + k) & 31);
        d.carried += (hp * ((mp >> bit) & 1)) as i32 - (hm * ((mm >> bit) & 1)) as i32;
    }
    (p, m)
}

/// `H` half periods of `N` samples, `S` skipped: compile-time sizes so the
/// loops unroll; `None` if `adc` is shorter (the caller falls back to
/// [`any`]). Plus and minus halves are summed apart and combined once at the end.
#[inline(always)]
fn fixed<const H: usize, const N: usize, const S: usize>(
    adc: &[u16],
    masks: (u32, u32),
) -> Option<DemodSums> {
    let adc = adc.get(..H * N)?;
    let (a_first, a_second) = adc.split_at(H * N / 2);
    let mut d = DemodSums::default();
    let (p1, m1) = half_step::<N, S>(a_first, &mut d, masks, 0);
    let (p2, m2) = half_step::<N, S>(a_second, &mut d, masks, H / 4);
    d.first = p1 as i32 - m1 as i32;
    d.second = p2 as i32 - m2 as i32;
    d.dc = p1 + m1 + p2 + m2;
    Some(d)
}

/// Any layout (runtime sizes); same result as [`fixed`].
fn any(
    adc: &[u16],
    n: usize,
    skip: usize,
    n_half: usize,
    (mut mp, mut mm): (u32, u32),
) -> DemodSums {
    let mut d = DemodSums::default();
    for (j, half) in adc.chunks_exact(n.max(1)).enumerate() {
        let h: u32 = half.iter().skip(skip).map(|&x| x as u32).sum();
        let s = if j % 2 == 0 { h as i32 } else { -(h as i32) };
        if j < n_half / 2 {
            d.first += s;
        } else {
            d.second += s;
        }
        d.dc += h;
        if j % 2 == 0 {
            if (mp as i32) < 0 {
                d.carried += h as i32;
            }
            mp <<= 1;
        } else {
            if (mm as i32) < 0 {
                d.carried -= h as i32;
            }
            mm <<= 1;
        }
    }
    d
}

#[cfg(test)]
mod tests {
    use super::{demodulate, DemodSums, Resets};
    use proptest::prelude::*;
    use std::vec;

    /// Straightforward demodulation, half period by half period.
    fn reference(adc: &[u16], n: usize, skip: usize, halves: usize, c: &Resets) -> DemodSums {
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

    proptest! {
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
            let c = Resets { plus: plus & keep, minus: minus & keep, ..Resets::default() };
            let want = reference(a, n, skip, halves, &c);
            prop_assert_eq!(demodulate::<0, 0, 0>(a, n, skip, halves, &c), want);
            // The unrolled copies, where the layout is theirs.
            match (halves, n, skip) {
                (16, 4, 1) => prop_assert_eq!(demodulate::<16, 4, 1>(a, n, skip, halves, &c), want),
                (32, 4, 1) => prop_assert_eq!(demodulate::<32, 4, 1>(a, n, skip, halves, &c), want),
                _ => {}
            }
        }
    }
}
