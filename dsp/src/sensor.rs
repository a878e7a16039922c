//! A temperature sensor as the compensations see it: every read checked,
//! the last good value held while the sensor is bad.
//!
//! A read that failed (NACK, timeout: `None`), reads outside -55..+150 degC
//! (the TMP117's range; anything else is nonsense) or repeats the exact same
//! value for [`STUCK_READS`] reads marks the sensor bad; the value in use is
//! then the last good one, and the flag stays up while it lasts. Values are
//! Q8 degC (1/256 degC; the TMP117's LSB is 1/128 degC).

/// Identical consecutive reads that mark a sensor stuck (TMP117 noise moves
/// the last bit within a few reads; 64 reads at 8 Hz is 8 s).
pub const STUCK_READS: u16 = 64;
/// Plausible range, Q8 degC.
pub const T_MIN_Q8: i32 = -55 * 256;
pub const T_MAX_Q8: i32 = 150 * 256;

#[derive(Clone, Copy, Debug, Default)]
pub struct SensorHold {
    last_good_q8: i32,
    last_raw: Option<i32>,
    repeats: u16,
    seen: bool,
}

impl SensorHold {
    /// Takes one read; returns the value to use (Q8 degC) and whether the
    /// sensor is bad (also before its first good read, when the value is 0).
    #[inline(always)]
    pub fn take(&mut self, read: Option<i32>) -> (i32, bool) {
        let bad = match read {
            Some(t) if (T_MIN_Q8..=T_MAX_Q8).contains(&t) => {
                if self.last_raw == Some(t) {
                    self.repeats = self.repeats.saturating_add(1);
                } else {
                    self.repeats = 0;
                }
                self.last_raw = Some(t);
                if self.repeats < STUCK_READS {
                    self.last_good_q8 = t;
                    self.seen = true;
                    false
                } else {
                    true
                }
            }
            _ => true,
        };
        (self.last_good_q8, bad || !self.seen)
    }

    /// The value in use, Q8 degC.
    pub fn value_q8(&self) -> i32 {
        self.last_good_q8
    }
}
