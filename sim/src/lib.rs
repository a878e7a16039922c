//! The simulated gyro: the same model on the host (f64) and inside the `qemu`
//! firmware (f32). Generic over the float type through `num_traits::Float`
//! (libm underneath, accurate to the last bit or two; no micromath here because
//! the second-order fringe terms need full precision).

#![no_std]

pub mod fog_optics;
pub mod fog_rig;
pub mod fog_thermal;
pub mod noise;
pub mod profile;
pub mod rlg_dither;
pub mod rlg_dither_rig;
pub mod rlg_rig;
pub mod vibration_drift;

pub use fog_optics::{Chain, FogOptics, OpticsParams};
pub use fog_rig::FogRig;
pub use fog_thermal::{CoilThermal, ScaleFactorTruth};
pub use noise::{NoiseParams, RateNoise};
pub use profile::{Profile, Segment};
pub use rlg_dither::{DitherParams, DitheredRlg};
pub use rlg_dither_rig::DitheredChamber;
pub use rlg_rig::{Chamber, ChamberParams, ChamberSample};
pub use vibration_drift::{eps2_point, Drift, DriftMeter, Eps2Point};
