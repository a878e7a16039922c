//! Modulator drive: square-wave +-phi0/2 bias modulation summed with the serrodyne
//! ramp, one DAC word per half period.
//!
//! The drive phase theta is a wrapping [`Phase`]; its wrap-around is the 2*pi reset.
//! Per half period theta moves by `sign*phi0 - feedback`, so the interferometer sees
//! `phi_s - feedback + sign*phi0` and the loop drives `feedback` to the Sagnac phase.
//! The DAC code is theta scaled by the digital gain (codes per turn, trimmed by the
//! 2*pi loop).
//!
//! Depth dither: the depth of each closure is phi0 + r_k, r_k pseudo-random and
//! uniform. Both half periods' detector levels move together by about
//! `A*sin(phi0)*r_k`, so their difference (the error) is unchanged while the ADC
//! rounding is averaged away over closures: without it a noise-free or quiet
//! detector leaves the loop a dead zone of half an ADC LSB (about 4e-4 rad with a
//! 12-bit ADC).

use crate::phase::Phase;

/// Where the drive phase carried out of the u32 (wrapped) in one closure.
/// Bit i (counted from bit `pairs - 1` down to 0) is pair i's plus or minus
/// half period. Whether a carry is a reset depends on the increment's sign,
/// fixed for all plus (or all minus) halves of a closure: see `Resets::weight`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(crate) struct Resets {
    pub plus: u32,
    pub minus: u32,
    /// The plus (minus) halves' increment is negative: there a reset is a
    /// missing carry (theta wrapped downward), elsewhere a carry (upward).
    pub plus_negative: bool,
    pub minus_negative: bool,
}

#[derive(Clone, Copy, Debug, Default)]
pub(crate) struct Modulator {
    /// Drive phase of the last DAC word written.
    theta: Phase,
}

impl Modulator {
    /// Writes the DAC words of the next closure (one per half period, starting on
    /// +phi0) and returns where the drive phase carried (the 2*pi resets).
    /// `feedback`: feedback phase (phase LSB, taken modulo a turn); `depth`: this
    /// closure's phi0 (+ dither), phase LSB; `codes_per_turn_q8`: DAC codes per turn, Q8.
    /// At most 64 half periods (32 pairs) are written; the reference
    /// instruments' 16 and 32 run a loop unrolled at compile time.
    #[inline(always)]
    pub(crate) fn write_closure<const H: usize>(
        &mut self,
        feedback: Phase,
        depth: Phase,
        codes_per_turn_q8: u32,
        dac: &mut [u16],
    ) -> Resets {
        let d_plus = depth.wrapping_sub(feedback);
        let d_minus = 0u32.wrapping_sub(depth).wrapping_sub(feedback);
        let (plus, minus) = if H == 0 {
            self.write_any(dac, d_plus, d_minus, codes_per_turn_q8)
        } else {
            self.write::<H>(dac, d_plus, d_minus, codes_per_turn_q8)
        };
        Resets {
            plus,
            minus,
            plus_negative: (d_plus as i32) < 0,
            minus_negative: (d_minus as i32) < 0,
        }
    }

    /// `H` half periods (a compile-time count, so the loop unrolls).
    #[inline(always)]
    fn write<const H: usize>(
        &mut self,
        dac: &mut [u16],
        d_plus: Phase,
        d_minus: Phase,
        codes_per_turn_q8: u32,
    ) -> (u32, u32) {
        match dac.first_chunk_mut::<H>() {
            Some(dac) => self.write_any(dac, d_plus, d_minus, codes_per_turn_q8),
            None => (0, 0),
        }
    }

    #[inline(always)]
    fn write_any(
        &mut self,
        dac: &mut [u16],
        d_plus: Phase,
        d_minus: Phase,
        codes_per_turn_q8: u32,
    ) -> (u32, u32) {
        let cpt = codes_per_turn_q8 as u64;
        let mut theta = self.theta;
        let (mut plus, mut minus) = (0u32, 0u32);
        for pair in dac.chunks_exact_mut(2).take(32) {
            // The sums' bit 32 is the carry (adds + adc on the M4).
            let s1 = theta as u64 + d_plus as u64;
            let t1 = s1 as u32;
            let s2 = t1 as u64 + d_minus as u64;
            let t2 = s2 as u32;
            theta = t2;
            plus = (plus << 1) | (s1 >> 32) as u32;
            minus = (minus << 1) | (s2 >> 32) as u32;
            pair.copy_from_slice(&[dac_word(t1, cpt), dac_word(t2, cpt)]);
        }
        self.theta = theta;
        (plus, minus)
    }
}

/// DAC code of drive phase `theta` at `cpt` codes per turn (Q8): the high
/// word of one 32x32 multiply. theta's low 8 bits are dropped first (2^-8 of
/// a code at most); u24 * (<2^24) >> 32 stays below 2^16 while codes_per_turn_q8 < 2^24
/// (config clamps it).
#[inline(always)]
fn dac_word(theta: Phase, cpt: u64) -> u16 {
    (((theta >> 8) as u64 * cpt) >> 32) as u16
}

impl Resets {
    /// Reset weight w_j = r_j * sign_j of half period j of a closure of `n_half`
    /// (r_j = +1 upward reset, -1 downward, 0 none; sign +1 on plus halves).
    /// What `gain_loop::reset_error` sums in closed form; the test's reference.
    #[cfg(test)]
    fn weight(&self, j: usize, n_half: usize) -> i32 {
        let pairs = n_half / 2;
        let bit = pairs.wrapping_sub(1 + j / 2) as u32;
        if j.is_multiple_of(2) {
            let c = (self.plus.checked_shr(bit).unwrap_or(0) & 1) as i32;
            c - self.plus_negative as i32
        } else {
            let c = (self.minus.checked_shr(bit).unwrap_or(0) & 1) as i32;
            self.minus_negative as i32 - c
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    proptest! {
    /// The reset weights mark exactly the half periods whose DAC code jumps by
    /// more than half a turn, with the jump's direction times the modulation sign.
    #[test]
    fn weights_mark_the_resets(feedback in any::<u32>(), depth in 0x1000_0000u32..0x7000_0000) {
        // A DAC jump tells a reset from a plain increment only while increments
        // stay clear of half a turn.
        let clear = |d: u32| (d as i32).unsigned_abs() < 0x7000_0000;
        prop_assume!(clear(depth.wrapping_sub(feedback)) && clear(0u32.wrapping_sub(depth).wrapping_sub(feedback)));
        let codes_per_turn_q8 = 49_152u32 << 8;
        let mut m = Modulator::default();
        let mut dac = [0u16; 16];
        let mut prev = 0i32;
        for _ in 0..10 {
            let c = m.write_closure::<16>(feedback, depth, codes_per_turn_q8, &mut dac);
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
}
