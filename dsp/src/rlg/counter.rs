//! Quadrature pulse counting: the encoder-mode timer counts up/down on both
//! edges of both photodiode channels (4 counts per fringe) in hardware; the
//! periodic interrupt reads the wrapping 16-bit counter and differences it.
//!
//! Formats: counts are integers (one count = 1/K deg, K pulses per degree
//! including the x4 of quadrature decoding); the running angle is an i64 of
//! counts, so no count is ever lost (2^63 counts is far beyond any mission).

/// Difference of a wrapping 16-bit counter: correct while fewer than 2^15
/// counts pass between two reads (at K = 2000 pulses/deg and a 2 kHz update
/// that is 32 768 deg/s).
#[inline(always)]
pub fn count_delta(now: u16, last: u16) -> i16 {
    now.wrapping_sub(last) as i16
}

#[derive(Clone, Copy, Debug, Default)]
pub struct PulseCounter {
    last: u16,
    started: bool,
    /// Counts since start.
    angle: i64,
}

impl PulseCounter {
    /// Takes the timer's counter register; returns the counts since the last
    /// read (the angle increment). The first read only sets the reference.
    #[inline(always)]
    pub fn update(&mut self, raw: u16) -> i32 {
        let d = if self.started {
            count_delta(raw, self.last) as i32
        } else {
            self.started = true;
            0
        };
        self.last = raw;
        self.angle += d as i64;
        d
    }

    /// Counts accumulated since start.
    pub fn angle_counts(&self) -> i64 {
        self.angle
    }

    /// The counts since start that a register value taken within 2^15
    /// counts of the last read stands for (a latched count); None before
    /// the first read.
    #[inline(always)]
    pub fn unwrap(&self, raw: u16) -> Option<i64> {
        self.started
            .then(|| self.angle.wrapping_add(count_delta(raw, self.last) as i64))
    }
}
