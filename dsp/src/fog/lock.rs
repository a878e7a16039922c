//! Lock detector: the loop counts as out of lock after several consecutive
//! closures with the residual beyond pi/2 (the error's slope changes sign
//! there), and back in lock at the first closure inside.

use crate::{phase_from_rad, Phase};

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct LockConfig {
    /// Residual beyond which a closure counts toward loss of lock, phase LSB.
    pub limit: Phase,
    /// Consecutive closures beyond `limit` that declare loss of lock.
    pub closures: u16,
}

impl LockConfig {
    /// pi/2 for 8 closures (0.64 ms at 12.5 kHz): one noisy closure is not a loss.
    pub fn new() -> Self {
        Self {
            limit: phase_from_rad(0.5 * core::f64::consts::PI),
            closures: 8,
        }
    }
}

impl Default for LockConfig {
    fn default() -> Self {
        Self::new()
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
        let cfg = LockConfig::new();
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
}
