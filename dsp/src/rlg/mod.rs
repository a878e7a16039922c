//! Ring laser gyro channel (docs/rlg.md): quadrature pulse counting
//! and thermal bias compensation from two monoblock sensors and the case sensor.
//!
//! Data flow per RLG update (one periodic interrupt): encoder-timer count ->
//! [`counter`] (angle increment, rate) -> [`thermal`] (B_TC from the three
//! temperatures, with coefficients from [`coeffs`]) -> compensated rate.

pub mod channel;
pub mod coeffs;
pub mod counter;
pub mod thermal;

pub use channel::{compensate_rate_ndps, RlgChannel, RlgConfig, RlgWords};
pub use coeffs::{CoeffError, ThermalCoeffs};
pub use counter::PulseCounter;
pub use thermal::{RlgFlags, Temperatures, ThermalComp};
