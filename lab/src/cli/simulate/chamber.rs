//! `gyro-lab simulate chamber`: an RLG run in a thermal chamber
//! (sim/chamber.rs), written as a run file.

use crate::cli::args::{Json, Out, Seed};
use clap::{Args, ValueEnum};
use gyro_lab_core::data::csv_writer::CellFormat::Fixed;
use gyro_lab_core::data::run_file::{Column, RunWriter};
use gyro_lab_core::error::LabError;
use gyro_lab_core::sim::chamber::{profile_duration, ChamberProfile, ChamberRun, ChamberRunParams};

/// The chamber profiles, as the command line names them.
#[derive(Clone, Copy, Debug, ValueEnum, PartialEq, Eq)]
pub enum ChamberProfileArg {
    /// 20 -> -40 -> +50 -> 20 degC at 1 degC/min, 90 min soaks at the ends.
    Cycle,
    /// Steps 20, 50, 35, 5, -25, -40, -10, 20 degC at 2 degC/min, 45 min soaks.
    Steps,
    /// Constant at --soak-c.
    Soak,
}

impl From<ChamberProfileArg> for ChamberProfile {
    fn from(p: ChamberProfileArg) -> Self {
        match p {
            ChamberProfileArg::Cycle => ChamberProfile::Cycle,
            ChamberProfileArg::Steps => ChamberProfile::Steps,
            ChamberProfileArg::Soak => ChamberProfile::Soak,
        }
    }
}

#[derive(Args, Debug, Clone)]
#[command(mut_arg("out", |a| a.help("A file: the run file to write (CSV)")))]
pub struct ChamberArgs {
    /// Chamber temperature profile.
    #[arg(long, value_enum, default_value_t = ChamberProfileArg::Cycle)]
    pub profile: ChamberProfileArg,
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
    /// Latitude, deg (the Earth rate's vertical component).
    #[arg(long, default_value_t = 48.0, allow_negative_numbers = true)]
    pub latitude_deg: f64,
    #[command(flatten)]
    pub seed: Seed,
    #[command(flatten)]
    pub out: Out,
    #[command(flatten)]
    pub json: Json,
}

/// The options in range, `dur` the run's duration.
fn check(a: &ChamberArgs, dur: f64) -> Result<(), LabError> {
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
    Ok(())
}

pub fn run(a: &ChamberArgs) -> Result<(), LabError> {
    let profile = ChamberProfile::from(a.profile);
    let dur = a.duration_s.unwrap_or(profile_duration(profile));
    check(a, dur)?;
    let chamber = ChamberRun::new(ChamberRunParams {
        profile,
        soak_c: a.soak_c,
        duration_s: dur,
        dt_s: a.dt_s,
        azimuth_deg: a.azimuth_deg,
        elevation_deg: a.elevation_deg,
        latitude_deg: a.latitude_deg,
        seed: a.seed.seed,
    });
    let (reference, n) = (chamber.reference_dps(), chamber.rows());
    let out = &a.out.out;
    let mut w = RunWriter::create(
        out,
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
    for r in chamber {
        w.row(&[
            r.t_s,
            r.ref_rate_dps,
            r.rate_dps,
            r.t_mono_a_c,
            r.t_mono_b_c,
            r.t_case_c,
            r.air_c,
            r.bias_true_dph,
        ])?;
    }
    w.finish()?;
    if a.json.json {
        println!(
            "{}",
            serde_json::json!({
                "rows": n, "duration_s": dur, Column::RefRate.name(): reference, "out": out
            })
        );
    } else {
        println!(
            "{n} rows, {:.1} h, reference {:.6} deg/s -> {}",
            dur / 3600.0,
            reference,
            out.display()
        );
    }
    Ok(())
}
