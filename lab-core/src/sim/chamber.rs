//! An RLG in a thermal chamber (profiles over -40..+50 degC) at a fixed
//! orientation. The gyro model is `gyro_sim::Chamber` (also inside the qemu
//! firmware); this adds the chamber profile and the Earth-rate component of
//! the orientation.

use gyro_sim::{Chamber, ChamberParams};

/// Earth rate, deg/h.
pub const EARTH_RATE_DPH: f64 = 15.041_067;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ChamberProfile {
    /// 20 -> -40 -> +50 -> 20 degC at 1 degC/min, 90 min soaks at the ends.
    Cycle,
    /// Steps 20, 50, 35, 5, -25, -40, -10, 20 degC at 2 degC/min, 45 min soaks.
    Steps,
    /// Constant at --soak-c.
    Soak,
}

/// Chamber air temperature, degC, at time t.
pub fn air_temperature(profile: ChamberProfile, soak_c: f64, t: f64) -> f64 {
    let (points, rate_c_per_s, hold_s): (&[f64], f64, f64) = match profile {
        ChamberProfile::Cycle => (&[20.0, -40.0, 50.0, 20.0], 1.0 / 60.0, 5400.0),
        ChamberProfile::Steps => (
            &[20.0, 50.0, 35.0, 5.0, -25.0, -40.0, -10.0, 20.0],
            2.0 / 60.0,
            2700.0,
        ),
        ChamberProfile::Soak => return soak_c,
    };
    // Hold 10 min at the start, then ramp/hold legs.
    let mut t0 = 600.0;
    if t < t0 {
        return points[0];
    }
    for w in points.windows(2) {
        let ramp = (w[1] - w[0]).abs() / rate_c_per_s;
        if t < t0 + ramp {
            return w[0] + (w[1] - w[0]) * (t - t0) / ramp;
        }
        t0 += ramp;
        if t < t0 + hold_s {
            return w[1];
        }
        t0 += hold_s;
    }
    points[points.len() - 1]
}

/// Length of a profile, s.
pub fn profile_duration(profile: ChamberProfile) -> f64 {
    match profile {
        ChamberProfile::Cycle => 600.0 + 3600.0 + 5400.0 + 5400.0 + 5400.0 + 1800.0 + 5400.0,
        ChamberProfile::Steps => {
            let pts = [20.0, 50.0, 35.0, 5.0, -25.0, -40.0, -10.0, 20.0f64];
            600.0
                + pts
                    .windows(2)
                    .map(|w| (w[1] - w[0]).abs() * 30.0 + 2700.0)
                    .sum::<f64>()
        }
        ChamberProfile::Soak => 4.0 * 3600.0,
    }
}

/// Earth-rate component about a sensitive axis at azimuth `az` (from north,
/// towards east) and elevation `el` (up), latitude `lat`, all degrees: deg/s.
pub fn earth_component_dps(az: f64, el: f64, lat: f64) -> f64 {
    let r = f64::to_radians;
    EARTH_RATE_DPH / 3600.0
        * (r(el).cos() * r(az).cos() * r(lat).cos() + r(el).sin() * r(lat).sin())
}

/// A chamber run: the profile, the sensitive axis and the rows.
#[derive(Clone, Copy, Debug)]
pub struct ChamberRunParams {
    pub profile: ChamberProfile,
    /// Chamber temperature of the `Soak` profile, degC.
    pub soak_c: f64,
    pub duration_s: f64,
    /// Row period, s.
    pub dt_s: f64,
    /// Sensitive axis azimuth from north and elevation, latitude, deg.
    pub azimuth_deg: f64,
    pub elevation_deg: f64,
    pub latitude_deg: f64,
    pub seed: u64,
}

/// One row of a chamber run.
#[derive(Clone, Copy, Debug)]
pub struct ChamberRow {
    pub t_s: f64,
    pub ref_rate_dps: f64,
    /// The counter's whole counts over the row, deg/s.
    pub rate_dps: f64,
    pub t_mono_a_c: f64,
    pub t_mono_b_c: f64,
    pub t_case_c: f64,
    pub air_c: f64,
    pub bias_true_dph: f64,
}

/// The rows of a chamber run, one at a time (a month at 10 ms is too long
/// to hold).
pub struct ChamberRun {
    run: ChamberRunParams,
    params: ChamberParams,
    chamber: Chamber,
    reference_dps: f64,
    rows: u64,
    k: u64,
    last_counts: i64,
}

impl ChamberRun {
    pub fn new(run: ChamberRunParams) -> Self {
        let params = ChamberParams {
            seed: run.seed,
            ..Default::default()
        };
        let reference_dps =
            earth_component_dps(run.azimuth_deg, run.elevation_deg, run.latitude_deg);
        let air0 = air_temperature(run.profile, run.soak_c, 0.0);
        Self {
            run,
            params,
            chamber: Chamber::new(params, air0),
            reference_dps,
            rows: (run.duration_s / run.dt_s).round() as u64,
            k: 0,
            last_counts: 0,
        }
    }

    /// The Earth-rate component about the sensitive axis, deg/s.
    pub fn reference_dps(&self) -> f64 {
        self.reference_dps
    }

    pub fn rows(&self) -> u64 {
        self.rows
    }
}

impl Iterator for ChamberRun {
    type Item = ChamberRow;

    fn next(&mut self) -> Option<ChamberRow> {
        if self.k >= self.rows {
            return None;
        }
        let dt = self.run.dt_s;
        let t = (self.k as f64 + 1.0) * dt;
        let air = air_temperature(self.run.profile, self.run.soak_c, t - 0.5 * dt);
        let s = self.chamber.step(dt, air, self.reference_dps);
        let rate = (s.counts - self.last_counts) as f64 / self.params.counts_per_deg / dt;
        self.last_counts = s.counts;
        self.k += 1;
        Some(ChamberRow {
            t_s: s.t_s,
            ref_rate_dps: self.reference_dps,
            rate_dps: rate,
            t_mono_a_c: s.t_mono_a_c,
            t_mono_b_c: s.t_mono_b_c,
            t_case_c: s.t_case_c,
            air_c: air,
            bias_true_dph: s.bias_true_dph,
        })
    }
}
