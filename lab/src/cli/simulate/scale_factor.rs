//! `gyro-lab simulate scale-factor`: a FOG scale-factor calibration run
//! over temperature (sim/scale_factor_rig.rs), written as a run file.

use crate::cli::args::{Json, Out, Seed};
use crate::cli::output::print_json;
use clap::{Args, ValueEnum};
use gyro_lab_core::data::csv_writer::CellFormat::Fixed;
use gyro_lab_core::data::run_file::{Column, RunWriter};
use gyro_lab_core::error::LabError;
use gyro_lab_core::sim::scale_factor_rig::{simulate, Direction, RigParams, SweepProfile, Test};
use gyro_sim::fog_thermal::MAX_KNEES;

/// Chamber profiles of the continuous-rotation test, as the command line
/// names them.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum SweepProfileArg {
    /// 20 -> -40 degC, 60 min soak, -> +60 degC, 60 min soak, -> -40 degC,
    /// 30 min soak; ramps at 1 degC/min.
    Cycle,
    /// Plateaus 20, 0, 45, 55, 30, -20, 10 degC, ramps at 2 degC/min,
    /// 40 min soaks (a validation profile unlike the cycle).
    Steps,
}

impl From<SweepProfileArg> for SweepProfile {
    fn from(p: SweepProfileArg) -> Self {
        match p {
            SweepProfileArg::Cycle => SweepProfile::Cycle,
            SweepProfileArg::Steps => SweepProfile::Steps,
        }
    }
}

/// Table directions of the continuous test, as the command line names them.
#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum DirectionArg {
    Positive,
    Negative,
    /// Reversed every `reverse_every_s` (separates bias and scale factor).
    Both,
}

impl From<DirectionArg> for Direction {
    fn from(d: DirectionArg) -> Self {
        match d {
            DirectionArg::Positive => Direction::Positive,
            DirectionArg::Negative => Direction::Negative,
            DirectionArg::Both => Direction::Both,
        }
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, ValueEnum)]
pub enum TestKind {
    /// Constant table rate while the chamber sweeps.
    Continuous,
    /// Temperature plateaus, each with a rate sequence in both directions.
    Multipoint,
}

