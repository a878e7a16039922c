//! Synchronous demodulation of one closure step of ADC samples.
//!
//! Half period j has modulation sign +1 for even j, -1 for odd j (each step starts
//! on +phi0, the convention the epsilon-squared derivation uses). The first
//! `skip` samples after each edge carry the detector transient and are dropped.
//! The same pass sums the half periods where the modulator's drive phase
//! carried (the 2*pi loop's input), so no per-half array is kept.
//!
//! ADC over-range is not searched for here: the ADC's analog watchdog flags any
//! conversion outside [`AWD_LOW`, `AWD_HIGH`] in hardware (STM32 ADC_SR.AWD;
//! the simulator models the same window), and the caller passes that flag in.

use super::modulator::Carries;

/// Analog-watchdog window on the left-aligned 16-bit code (12-bit ADC: 0x10 is
/// one code above zero, 0xFFE0 two codes below full scale).
pub const AWD_LOW: u16 = 0x0010;
pub const AWD_HIGH: u16 = 0xFFE0;

/// Sums of one step; units are ADC LSB summed over the kept samples.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct DemodSums {
    /// sum(sign_j * h_j) over the first half of the step.
    pub first: i32,
    /// sum(sign_j * h_j) over the second half of the step.
    pub second: i32,
    /// sum(h_j): the detector DC over the step.
    pub dc: u32,
    /// sum(h_j) over the plus (minus) half periods whose drive phase carried.
    pub carried_plus: u32,
    pub carried_minus: u32,
}

/// Demodulates `adc` (`n_half` half periods of `samples_per_half` samples);
/// `carries` as [`Carries`]. `n_half` must be a multiple of 4 and at most 64
/// (config checks it); the common sample layouts run a loop unrolled at
/// compile time.
#[inline(always)]
pub fn demodulate(
    adc: &[u16],
    samples_per_half: usize,
    skip: usize,
    n_half: usize,
    carries: &Carries,
) -> DemodSums {
    // Align the masks so pair 0's bit is bit 31.
    let shift = 32u32.saturating_sub((n_half / 2) as u32);
    let masks = (
        carries.plus.checked_shl(shift).unwrap_or(0),
        carries.minus.checked_shl(shift).unwrap_or(0),
    );
    let adc = adc.get(..n_half * samples_per_half).unwrap_or(adc);
    match (samples_per_half, skip) {
        (4, 1) => fixed::<4, 1>(adc, n_half, masks),
        (4, 2) => fixed::<4, 2>(adc, n_half, masks),
        (2, 1) => fixed::<2, 1>(adc, n_half, masks),
        (8, 2) => fixed::<8, 2>(adc, n_half, masks),
        _ => any(adc, samples_per_half, skip, n_half, masks),
    }
}

/// Sum of the kept samples of one half period.
#[inline(always)]
fn kept<const S: usize>(half: &[u16]) -> u32 {
    half.iter().skip(S).map(|&x| x as u32).sum()
}

/// `h` if the mask's top bit is set, else 0 (branch-free).
#[inline(always)]
fn if_top(mask: u32, h: u32) -> u32 {
    h & ((mask as i32 >> 31) as u32)
}

#[inline(always)]
fn fixed<const N: usize, const S: usize>(
    adc: &[u16],
    n_half: usize,
    (mut mp, mut mm): (u32, u32),
) -> DemodSums {
    let mut d = DemodSums::default();
    let (a_first, a_second) = adc.split_at((n_half / 2 * N).min(adc.len()));
    for (adc, acc) in [(a_first, &mut d.first), (a_second, &mut d.second)] {
        for pair in adc.chunks_exact(2 * N) {
            let (plus, minus) = pair.split_at(N);
            let (hp, hm) = (kept::<S>(plus), kept::<S>(minus));
            *acc += hp as i32 - hm as i32;
            d.dc += hp + hm;
            d.carried_plus += if_top(mp, hp);
            d.carried_minus += if_top(mm, hm);
            mp <<= 1;
            mm <<= 1;
        }
    }
    d
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
            d.carried_plus += if_top(mp, h);
            mp <<= 1;
        } else {
            d.carried_minus += if_top(mm, h);
            mm <<= 1;
        }
    }
    d
}
