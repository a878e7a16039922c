//! Closed-loop fiber-optic gyro: square-wave +-phi0 bias modulation, synchronous
//! demodulation, digital serrodyne feedback, the 2*pi gain loop and the online
//! epsilon-squared (vibration rectification) correction. See docs/fog.md.
//!
//! Data flow per closure (one interrupt, `n_half` half periods of tau):
//! ADC batch -> [`demod`] -> main loop ([`closure`]) and [`gain_loop`] ->
//! [`modulator`] writes the DAC words of the next closure; [`vibration`] corrects
//! the output; [`faults`] flags what went wrong. At the frame rate,
//! [`scale_factor`] applies the scale factor and bias over coil temperature.

pub mod agc;
pub mod closure;
pub mod config;
pub mod demod;
pub mod dither;
pub mod faults;
pub mod gain_loop;
pub mod lock;
mod modulator;
pub mod scale_factor;
pub mod vibration;

pub use closure::{ClosureOutput, FogLoop};
pub use config::{FogConfig, FogParams};
pub use faults::Faults;

/// Most half periods per closure (6.25 kHz closure at tau = 5 us is 32).
pub const MAX_HALF: usize = 64;
/// Most ADC samples per half period.
pub const MAX_SAMPLES_PER_HALF: usize = 16;

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
                prop_assert_eq!(shr_saturate::<23, 21>(v), shr_clamp(v, 23, 21));
                prop_assert_eq!(shr_saturate::<8, 29>(v), shr_clamp(v, 8, 29));
            }
        }
    }
}
