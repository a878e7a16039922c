//! Ring laser gyro channel (docs/rlg.md): quadrature pulse counting, the
//! mechanical dither stripped from the count, and thermal bias compensation
//! from two monoblock sensors and the case sensor.
//!
//! Data flow: each dither pickoff zero crossing (the latch interrupt) ->
//! [`dither`] (the latched count placed within its fringe); per RLG update
//! (one periodic interrupt): encoder-timer count -> [`counter`] (unwrapped
//! angle) -> the stripped angle at the previous update -> [`thermal`] (B_TC
//! from the three temperatures, with coefficients from [`coeffs`]) ->
//! compensated rate.

pub mod channel;
pub mod coeffs;
pub mod counter;
pub mod dither;
pub mod thermal;

pub use channel::{compensate_rate_ndps, FrameSpan, RlgChannel, RlgConfig, RlgWords};
pub use coeffs::{CoeffError, ThermalCoeffs};
pub use counter::PulseCounter;
pub use dither::{DitherStripper, LatchSample, StripConfig, StripFlags};
pub use thermal::{RlgFlags, Temperatures, ThermalComp};
