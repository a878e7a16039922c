//! Simulated scale-factor calibration runs on one FOG (gyro_sp's
//! `sim::fog_thermal` truth): a continuous-rotation test (constant table
//! rate while the chamber sweeps) and the classic multi-point test
//! (temperature plateaus, each with a rate sequence in both directions).
//! Rates are in deg/s; one row per sample period, the means over it.

use gyro_sim::{CoilThermal, NoiseParams, RateNoise, ScaleFactorTruth};
use rand_core::SeedableRng;
use rand_distr::{Distribution, StandardNormal};
use rand_xoshiro::Xoshiro256PlusPlus;

/// Chamber profiles of the continuous-rotation test.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SweepProfile {
    /// 20 -> -40 degC, 60 min soak, -> +60 degC, 60 min soak, -> -40 degC,
    /// 30 min soak; ramps at 1 degC/min.
    Cycle,
    /// Plateaus 20, 0, 45, 55, 30, -20, 10 degC, ramps at 2 degC/min,
    /// 40 min soaks (a validation profile unlike the cycle).
    Steps,
}

/// Table directions of the continuous test.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Direction {
    Positive,
    Negative,
    /// Reversed every `reverse_every_s` (separates bias and scale factor).
    Both,
}

/// What a run is made of.
#[derive(Clone, Debug)]
pub enum Test {
    Continuous {
        profile: SweepProfile,
        rate_dps: f64,
        direction: Direction,
        reverse_every_s: f64,
    },
    MultiPoint {
        plateaus_c: Vec<f64>,
        rates_dps: Vec<f64>,
        soak_s: f64,
        dwell_s: f64,
    },
}

/// The gyro and rig behind a run.
#[derive(Clone, Copy, Debug)]
pub struct RigParams {
    pub truth: ScaleFactorTruth,
    /// Angle random walk, deg/sqrt(h), and bias instability, deg/h.
    pub arw_dpsh: f64,
    pub bias_instability_dph: f64,
    /// Coil sensor: noise rms, degC (read at 1/128 degC).
    pub sensor_noise_c: f64,
    pub tau_coil_s: f64,
    pub tau_sensor_s: f64,
    pub dt_s: f64,
    pub seed: u64,
}

impl Default for RigParams {
    /// A navigation-grade 1 km coil: 0.005 deg/sqrt(h), 0.01 deg/h; a
    /// TMP117 on the coil mount.
    fn default() -> Self {
        Self {
            truth: ScaleFactorTruth::default(),
            arw_dpsh: 0.005,
            bias_instability_dph: 0.01,
            sensor_noise_c: 0.005,
            tau_coil_s: 600.0,
            tau_sensor_s: 30.0,
            dt_s: 1.0,
            seed: 1,
        }
    }
}

/// A run as the tools read it, with the truth alongside.
#[derive(Clone, Debug, Default)]
pub struct Run {
    pub t_s: Vec<f64>,
    pub ref_rate_dps: Vec<f64>,
    pub rate_dps: Vec<f64>,
    pub temp_c: Vec<f64>,
    pub air_c: Vec<f64>,
    pub coil_true_c: Vec<f64>,
    pub sf_true_ppm: Vec<f64>,
}

/// Piecewise-linear chamber air temperature through `(time, temp)` points.
struct AirProfile(Vec<(f64, f64)>);

impl AirProfile {
    /// Start at `points[0]`, hold `hold0_s`, then ramp at `rate_c_per_s`
    /// to each next point and hold there `hold_s` (`holds` per point).
    fn ramps(points: &[f64], rate_c_per_s: f64, hold0_s: f64, holds: &[f64]) -> Self {
        let mut v = vec![(0.0, points[0]), (hold0_s, points[0])];
        let mut t = hold0_s;
        for (k, w) in points.windows(2).enumerate() {
            t += (w[1] - w[0]).abs() / rate_c_per_s;
            v.push((t, w[1]));
            t += holds.get(k).copied().unwrap_or(0.0);
            v.push((t, w[1]));
        }
        Self(v)
    }

    fn at(&self, t: f64) -> f64 {
        let p = &self.0;
        match p.iter().position(|&(tk, _)| tk > t) {
            None => p[p.len() - 1].1,
            Some(0) => p[0].1,
            Some(i) => {
                let (t0, x0) = p[i - 1];
                let (t1, x1) = p[i];
                x0 + (x1 - x0) * (t - t0) / (t1 - t0)
            }
        }
    }

    fn duration(&self) -> f64 {
        self.0.last().map_or(0.0, |x| x.0)
    }
}

/// The table rate (deg/s) over the sample ending at `t_end`, per test.
struct RateSchedule {
    /// (start time, rate) in order; the last holds.
    steps: Vec<(f64, f64)>,
}

impl RateSchedule {
    fn at(&self, t_mid: f64) -> f64 {
        self.steps
            .iter()
            .rev()
            .find(|(t0, _)| *t0 <= t_mid)
            .map_or(0.0, |x| x.1)
    }
}

