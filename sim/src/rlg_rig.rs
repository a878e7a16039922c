//! Simulated RLG in a thermal chamber (docs/rlg.md): the case follows the
//! chamber air with a lag and warms itself up; the two monoblock sensors sit
//! at places with different lags and different self-heating, so their
//! difference dT moves with ramps and warm-up. The true bias follows the
//! physics of the improved model from the *true* temperatures and the true
//! d(dT)/dt; the firmware sees TMP117 readings (noise, 1/128 degC steps) and
//! a filtered gradient. Rate noise (angle random walk) and the quadrature
//! counter's whole counts are modelled. Used by `gyro-lab simulate chamber`
//! (f64 on the host) and by the `qemu` firmware.

use gyro_sp::rlg::ThermalCoeffs;
#[allow(unused_imports)] // f64 maths comes from libm where core lacks it
use num_traits::float::Float;
use rand_core::SeedableRng;
use rand_distr::{Distribution, StandardNormal};
use rand_xoshiro::Xoshiro256PlusPlus;

#[derive(Clone, Copy, Debug)]
pub struct ChamberParams {
    /// Case lag to the chamber air, s.
    pub tau_case_s: f64,
    /// Self-heating of the case at full warm-up, degC, and its time constant, s.
    pub heat_case_c: f64,
    pub tau_heat_s: f64,
    /// Monoblock sensor places: lag to the case, s, and self-heating, degC.
    pub tau_a_s: f64,
    pub heat_a_c: f64,
    pub tau_b_s: f64,
    pub heat_b_c: f64,
    /// Sensor noise, degC (TMP117: about 0.005 degC rms at 8 averages).
    pub sensor_noise_c: f64,
    /// Counts per degree (pulses per degree x 4 quadrature edges).
    pub counts_per_deg: f64,
    /// White rate noise, deg/h rms in 1 s (angle random walk in deg/sqrt(h)
    /// is this / 60).
    pub rate_noise_dph_1s: f64,
    /// The true bias model.
    pub truth: ThermalCoeffs,
    pub seed: u64,
}

impl Default for ChamberParams {
    /// A navigation-grade RLG whose raw drift spans about 0.6..0.7 deg/h over
    /// -40..+50 degC (docs/rlg.md reference).
    fn default() -> Self {
        Self {
            tau_case_s: 900.0,
            heat_case_c: 4.0,
            tau_heat_s: 1200.0,
            tau_a_s: 300.0,
            heat_a_c: 3.0,
            tau_b_s: 450.0,
            heat_b_c: 1.5,
            sensor_noise_c: 0.005,
            counts_per_deg: 8000.0,
            rate_noise_dph_1s: 0.2,
            truth: ThermalCoeffs {
                bias0_dph: 0.05,
                k1_dph_per_c: 0.08,
                k2_dph_per_c_per_s: 4.0,
                k3_dph_per_c2: 0.012,
                k4_dph_per_c: 0.004,
                k5_dph: 0.12,
                tau_warm_s: 800.0,
            },
            seed: 1,
        }
    }
}

/// One sample: what the board reads, plus the truth.
#[derive(Clone, Copy, Debug, Default)]
pub struct ChamberSample {
    pub t_s: f64,
    /// Sensor readings, degC (TMP117 resolution).
    pub t_mono_a_c: f64,
    pub t_mono_b_c: f64,
    pub t_case_c: f64,
    /// The encoder timer's 16-bit counter.
    pub counter: u16,
    /// Whole counts since power-on.
    pub counts: i64,
    pub bias_true_dph: f64,
    /// The gyro's true rate over the step (input, bias and rate noise),
    /// deg/s: what a gyro model with its own counter (the dithered one,
    /// `rlg_dither_rig.rs`) integrates.
    pub rate_true_dps: f64,
}

pub struct Chamber {
    pub p: ChamberParams,
    t: f64,
    case: f64,
    a: f64,
    b: f64,
    angle_deg: f64,
    rng: Xoshiro256PlusPlus,
}

impl Chamber {
    /// Power-on soaked at the chamber temperature `t0_c`.
    pub fn new(p: ChamberParams, t0_c: f64) -> Self {
        Self {
            p,
            t: 0.0,
            case: t0_c,
            a: t0_c,
            b: t0_c,
            angle_deg: 0.0,
            rng: Xoshiro256PlusPlus::seed_from_u64(p.seed),
        }
    }

    fn normal(&mut self) -> f64 {
        StandardNormal.sample(&mut self.rng)
    }

    /// Advances `dt` s with the chamber air at `air_c` and the input rate
    /// `rate_dps`; returns the sensor reads and counter at the end.
    pub fn step(&mut self, dt: f64, air_c: f64, rate_dps: f64) -> ChamberSample {
        let p = self.p;
        let warm = |tau: f64, t: f64| 1.0 - (-t / tau).exp();
        let t1 = self.t + dt;
        // Exact first-order steps towards targets held over dt.
        let lag = |x: &mut f64, target: f64, tau: f64| {
            *x += (target - *x) * (1.0 - (-dt / tau).exp());
        };
        let heat = warm(p.tau_heat_s, t1);
        let dt_before = self.a - self.b;
        lag(&mut self.case, air_c + p.heat_case_c * heat, p.tau_case_s);
        let case = self.case;
        lag(&mut self.a, case + p.heat_a_c * heat, p.tau_a_s);
        lag(&mut self.b, case + p.heat_b_c * heat, p.tau_b_s);
        self.t = t1;
        let d = self.a - self.b;
        let grad = (d - dt_before) / dt;
        let c = p.truth;
        let bias = c.bias0_dph
            + c.k1_dph_per_c * d
            + c.k2_dph_per_c_per_s * grad
            + c.k3_dph_per_c2 * d * d
            + c.k4_dph_per_c * self.case
            + c.k5_dph * warm(c.tau_warm_s, t1);
        // White rate noise of rms `rate_noise_dph_1s` in 1 s: angle random walk.
        let noise_dph = p.rate_noise_dph_1s * self.normal() / dt.sqrt();
        let rate_true_dps = rate_dps + (bias + noise_dph) / 3600.0;
        self.angle_deg += rate_true_dps * dt;
        let counts = (self.angle_deg * p.counts_per_deg).floor() as i64;
        let read = |x: f64, s: &mut Self| {
            let v = x + p.sensor_noise_c * s.normal();
            (v * 128.0).round() / 128.0
        };
        let (a, b, k) = (self.a, self.b, self.case);
        ChamberSample {
            t_s: t1,
            t_mono_a_c: read(a, self),
            t_mono_b_c: read(b, self),
            t_case_c: read(k, self),
            counter: counts as u16,
            counts,
            bias_true_dph: bias,
            rate_true_dps,
        }
    }
}
