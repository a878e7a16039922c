//! Input-rate profiles: constant, steps, ramps and sinusoidal oscillation with a
//! given peak angular acceleration.

use num_traits::Float;

/// One piece of a profile; rates in rad/s, durations in s.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Segment<F> {
    /// Constant rate.
    Constant { rate: F, duration: F },
    /// Linear ramp from `from` to `to`.
    Ramp { from: F, to: F, duration: F },
    /// `offset + (eps_peak/w)*sin(w*t)`, w = 2*pi*freq: peak angular acceleration eps_peak.
    Oscillation {
        offset: F,
        eps_peak: F,
        freq_hz: F,
        duration: F,
    },
}

impl<F: Float> Segment<F> {
    pub fn duration(&self) -> F {
        match *self {
            Segment::Constant { duration, .. }
            | Segment::Ramp { duration, .. }
            | Segment::Oscillation { duration, .. } => duration,
        }
    }

    /// Rate at local time `t` in [0, duration].
    pub fn rate_at(&self, t: F) -> F {
        match *self {
            Segment::Constant { rate, .. } => rate,
            Segment::Ramp { from, to, duration } => from + (to - from) * (t / duration),
            Segment::Oscillation {
                offset,
                eps_peak,
                freq_hz,
                ..
            } => {
                let w = F::from(core::f64::consts::TAU).unwrap_or(F::zero()) * freq_hz;
                offset + eps_peak / w * (w * t).sin()
            }
        }
    }

    /// Angular acceleration (rad/s^2) at local time `t`.
    pub fn accel_at(&self, t: F) -> F {
        match *self {
            Segment::Constant { .. } => F::zero(),
            Segment::Ramp { from, to, duration } => (to - from) / duration,
            Segment::Oscillation {
                eps_peak, freq_hz, ..
            } => {
                let w = F::from(core::f64::consts::TAU).unwrap_or(F::zero()) * freq_hz;
                eps_peak * (w * t).cos()
            }
        }
    }
}

/// Up to eight segments played in order; the last one holds after its end.
#[derive(Clone, Debug)]
pub struct Profile<F> {
    pub segments: heapless::Vec<Segment<F>, 8>,
}

impl<F: Float> Profile<F> {
    pub fn new(segments: &[Segment<F>]) -> Self {
        let mut v = heapless::Vec::new();
        for s in segments.iter().take(8) {
            let _ = v.push(*s);
        }
        Self { segments: v }
    }

    pub fn constant(rate: F) -> Self {
        Self::new(&[Segment::Constant {
            rate,
            duration: F::infinity(),
        }])
    }

    pub fn total_duration(&self) -> F {
        self.segments
            .iter()
            .fold(F::zero(), |a, s| a + s.duration())
    }

    /// The segment playing at `t` and the local time in it.
    fn at(&self, t: F) -> Option<(&Segment<F>, F)> {
        let mut start = F::zero();
        let mut last = None;
        for s in &self.segments {
            let end = start + s.duration();
            if t < end {
                return Some((s, t - start));
            }
            last = Some((s, start));
            start = end;
        }
        last.map(|(s, start)| (s, (t - start).min(s.duration())))
    }

    /// Rate (rad/s) at time `t` (s) since the start.
    pub fn rate_at(&self, t: F) -> F {
        self.at(t).map_or(F::zero(), |(s, u)| s.rate_at(u))
    }

    /// Angular acceleration (rad/s^2) at time `t` (s) since the start.
    pub fn accel_at(&self, t: F) -> F {
        self.at(t).map_or(F::zero(), |(s, u)| s.accel_at(u))
    }
}

/// The built-in profile of the `qemu` firmware (and of its host-side decoder):
/// rest, a rate step, ramps to large rates (a step beyond +-pi of Sagnac phase,
/// about 133 deg/s here, cannot be told from one a fringe away), then a 60 Hz
/// oscillation at 50 000 deg/s^2 peak. Returns the profile and segment names.
pub fn qemu_demo<F: Float>() -> (Profile<F>, [&'static str; 8]) {
    let f = |x: f64| F::from(x).unwrap_or(F::zero());
    let deg = core::f64::consts::PI / 180.0;
    (
        Profile::new(&[
            Segment::Constant {
                rate: f(0.0),
                duration: f(0.2),
            },
            Segment::Constant {
                rate: f(100.0 * deg),
                duration: f(0.3),
            },
            Segment::Ramp {
                from: f(100.0 * deg),
                to: f(-200.0 * deg),
                duration: f(0.1),
            },
            Segment::Constant {
                rate: f(-200.0 * deg),
                duration: f(0.3),
            },
            Segment::Ramp {
                from: f(-200.0 * deg),
                to: f(50.0 * deg),
                duration: f(0.1),
            },
            Segment::Constant {
                rate: f(50.0 * deg),
                duration: f(0.2),
            },
            Segment::Oscillation {
                offset: f(0.0),
                eps_peak: f(50_000.0 * deg),
                freq_hz: f(60.0),
                duration: f(1.0),
            },
            Segment::Constant {
                rate: f(0.0),
                duration: f(0.2),
            },
        ]),
        [
            "rest",
            "step to +100 dps",
            "ramp to -200 dps",
            "hold -200 dps",
            "ramp to +50 dps",
            "hold +50 dps",
            "vibration 60 Hz 50000 dps2",
            "rest, power loss",
        ],
    )
}
