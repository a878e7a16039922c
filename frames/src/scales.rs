//! What one LSB of the frame's words is worth on a given board.

use gyro_sp::fog::{FogConfig, FogParams};

/// The board's units: the frame carries integers, these make them physical.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Scales {
    /// Closure period, s (the closure counter's LSB).
    pub closure_s: f64,
    /// FOG angle word LSB, rad (2*pi/2^32 rad * tau / K_s).
    pub fog_rad_per_lsb: f64,
    /// RLG counts per degree (quadrature edges, x4).
    pub rlg_counts_per_deg: f64,
}

impl Scales {
    /// From the FOG configuration the board runs and its RLG readout.
    pub fn new(fog: &FogConfig, rlg_counts_per_deg: f64) -> Self {
        Self {
            closure_s: fog.closure_period_s(),
            fog_rad_per_lsb: fog.rad_per_angle_lsb(),
            rlg_counts_per_deg,
        }
    }

    /// The boards of this project: the reference FOG (docs/fog.md; both
    /// boards run its layout) and 8 000 counts per degree.
    pub fn board() -> Self {
        match FogConfig::new(FogParams::default()) {
            Ok(c) => Self::new(&c, 8_000.0),
            // The defaults are a valid configuration (tested); never taken.
            Err(_) => Self {
                closure_s: 80e-6,
                fog_rad_per_lsb: 0.0,
                rlg_counts_per_deg: 8_000.0,
            },
        }
    }
}
