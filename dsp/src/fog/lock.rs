//! Lock detector: the loop counts as out of lock after the residual has
//! stayed beyond pi/2 (the error's slope changes sign there) for a set
//! time, and back in lock at the first closure inside.

use crate::phase::{phase_from_rad, Phase};
#[allow(unused_imports)] // f64 maths comes from libm where core lacks it
use num_traits::float::Float;

/// How long the residual must stay out before the loss is declared, s:
/// 0.64 ms, so one noisy closure is not a loss (8 closures at 12.5 kHz).
pub const LOSS_WINDOW_S: f64 = 0.64e-3;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct LockConfig {
    /// Residual beyond which a closure counts toward loss of lock, phase LSB.
    pub limit: Phase,
    /// Consecutive closures beyond `limit` that declare loss of lock.
    pub closures: u16,
}

impl LockConfig {
    /// pi/2 for [`LOSS_WINDOW_S`] at `closure_hz` (at least one closure).
    pub fn new(closure_hz: f64) -> Self {
        let closures = (LOSS_WINDOW_S * closure_hz).round();
        Self {
            limit: phase_from_rad(0.5 * core::f64::consts::PI),
            closures: if closures.is_finite() {
                closures.clamp(1.0, u16::MAX as f64) as u16
            } else {
                1
            },
        }
    }
}

#[derive(Clone, Copy, Debug, Default)]
pub struct LockDetector {
    unlocked: u16,
}

impl LockDetector {
    /// Takes a closure's residual; `Some(true)` when lock is lost,
    /// `Some(false)` when it is back, `None` when the state holds.
    #[inline(always)]
    pub fn update(&mut self, cfg: &LockConfig, residual: i32) -> Option<bool> {
        if residual.unsigned_abs() > cfg.limit {
            self.unlocked = self.unlocked.saturating_add(1);
            (self.unlocked >= cfg.closures).then_some(true)
        } else {
            self.unlocked = 0;
            Some(false)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lost_after_the_count_and_back_at_once() {
        let cfg = LockConfig::new(12_500.0);
        let mut d = LockDetector::default();
        let far = (cfg.limit + 1) as i32;
        for _ in 1..cfg.closures {
            assert_eq!(d.update(&cfg, -far), None);
        }
        assert_eq!(d.update(&cfg, far), Some(true));
        assert_eq!(d.update(&cfg, far), Some(true));
        assert_eq!(d.update(&cfg, cfg.limit as i32), Some(false));
        assert_eq!(d.update(&cfg, far), None);
    }

    /// The window is a time: 8 closures at 12.5 kHz, 4 at 6.25 kHz.
    #[test]
    fn window_follows_the_closure_rate() {
        assert_eq!(LockConfig::new(12_500.0).closures, 8);
        assert_eq!(LockConfig::new(6_250.0).closures, 4);
        assert_eq!(LockConfig::new(100.0).closures, 1);
        assert_eq!(LockConfig::new(f64::NAN).closures, 1);
    }
}
