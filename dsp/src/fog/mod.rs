//! Closed-loop fiber-optic gyro: square-wave +-phi0 bias modulation, synchronous
//! demodulation, digital serrodyne feedback, the 2*pi gain loop and the online
//! epsilon-squared (vibration rectification) correction. See docs/fog.md.
//!
//! Data flow per closure (one interrupt, `n_half` half periods of tau):
//! ADC batch -> [`demod`] -> main loop ([`closure`]) and [`gain_loop`] ->
//! [`modulator`] writes the DAC words of the next closure; [`vibration`] corrects
//! the output; [`faults`] flags what went wrong. At the frame rate,
//! [`scale_factor`] applies the scale factor and bias over coil temperature.
//!
//! Every block has one shape: a `Config` built by its `new` from its own
//! physical parameters, a state, and one `update` call per closure;
//! [`config`] derives the blocks' parameters from [`FogParams`] and
//! composes their configs.

pub mod agc;
pub mod closure;
pub mod config;
pub mod demod;
pub mod dither;
pub mod faults;
pub mod gain_loop;
pub mod layout;
pub mod lock;
mod modulator;
pub mod residual;
pub mod scale_factor;
pub mod vibration;

pub use closure::{ClosureOutput, FogLoop};
pub use config::{FogConfig, FogParams};
pub use faults::Faults;
pub use layout::{Kernel, MAX_HALF, MAX_SAMPLES_PER_HALF};
