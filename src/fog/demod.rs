//! Synchronous demodulation of one closure step of ADC samples.
//!
//! Half period j has modulation sign +1 for even j, -1 for odd j (each step starts
//! on +phi0, the convention the epsilon-squared derivation uses). The first
//! `skip` samples after each edge carry the detector transient and are dropped.

/// ADC codes at or beyond these count as saturated (left-aligned 12-bit tops at 0xFFF0).
pub const ADC_RAIL_LOW: u16 = 0x0010;
pub const ADC_RAIL_HIGH: u16 = 0xFFE0;

/// Sums of one step; units are ADC LSB summed over the kept samples.
#[derive(Clone, Copy, Debug, Default)]
pub struct DemodSums {
    /// sum(sign_j * h_j) over the first half of the step.
    pub first: i32,
    /// sum(sign_j * h_j) over the second half of the step.
    pub second: i32,
    /// sum(h_j): the detector DC over the step.
    pub dc: u32,
    /// A kept sample touched a rail.
    pub saturated: bool,
}

/// Demodulates `adc` (n_half * samples_per_half samples) and stores each half
/// period's kept-sample sum h_j in `halves` (for the 2*pi loop).
#[inline(always)]
pub fn demodulate(
    adc: &[u16],
    samples_per_half: usize,
    skip: usize,
    halves: &mut [u32],
) -> DemodSums {
    let n_half = halves.len();
    let mut signed = [0i32; 2];
    let mut dc = 0u32;
    let mut lo = u16::MAX;
    let mut hi = 0u16;
    for (j, (chunk, h)) in adc
        .chunks_exact(samples_per_half)
        .zip(halves.iter_mut())
        .enumerate()
    {
        let mut sum = 0u32;
        for &x in chunk.iter().skip(skip) {
            sum += x as u32;
            lo = lo.min(x);
            hi = hi.max(x);
        }
        *h = sum;
        dc += sum;
        let s = if j % 2 == 0 {
            sum as i32
        } else {
            -(sum as i32)
        };
        if let Some(acc) = signed.get_mut(usize::from(2 * j >= n_half)) {
            *acc += s;
        }
    }
    DemodSums {
        first: signed[0],
        second: signed[1],
        dc,
        saturated: lo <= ADC_RAIL_LOW || hi >= ADC_RAIL_HIGH,
    }
}
