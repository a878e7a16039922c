//! The byte stream a board sends, without QEMU: frames of the board's
//! format (gyro-sp's FrameBuilder and the cumulative angle words) for a
//! FOG at a constant rate with white rate noise and an RLG counting the
//! same rate, 25 closures a frame at 12.5 kHz (500 frames/s). For the
//! recorder's tests and its speed bench.

use gyro_sp::fog::{ClosureOutput, FogConfig, FogParams};
use gyro_sp::frame::{AngleTotals, FrameBuilder, ResetCause};
use gyro_sp::rlg::RlgWords;
use rand_core::SeedableRng;
use rand_distr::{Distribution, Normal};
use rand_xoshiro::Xoshiro256PlusPlus;

/// What the stream holds.
#[derive(Clone, Copy, Debug)]
pub struct BoardStream {
    /// Frames to send.
    pub frames: usize,
    /// The true rate, deg/s.
    pub rate_dps: f64,
    /// White rate noise per closure, deg/s (1 sigma).
    pub noise_dps: f64,
    pub seed: u64,
}

/// The stream's bytes and its truth: the FOG angle (deg) and the RLG
/// counts summed over every frame.
pub struct Stream {
    pub bytes: Vec<u8>,
    pub fog_angle_deg: f64,
    pub rlg_counts: i64,
}

/// RLG counts per degree of the stream.
pub const RLG_COUNTS_PER_DEG: f64 = 8_000.0;

impl BoardStream {
    pub fn generate(&self) -> Stream {
        let cfg = match FogConfig::new(FogParams::default()) {
            Ok(c) => c,
            Err(_) => unreachable!("the default FOG configuration is valid"),
        };
        let lsb_rad_s = cfg.rad_s_per_phase_lsb();
        let deg = std::f64::consts::PI / 180.0;
        let closure_s = cfg.closure_period_s();
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(self.seed);
        let normal = Normal::new(0.0, self.noise_dps.max(0.0)).ok();
        let mut builder = FrameBuilder::new(25, cfg.n_half);
        builder.set_reset_cause(ResetCause::PowerOn);
        let mut totals = AngleTotals::default();
        let mut bytes = Vec::with_capacity(self.frames * gyro_sp::frame::FRAME_LEN);
        let (mut fog_lsb, mut rlg_counts) = (0i128, 0i64);
        let mut rlg_angle = 0.0f64;
        let mut counter = 0u32;
        while bytes.len() < self.frames * gyro_sp::frame::FRAME_LEN {
            let rate = self.rate_dps + normal.map_or(0.0, |n| n.sample(&mut rng));
            let phase = (rate * deg / lsb_rad_s).round() as i64;
            let out = ClosureOutput {
                sagnac_phase: phase,
                sagnac_phase_corrected: phase,
                dc: 24_000,
                codes_per_turn_q8: 49_152 << 8,
                ..ClosureOutput::default()
            };
            rlg_angle += self.rate_dps * closure_s;
            counter = counter.wrapping_add(1);
            if builder.completes_next() {
                let total = (rlg_angle * RLG_COUNTS_PER_DEG).floor() as i64;
                let d = total - rlg_counts;
                rlg_counts = total;
                builder.set_rlg(RlgWords {
                    delta_counts: d as i32,
                    rate_comp_udps: (self.rate_dps * 1e6) as i32,
                    t_mono_a_q8: 20 * 256,
                    t_mono_b_q8: 20 * 256,
                    t_case_q8: 20 * 256,
                    ..RlgWords::default()
                });
            }
            if let Some(mut f) = builder.push(&out, counter) {
                f.fog_angle_comp = f.fog_angle;
                fog_lsb += f.fog_angle as i128;
                let (wire, after) = totals.stamp(&f);
                totals = after;
                bytes.extend_from_slice(&wire.encode());
            }
        }
        Stream {
            bytes,
            fog_angle_deg: fog_lsb as f64 * cfg.rad_per_angle_lsb() / deg,
            rlg_counts,
        }
    }
}
