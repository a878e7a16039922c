//! `gyro-lab simulate chamber`: an RLG run in a thermal chamber (profiles over
//! -40..+50 degC) at a fixed orientation, written as a run file. The gyro
//! model is `gyro_sim::Chamber` (also inside the qemu firmware); this adds
//! the chamber profile and the Earth-rate component of the orientation.

use crate::data::csv_writer::CellFormat::Fixed;
use crate::data::run_file::{Column, RunWriter};
use crate::error::LabError;
use clap::{Args, ValueEnum};
use gyro_sim::{Chamber, ChamberParams};
use std::path::PathBuf;

/// Earth rate, deg/h.
pub const EARTH_RATE_DPH: f64 = 15.041_067;

#[derive(Clone, Copy, Debug, ValueEnum, PartialEq, Eq)]
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

#[derive(Args, Debug, Clone)]
pub struct ChamberArgs {
    #[arg(long, value_enum, default_value_t = ChamberProfile::Cycle)]
    pub profile: ChamberProfile,
    /// Chamber temperature of the `soak` profile, degC.
    #[arg(long, default_value_t = 20.0, allow_negative_numbers = true)]
    pub soak_c: f64,
    /// Duration, s (default: the profile's length).
    #[arg(long)]
    pub duration_s: Option<f64>,
    /// Sample period of the run file, s.
    #[arg(long, default_value_t = 1.0)]
    pub dt_s: f64,
    /// Sensitive axis azimuth from north, deg.
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
    pub azimuth_deg: f64,
    /// Sensitive axis elevation, deg (90: axis up).
    #[arg(long, default_value_t = 90.0, allow_negative_numbers = true)]
    pub elevation_deg: f64,
    #[arg(long, default_value_t = 48.0, allow_negative_numbers = true)]
    pub latitude_deg: f64,
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    #[arg(long)]
    pub out: PathBuf,
    #[arg(long)]
    pub json: bool,
}

pub fn simulate(a: &ChamberArgs) -> Result<(), LabError> {
    let dur = a.duration_s.unwrap_or(profile_duration(a.profile));
    let bad = |n: &str, v: f64| LabError::Usage(format!("--{n} {v}: out of range"));
    if !(dur.is_finite() && dur > 0.0 && dur <= 30.0 * 86_400.0) {
        return Err(bad("duration-s", dur));
    }
    if !(a.dt_s.is_finite() && (0.01..=10.0).contains(&a.dt_s)) {
        return Err(bad("dt-s", a.dt_s));
    }
    if !(a.soak_c.is_finite() && (-55.0..=125.0).contains(&a.soak_c)) {
        return Err(bad("soak-c", a.soak_c));
    }
    for (n, v) in [
        ("azimuth-deg", a.azimuth_deg),
        ("elevation-deg", a.elevation_deg),
        ("latitude-deg", a.latitude_deg),
    ] {
        if !v.is_finite() {
            return Err(bad(n, v));
        }
    }
    let p = ChamberParams {
        seed: a.seed,
        ..Default::default()
    };
    let reference = earth_component_dps(a.azimuth_deg, a.elevation_deg, a.latitude_deg);
    let air0 = air_temperature(a.profile, a.soak_c, 0.0);
    let mut ch = Chamber::new(p, air0);
    let mut w = RunWriter::create(
        &a.out,
        &format!(
            "gyro-lab simulate chamber: profile {:?}, axis azimuth {} deg elevation {} deg, latitude {} deg",
            a.profile, a.azimuth_deg, a.elevation_deg, a.latitude_deg
        ),
        &[
            (Column::Time, Fixed(3)),
            (Column::RefRate, Fixed(9)),
            (Column::Rate, Fixed(9)),
            (Column::MonoA, Fixed(4)),
            (Column::MonoB, Fixed(4)),
            (Column::Case, Fixed(4)),
            (Column::AirTemp, Fixed(3)),
            (Column::TrueBias, Fixed(6)),
        ],
    )?;
    let n = (dur / a.dt_s).round() as u64;
    let mut last = 0i64;
    for k in 0..n {
        let t = (k as f64 + 1.0) * a.dt_s;
        let air = air_temperature(a.profile, a.soak_c, t - 0.5 * a.dt_s);
        let s = ch.step(a.dt_s, air, reference);
        let rate = (s.counts - last) as f64 / p.counts_per_deg / a.dt_s;
        last = s.counts;
        w.row(&[
            s.t_s,
            reference,
            rate,
            s.t_mono_a_c,
            s.t_mono_b_c,
            s.t_case_c,
            air,
            s.bias_true_dph,
        ])?;
    }
    w.finish()?;
    if a.json {
        println!(
            "{}",
            serde_json::json!({"rows": n, "duration_s": dur, "ref_rate_dps": reference, "out": a.out})
        );
    } else {
        println!(
            "{n} rows, {:.1} h, reference {:.6} deg/s -> {}",
            dur / 3600.0,
            reference,
            a.out.display()
        );
    }
    Ok(())
}
