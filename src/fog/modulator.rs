//! Modulator drive: square-wave +-phi0/2 bias modulation summed with the serrodyne
//! ramp, one DAC word per half period.
//!
//! The drive phase theta is a wrapping [`Phase`]; its wrap-around is the 2*pi reset.
//! Per half period theta moves by `sign*phi0 - step`, so the interferometer sees
//! `phi_s - step + sign*phi0` and the loop drives `step` to the Sagnac phase.
//! The DAC code is theta scaled by the digital gain (codes per turn, trimmed by the
//! 2*pi loop).
//!
//! Depth dither: the depth of each step is phi0 + r_k, r_k pseudo-random and
//! uniform. Both half periods' detector levels move together by about
//! `A*sin(phi0)*r_k`, so their difference (the error) is unchanged while the ADC
//! rounding is averaged away over steps: without it a noise-free or quiet
//! detector leaves the loop a dead zone of half an ADC LSB (about 4e-4 rad with a
//! 12-bit ADC).

use crate::Phase;

/// Which half periods of a step carry a 2*pi reset, and in which direction.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Resets {
    /// Bit j: theta overflowed upward (the DAC code fell by about a turn).
    pub up: u64,
    /// Bit j: theta underflowed (the DAC code rose by about a turn).
    pub down: u64,
}

#[derive(Clone, Copy, Debug, Default)]
pub struct Modulator {
    /// Drive phase of the last DAC word written.
    theta: Phase,
}

impl Modulator {
    /// Writes the DAC words of the next step (one per half period, starting on +phi0)
    /// and says where the resets fall.
    /// `step`: feedback step (phase LSB, taken modulo a turn). `cpt_q8`: DAC codes
    /// per turn in Q8.
    #[inline(always)]
    /// `depth`: this step's modulation depth phi0 (+ dither), phase LSB.
    pub fn write_step(
        &mut self,
        step: Phase,
        depth: Phase,
        cpt_q8: u32,
        dac: &mut [u16],
    ) -> Resets {
        let d_plus = depth.wrapping_sub(step) as i32;
        let d_minus = 0u32.wrapping_sub(depth).wrapping_sub(step) as i32;
        let mut plus_wraps = 0u64;
        let mut minus_wraps = 0u64;
        let mut theta = self.theta;
        let cpt = cpt_q8 as u64;
        for (j, pair) in dac.chunks_exact_mut(2).enumerate() {
            if let [plus, minus] = pair {
                let (t, ov) = theta.overflowing_add_signed(d_plus);
                plus_wraps |= (ov as u64) << (2 * j);
                // u32 * (<2^24) >> 40 stays below 2^16 while cpt_q8 < 2^24 (config clamps it).
                *plus = ((t as u64 * cpt) >> 40) as u16;
                let (t2, ov2) = t.overflowing_add_signed(d_minus);
                minus_wraps |= (ov2 as u64) << (2 * j + 1);
                *minus = ((t2 as u64 * cpt) >> 40) as u16;
                theta = t2;
            }
        }
        self.theta = theta;
        // An overflow while adding a positive increment is an upward reset.
        let (mut up, mut down) = (0, 0);
        if d_plus >= 0 {
            up |= plus_wraps
        } else {
            down |= plus_wraps
        }
        if d_minus >= 0 {
            up |= minus_wraps
        } else {
            down |= minus_wraps
        }
        Resets { up, down }
    }
}
