//! Second loop: 2*pi gain control.
//!
//! If the DAC-to-phase gain is (1 + g) turns per nominal turn, a reset leaves a
//! phase error of `-2*pi*g*w` for one half period (w = +1 for an upward reset).
//! With the half period's residual estimate `d_j = -sign_j*(h_j - H)*cot(phi0/2)/H`,
//! `sum_j w_j*sign_j*(h_j - H)` over the reset half periods is proportional to +g;
//! integrating it against the digital gain (codes per turn) keeps a reset exactly 2*pi.

use super::modulator::Resets;

/// Returns sum_j w_j * sign_j * (h_j - mean(h)) over the half periods with a reset.
#[inline(always)]
pub fn reset_error(halves: &[u32], resets: Resets, dc: u32) -> i32 {
    let n = halves.len() as u32;
    let mean = (dc / n.max(1)) as i32;
    let mut acc = 0i32;
    let mut bits = resets.up | resets.down;
    while bits != 0 {
        let j = bits.trailing_zeros();
        bits &= bits - 1;
        if let Some(&h) = halves.get(j as usize) {
            let dev = h as i32 - mean;
            let w_sign_positive = ((resets.up >> j) & 1 == 1) == j.is_multiple_of(2);
            acc += if w_sign_positive { dev } else { -dev };
        }
    }
    acc
}

/// New digital gain (DAC codes per turn, Q8) after one step's reset error.
/// `gain_q16`: loop gain in Q8 codes per unit normalised error, Q16;
/// `recip_h`: 2^32 / H (H = DC of one half period's kept samples).
#[inline(always)]
pub fn update(cpt_q8: u32, err: i32, gain_q16: i64, recip_h: u32, min: u32, max: u32) -> u32 {
    // err < 2^21, gain_q16 < 2^40: the product is below 2^61.
    let scaled = (err as i64 * gain_q16) >> 16;
    let delta = (scaled.clamp(-(1 << 30), 1 << 30) * recip_h as i64) >> 32;
    (cpt_q8 as i64 - delta).clamp(min as i64, max as i64) as u32
}
