//! Second loop: 2*pi gain control.
//!
//! If the DAC-to-phase gain is (1 + g) turns per nominal turn, a reset leaves a
//! phase error of `-2*pi*g*w` for one half period (w = +1 for an upward reset).
//! With the half period's residual estimate `d_j = -sign_j*(h_j - H)*cot(phi0/2)/H`,
//! `sum_j w_j*sign_j*(h_j - H)` over the reset half periods is proportional to +g;
//! integrating it against the digital gain (codes per turn) keeps a reset exactly 2*pi.

use super::demod::DemodSums;
use super::modulator::Carries;

/// Returns sum_j w_j * (h_j - mean(h)) - r_j * e over the step, w_j = r_j *
/// sign_j, r_j the reset direction (see [`Carries::weight`]) and e the step's
/// mean of sign_j * h_j, from the demodulator's
/// sums: over plus halves sum(w*h) = carried - [negative]*all, over minus
/// halves [negative]*all - carried. |result| < 2^27 (kept sums below 2^20,
/// at most 64 half periods).
#[inline(always)]
pub fn reset_error(sums: &DemodSums, carries: &Carries, n_half: u32) -> i32 {
    let pairs = (n_half / 2) as i32;
    let (neg_p, neg_m) = (carries.plus_negative as i32, carries.minus_negative as i32);
    // Plus and minus totals from dc = P + M and P - M = first + second.
    let diff = sums.first + sums.second;
    let plus_all = (sums.dc as i32 + diff) / 2;
    let minus_all = (sums.dc as i32 - diff) / 2;
    let weighted =
        sums.carried_plus as i32 - neg_p * plus_all + neg_m * minus_all - sums.carried_minus as i32;
    let (n_plus, n_minus) = (
        carry_count(carries.plus, pairs) as i32,
        carry_count(carries.minus, pairs) as i32,
    );
    let w_sum = n_plus - n_minus + (neg_m - neg_p) * pairs;
    let mean = (sums.dc / n_half.max(1)) as i32;
    // The step's common residual (mean of sign_j*h_j: the main loop's error, or
    // the lag under acceleration) shows at every half period, reset or not;
    // taken out per reset (sum of reset directions r_sum) so that only the
    // reset's own phase error remains: the number of resets in a step
    // correlates with the dither and the rate, and would bias the gain.
    let r_sum = n_plus + n_minus - (neg_p + neg_m) * pairs;
    let common = (diff * r_sum) / n_half.max(1) as i32;
    weighted - mean * w_sum - common
}

/// Set bits of a carry mask of `pairs` bits. The M4 has no popcount
/// instruction; up to 8 bits (16 half periods) two multiplies spread the bits
/// into nibbles and sum them (Bit Twiddling Hacks), else the general count.
#[inline(always)]
pub fn carry_count(mask: u32, pairs: i32) -> u32 {
    if pairs <= 8 {
        let spread = ((mask & 0xFF).wrapping_mul(0x0804_0201) >> 3) & 0x1111_1111;
        spread.wrapping_mul(0x1111_1111) >> 28
    } else {
        mask.count_ones()
    }
}

/// New digital gain (DAC codes per turn, Q8) after one step's reset error.
/// `gain`: Q8 codes per unit normalised error (err/H), below 2^27;
/// `recip_h`: 2^32 / H (H = DC of one half period's kept samples).
#[inline(always)]
pub fn update(cpt_q8: u32, err: i32, gain: i32, recip_h: u32, min: u32, max: u32) -> u32 {
    // |err| <= 2^20 (beyond is not a gain error but a lost loop): one `ssat`.
    let err = err.clamp(-(1 << 20), (1 << 20) - 1) as i64;
    // err/H in Q24, saturated at |err/H| < 16 (a 25 % gain error, the
    // clamp's end, gives a few units): only a wild start converges slower.
    let e_q24 = super::shr_saturate::<8, 29>(err * recip_h as i64) as i64;
    // Q24 x gain >> 24 = Q8 codes, rounded; |delta| < 2^31.
    let delta = ((e_q24 * gain as i64 + (1 << 23)) >> 24) as i32;
    // cpt_q8, min, max < 2^24 (config); the subtraction saturates.
    (cpt_q8 as i32)
        .saturating_sub(delta)
        .max(min as i32)
        .min(max as i32) as u32
}