#[derive(Args, Debug, Clone)]
#[command(mut_arg("out", |a| a.help("A file: the run file to write (CSV)")))]
pub struct SimulateArgs {
    /// The calibration test: continuous rotation through the chamber sweep, or the classic
    /// multi-point plateaus.
    #[arg(long, value_enum, default_value_t = TestKind::Continuous)]
    pub test: TestKind,
    /// Chamber profile of the continuous test.
    #[arg(long, value_enum, default_value_t = SweepProfileArg::Cycle)]
    pub profile: SweepProfileArg,
    /// Table rate of the continuous test, deg/s (50 or more).
    #[arg(long, default_value_t = 50.0)]
    pub rate_dps: f64,
    /// Table direction of the continuous test: positive, negative, or both (alternating).
    #[arg(long, value_enum, default_value_t = DirectionArg::Both)]
    pub direction: DirectionArg,
    /// With `--direction both`: reverse every this many seconds.
    #[arg(long, default_value_t = 300.0)]
    pub reverse_every_s: f64,
    /// Plateau temperatures of the multi-point test, degC.
    #[arg(long, value_delimiter = ',', default_values_t = [-40.0, -15.0, 10.0, 35.0, 60.0], allow_negative_numbers = true)]
    pub plateaus_c: Vec<f64>,
    /// Rate magnitudes of each plateau's sequence (each both ways), deg/s.
    #[arg(long, value_delimiter = ',', default_values_t = [10.0, 20.0, 50.0, 100.0, 200.0])]
    pub rates_dps: Vec<f64>,
    /// Soak at rest before each plateau's sequence, s.
    #[arg(long, default_value_t = 3600.0)]
    pub soak_s: f64,
    /// Dwell at each rate of a multi-point plateau, s.
    #[arg(long, default_value_t = 60.0)]
    pub dwell_s: f64,
    /// The same gyro without its knee.
    #[arg(long)]
    pub no_knee: bool,
    /// Knee temperatures of the truth, degC (replacing the default 48),
    /// with `--knee-slope-changes` (ppm/degC, one per knee).
    #[arg(
        long,
        value_delimiter = ',',
        allow_negative_numbers = true,
        conflicts_with = "no_knee"
    )]
    pub knees_c: Vec<f64>,
    /// Slope change at each of `--knees-c`, ppm/degC (one per knee).
    #[arg(long, value_delimiter = ',', allow_negative_numbers = true)]
    pub knee_slope_changes: Vec<f64>,
    /// Smooth curvature of the truth: `q (T - centre)^2 + c (T - centre)^3`
    /// added to the scale-factor error; this is q, ppm/degC^2.
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
    pub quadratic_ppm_per_c2: f64,
    /// Cubic term of the scale-factor error about `--curve-centre-c`, ppm/degC^3.
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
    pub cubic_ppm_per_c3: f64,
    /// Temperature the quadratic and cubic terms are centred on, degC.
    #[arg(long, default_value_t = 10.0, allow_negative_numbers = true)]
    pub curve_centre_c: f64,
    /// Angle random walk of the gyro noise, deg/sqrt(h).
    #[arg(long, default_value_t = 0.005)]
    pub arw_dpsh: f64,
    /// Bias instability of the gyro noise, deg/h.
    #[arg(long, default_value_t = 0.01)]
    pub bias_instability_dph: f64,
    /// Coil sensor lag behind the coil, s.
    #[arg(long, default_value_t = 30.0)]
    pub sensor_lag_s: f64,
    /// Coil sensor noise, degC rms (read at 1/128 degC).
    #[arg(long, default_value_t = 0.005)]
    pub sensor_noise_c: f64,
    /// Row period, s.
    #[arg(long, default_value_t = 1.0)]
    pub dt_s: f64,
    #[command(flatten)]
    pub seed: Seed,
    #[command(flatten)]
    pub out: Out,
    #[command(flatten)]
    pub json: Json,
}

impl SimulateArgs {
    pub fn test(&self) -> Test {
        match self.test {
            TestKind::Continuous => Test::Continuous {
                profile: self.profile.into(),
                rate_dps: self.rate_dps,
                direction: self.direction.into(),
                reverse_every_s: self.reverse_every_s,
            },
            TestKind::Multipoint => Test::MultiPoint {
                plateaus_c: self.plateaus_c.clone(),
                rates_dps: self.rates_dps.clone(),
                soak_s: self.soak_s,
                dwell_s: self.dwell_s,
            },
        }
    }

    pub fn rig(&self) -> RigParams {
        let d = RigParams::default();
        let mut truth = if self.no_knee {
            d.truth.without_knees()
        } else {
            d.truth
        };
        if !self.knees_c.is_empty() {
            truth.n_knees = self.knees_c.len().min(MAX_KNEES);
            for (k, &t) in self.knees_c.iter().take(MAX_KNEES).enumerate() {
                let ds = self.knee_slope_changes.get(k).copied().unwrap_or(6.0);
                truth.knees[k] = (t, ds);
            }
        }
        let truth = truth.curved(
            self.quadratic_ppm_per_c2,
            self.cubic_ppm_per_c3,
            self.curve_centre_c,
        );
        RigParams {
            truth,
            arw_dpsh: self.arw_dpsh,
            bias_instability_dph: self.bias_instability_dph,
            tau_sensor_s: self.sensor_lag_s,
            sensor_noise_c: self.sensor_noise_c,
            dt_s: self.dt_s,
            seed: self.seed.seed,
            ..d
        }
    }
}

