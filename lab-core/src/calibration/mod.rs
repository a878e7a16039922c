//! Calibration: the estimates a test rig's records give the firmware. RLG
//! thermal bias (thermal/), FOG scale factor over temperature
//! (scale_factor/), RLG lock-in rate (lockin.rs). Each takes typed records
//! and returns typed results; the commands read and write the files.

pub mod lockin;
pub mod scale_factor;
pub mod thermal;
pub mod warning;