fn continuous_schedule(duration: f64, rate: f64, dir: Direction, every: f64) -> RateSchedule {
    let steps = match dir {
        Direction::Positive => vec![(0.0, rate.abs())],
        Direction::Negative => vec![(0.0, -rate.abs())],
        Direction::Both => {
            let every = every.max(1.0);
            let n = (duration / every).ceil() as usize + 1;
            (0..n)
                .map(|k| {
                    let s = if k % 2 == 0 { 1.0 } else { -1.0 };
                    (k as f64 * every, s * rate.abs())
                })
                .collect()
        }
    };
    RateSchedule { steps }
}

/// The chamber air and the table rate over a test.
fn plan(test: &Test) -> (AirProfile, RateSchedule) {
    match test {
        Test::Continuous {
            profile,
            rate_dps,
            direction,
            reverse_every_s,
        } => {
            let air = match profile {
                SweepProfile::Cycle => AirProfile::ramps(
                    &[20.0, -40.0, 60.0, -40.0],
                    1.0 / 60.0,
                    600.0,
                    &[3600.0, 3600.0, 1800.0],
                ),
                SweepProfile::Steps => AirProfile::ramps(
                    &[20.0, 0.0, 45.0, 55.0, 30.0, -20.0, 10.0],
                    2.0 / 60.0,
                    600.0,
                    &[2400.0; 6],
                ),
            };
            let d = air.duration();
            (
                air,
                continuous_schedule(d, *rate_dps, *direction, *reverse_every_s),
            )
        }
        Test::MultiPoint {
            plateaus_c,
            rates_dps,
            soak_s,
            dwell_s,
        } => {
            // Ramps at 1 degC/min between plateaus at rest; at each plateau a
            // soak at rest, then every rate for `dwell_s` each way.
            let seq_s = 2.0 * dwell_s * rates_dps.len() as f64;
            let holds: Vec<f64> = plateaus_c.iter().map(|_| soak_s + seq_s).collect();
            let air = AirProfile::ramps(plateaus_c, 1.0 / 60.0, soak_s + seq_s, &holds[1..]);
            let mut steps = vec![(0.0, 0.0)];
            // Times the holds end: the sequence occupies the last seq_s of each.
            for (k, &(t, _)) in air.0.iter().enumerate() {
                if k % 2 == 1 {
                    let mut t0 = t - seq_s;
                    for &r in rates_dps {
                        steps.push((t0, r.abs()));
                        steps.push((t0 + dwell_s, -r.abs()));
                        t0 += 2.0 * dwell_s;
                    }
                    steps.push((t, 0.0));
                }
            }
            (air, RateSchedule { steps })
        }
    }
}

/// Simulates a run.
pub fn simulate(test: &Test, p: &RigParams) -> Run {
    let (air, schedule) = plan(test);
    let dt = p.dt_s;
    let n = (air.duration() / dt).round() as usize;
    let mut thermal = CoilThermal::new(air.at(0.0));
    thermal.tau_coil_s = p.tau_coil_s;
    thermal.tau_sensor_s = p.tau_sensor_s;
    let mut noise = RateNoise::new(
        NoiseParams {
            n_dps_rts: NoiseParams::arw_from_dpsh(p.arw_dpsh),
            b_dps: NoiseParams::b_from_dph(p.bias_instability_dph),
            flicker_max_tau_s: 1e5,
            ..NoiseParams::default()
        },
        dt,
        p.seed,
    );
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(p.seed ^ 0x5EED_C011);
    let mut run = Run::default();
    for k in 0..n {
        let t0 = k as f64 * dt;
        let t_mid = t0 + 0.5 * dt;
        let a = air.at(t_mid);
        let coil_start = thermal.coil_c;
        let sensor_start = thermal.sensor_c;
        let (coil, sensor_end) = thermal.step(dt, a);
        // Rows are means over the period: the sensor's too (a TMP117
        // averaging its conversions over the row).
        let sensor = 0.5 * (sensor_start + sensor_end);
        let w = schedule.at(t_mid);
        let coil_mid = 0.5 * (coil_start + coil);
        let y = p.truth.output_dps(w, coil_mid) + noise.sample();
        let z: f64 = StandardNormal.sample(&mut rng);
        let read = ((sensor + p.sensor_noise_c * z) * 128.0).round() / 128.0;
        let sign = if w > 0.0 {
            1.0
        } else if w < 0.0 {
            -1.0
        } else {
            0.0
        };
        run.t_s.push(t0 + dt);
        run.ref_rate_dps.push(w);
        run.rate_dps.push(y);
        run.temp_c.push(read);
        run.air_c.push(a);
        run.coil_true_c.push(coil_mid);
        run.sf_true_ppm.push(p.truth.sf_ppm(coil_mid, sign));
    }
    run
}