pub fn run(a: &SimulateArgs) -> Result<(), LabError> {
    let bad = |n: &str, v: f64| LabError::Usage(format!("--{n} {v}: out of range"));
    let pos = |n: &str, v: f64, lo: f64, hi: f64| {
        if v.is_finite() && v >= lo && v <= hi {
            Ok(())
        } else {
            Err(bad(n, v))
        }
    };
    pos("rate-dps", a.rate_dps.abs(), 0.0, 1000.0)?;
    pos("dt-s", a.dt_s, 0.01, 60.0)?;
    pos("reverse-every-s", a.reverse_every_s, 1.0, 1e5)?;
    pos("soak-s", a.soak_s, 0.0, 1e5)?;
    pos("dwell-s", a.dwell_s, a.dt_s, 1e4)?;
    pos("arw-dpsh", a.arw_dpsh, 0.0, 10.0)?;
    pos("bias-instability-dph", a.bias_instability_dph, 0.0, 100.0)?;
    pos("sensor-lag-s", a.sensor_lag_s, 0.0, 1000.0)?;
    pos("sensor-noise-c", a.sensor_noise_c, 0.0, 10.0)?;
    for &t in &a.plateaus_c {
        pos("plateaus-c", t, -55.0, 125.0)?;
    }
    for &r in &a.rates_dps {
        pos("rates-dps", r, 0.0, 1000.0)?;
    }
    if a.knees_c.len() > MAX_KNEES {
        return Err(LabError::Usage(format!(
            "--knees-c: at most {MAX_KNEES} knees"
        )));
    }
    for &t in &a.knees_c {
        pos("knees-c", t, -55.0, 125.0)?;
    }
    for &ds in &a.knee_slope_changes {
        pos("knee-slope-changes", ds.abs(), 0.0, 1000.0)?;
    }
    pos(
        "quadratic-ppm-per-c2",
        a.quadratic_ppm_per_c2.abs(),
        0.0,
        10.0,
    )?;
    pos("cubic-ppm-per-c3", a.cubic_ppm_per_c3.abs(), 0.0, 1.0)?;
    pos("curve-centre-c", a.curve_centre_c, -55.0, 125.0)?;
    let run = simulate(&a.test(), &a.rig());
    let truth = a.rig().truth;
    let knees: Vec<f64> = truth.knees[..truth.n_knees].iter().map(|k| k.0).collect();
    let mut w = RunWriter::create(
        &a.out.out,
        &format!(
            "gyro-lab simulate scale-factor: {:?} test, seed {}; truth: knees at {:?} degC, curvature {} ppm/degC^2 and {} ppm/degC^3 about {} degC, sensor lag {} s\n\
             {} is the coil sensor; {} and {} are the truth (not used by the fit)",
            a.test,
            a.seed.seed,
            knees,
            truth.quad_ppm_per_c2,
            truth.cubic_ppm_per_c3,
            truth.curve_centre_c,
            a.sensor_lag_s,
            Column::Temp.name(),
            Column::TrueCoilTemp.name(),
            Column::TrueScaleFactor.name()
        ),
        &[
            (Column::Time, Fixed(3)),
            (Column::RefRate, Fixed(6)),
            (Column::Rate, Fixed(10)),
            (Column::Temp, Fixed(4)),
            (Column::AirTemp, Fixed(3)),
            (Column::TrueCoilTemp, Fixed(4)),
            (Column::TrueScaleFactor, Fixed(4)),
        ],
    )?;
    for k in 0..run.t_s.len() {
        w.row(&[
            run.t_s[k],
            run.ref_rate_dps[k],
            run.rate_dps[k],
            run.temp_c[k],
            run.air_c[k],
            run.coil_true_c[k],
            run.sf_true_ppm[k],
        ])?;
    }
    w.finish()?;
    let hours = run.t_s.last().copied().unwrap_or(0.0) / 3600.0;
    if a.json.json {
        print_json(&serde_json::json!({
            "rows": run.t_s.len(), "duration_h": hours, "knees_true_c": knees, "out": a.out.out
        }))
    } else {
        println!(
            "{} rows, {hours:.1} h, true knees {knees:?} degC -> {}",
            run.t_s.len(),
            a.out.out.display()
        );
        Ok(())
    }
}
