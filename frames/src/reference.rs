//! The reference rate a recorded row is compared with: a constant (the
//! Earth-rate component on a static bench, a table at a set rate) or a
//! rate-table log sampled in its own time, merged by time.

/// A rate-table log: samples of the table's rate (deg/s) at its own times,
/// with the board's time of the table's zero (`board_s = table_s + offset_s`).
#[derive(Clone, Debug, PartialEq)]
pub struct RateLog {
    t_s: Vec<f64>,
    rate_dps: Vec<f64>,
    offset_s: f64,
}

/// Why a rate log cannot be used.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum RateLogError {
    /// Fewer than two samples.
    TooShort,
    /// Sample `index` (from 0) is not after the one before, or not finite.
    NotIncreasing { index: usize },
}

impl RateLog {
    /// From samples in increasing time.
    pub fn new(t_s: Vec<f64>, rate_dps: Vec<f64>, offset_s: f64) -> Result<Self, RateLogError> {
        if t_s.len() < 2 || t_s.len() != rate_dps.len() {
            return Err(RateLogError::TooShort);
        }
        if !(t_s[0].is_finite() && rate_dps[0].is_finite()) {
            return Err(RateLogError::NotIncreasing { index: 0 });
        }
        for i in 1..t_s.len() {
            if t_s[i].is_nan() || t_s[i] <= t_s[i - 1] || !rate_dps[i].is_finite() {
                return Err(RateLogError::NotIncreasing { index: i });
            }
        }
        Ok(Self {
            t_s,
            rate_dps,
            offset_s,
        })
    }

    /// The log's integral (deg) from its start to table time `t`, the
    /// samples joined by straight lines and held flat outside the log.
    fn angle_to(&self, t: f64) -> f64 {
        let (t0, tn) = (self.t_s[0], self.t_s[self.t_s.len() - 1]);
        if t <= t0 {
            return (t - t0) * self.rate_dps[0];
        }
        let i = self
            .t_s
            .partition_point(|&x| x <= t)
            .min(self.t_s.len() - 1);
        // Whole segments before sample i-1, then the part of segment i-1.
        let mut a = 0.0;
        for k in 1..i {
            a += 0.5 * (self.rate_dps[k] + self.rate_dps[k - 1]) * (self.t_s[k] - self.t_s[k - 1]);
        }
        if t >= tn {
            return a
                + 0.5
                    * (self.rate_dps[i] + self.rate_dps[i - 1])
                    * (self.t_s[i] - self.t_s[i - 1])
                + (t - tn) * self.rate_dps[i];
        }
        let (ta, tb) = (self.t_s[i - 1], self.t_s[i]);
        let (ra, rb) = (self.rate_dps[i - 1], self.rate_dps[i]);
        let rt = ra + (rb - ra) * (t - ta) / (tb - ta);
        a + 0.5 * (ra + rt) * (t - ta)
    }
}

/// The reference of a record.
#[derive(Clone, Debug, PartialEq)]
pub enum Reference {
    Constant(f64),
    Log(RateLog),
}

impl Reference {
    /// The mean reference rate (deg/s) over board time (from_s, to_s].
    pub fn mean(&self, from_s: f64, to_s: f64) -> f64 {
        match self {
            Reference::Constant(r) => *r,
            Reference::Log(log) => {
                let (a, b) = (from_s - log.offset_s, to_s - log.offset_s);
                if b > a {
                    (log.angle_to(b) - log.angle_to(a)) / (b - a)
                } else {
                    // An empty span: the rate at that time.
                    let i = log
                        .t_s
                        .partition_point(|&x| x <= b)
                        .clamp(1, log.t_s.len() - 1);
                    let (ta, tb) = (log.t_s[i - 1], log.t_s[i]);
                    let w = ((b - ta) / (tb - ta)).clamp(0.0, 1.0);
                    log.rate_dps[i - 1] + w * (log.rate_dps[i] - log.rate_dps[i - 1])
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Means over spans of a trapezoid rate profile against its integral.
    #[test]
    fn means_follow_the_log() {
        // 0 deg/s until 1 s, ramp to 10 deg/s at 2 s, hold to 4 s.
        let log =
            RateLog::new(vec![0.0, 1.0, 2.0, 4.0], vec![0.0, 0.0, 10.0, 10.0], 100.0).unwrap();
        let r = Reference::Log(log);
        // Board time 100 s is table time 0.
        assert!((r.mean(100.0, 101.0) - 0.0).abs() < 1e-12);
        assert!((r.mean(101.0, 102.0) - 5.0).abs() < 1e-12);
        assert!((r.mean(102.0, 104.0) - 10.0).abs() < 1e-12);
        // 1.5..2 s ramps 5 -> 10 (3.75 deg), 2..2.5 s holds 10 (5 deg).
        assert!((r.mean(101.5, 102.5) - 8.75).abs() < 1e-12);
        // Held flat past the end.
        assert!((r.mean(110.0, 111.0) - 10.0).abs() < 1e-12);
        assert_eq!(Reference::Constant(0.004).mean(1.0, 2.0), 0.004);
    }

    #[test]
    fn bad_logs_are_refused() {
        assert_eq!(
            RateLog::new(vec![0.0], vec![1.0], 0.0),
            Err(RateLogError::TooShort)
        );
        assert_eq!(
            RateLog::new(vec![0.0, 1.0, 1.0], vec![1.0, 1.0, 1.0], 0.0),
            Err(RateLogError::NotIncreasing { index: 2 })
        );
    }
}
