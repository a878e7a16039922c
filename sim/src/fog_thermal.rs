//! A FOG over temperature (docs/fog.md): the scale factor varies with the
//! coil temperature, piecewise linear with knees, on a background that may
//! be smoothly curved (quadratic and cubic terms about a centre); the bias
//! varies too; the coil follows the chamber air with a lag and its sensor
//! lags the coil.
//! Used by `gyro-lab simulate scale-factor` (run files at the rate level)
//! and by the `qemu` firmware (the Sagnac phase scaled by the true scale
//! factor, the coil sensor read through the frame path).

#[allow(unused_imports)] // f64 maths comes from libm where core lacks it
use num_traits::float::Float;

/// Most knees of the truth.
pub const MAX_KNEES: usize = 4;

/// The true scale-factor error and bias over coil temperature.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ScaleFactorTruth {
    /// Scale-factor error at 20 degC of the linear part (the curvature
    /// terms below add to it), ppm (output/input - 1 with the nominal
    /// scale factor).
    pub sf_20c_ppm: f64,
    /// The linear part's slope below the first knee, ppm/degC.
    pub slope_ppm_per_c: f64,
    /// Smooth curvature: `quad * (T - centre)^2 + cubic * (T - centre)^3`
    /// added to the error, ppm/degC^2 and ppm/degC^3 (0 for a coil whose
    /// scale factor is piecewise linear).
    pub quad_ppm_per_c2: f64,
    pub cubic_ppm_per_c3: f64,
    /// Centre of the curvature terms, degC.
    pub curve_centre_c: f64,
    /// Knees: temperature, degC, and the slope change there, ppm/degC.
    pub knees: [(f64, f64); MAX_KNEES],
    pub n_knees: usize,
    /// Scale factor for positive rates less that for negative rates, ppm.
    pub asymmetry_ppm: f64,
    /// Bias at 20 degC, deg/h, and its temperature slope, deg/h/degC.
    pub bias_20c_dph: f64,
    pub bias_slope_dph_per_c: f64,
}

impl Default for ScaleFactorTruth {
    /// An ASE-source FOG: 1.5 ppm/degC, a knee at 48 degC (the published
    /// one) where the slope rises by 6 ppm/degC; 1 ppm asymmetry.
    fn default() -> Self {
        Self {
            sf_20c_ppm: 150.0,
            slope_ppm_per_c: 1.5,
            quad_ppm_per_c2: 0.0,
            cubic_ppm_per_c3: 0.0,
            curve_centre_c: 10.0,
            knees: [(48.0, 6.0), (0.0, 0.0), (0.0, 0.0), (0.0, 0.0)],
            n_knees: 1,
            asymmetry_ppm: 1.0,
            bias_20c_dph: 0.3,
            bias_slope_dph_per_c: 0.004,
        }
    }
}

impl ScaleFactorTruth {
    /// The same gyro without knees.
    pub fn without_knees(self) -> Self {
        Self { n_knees: 0, ..self }
    }

    /// The same gyro with a smooth curvature about `centre_c`: `quad`
    /// ppm/degC^2, `cubic` ppm/degC^3.
    pub fn curved(self, quad: f64, cubic: f64, centre_c: f64) -> Self {
        Self {
            quad_ppm_per_c2: quad,
            cubic_ppm_per_c3: cubic,
            curve_centre_c: centre_c,
            ..self
        }
    }

    /// A smoothly curved coil with no knee: 0.02 ppm/degC^2 about 10 degC
    /// on the default slope.
    pub fn quadratic() -> Self {
        Self::default().without_knees().curved(0.02, 0.0, 10.0)
    }

    /// A cubic coil with no knee: 2e-4 ppm/degC^3 about 10 degC (25 ppm
    /// off the line at the ends of -40..+60 degC) on the default slope.
    pub fn cubic() -> Self {
        Self::default().without_knees().curved(0.0, 2e-4, 10.0)
    }

    /// The default knee (48 degC, +6 ppm/degC) on the quadratic's curved
    /// background.
    pub fn knee_on_curve() -> Self {
        Self::default().curved(0.02, 0.0, 10.0)
    }

    /// Curvature of the error at `t_c`, ppm/degC^2 (the knees' none).
    pub fn curvature_ppm_per_c2(&self, t_c: f64) -> f64 {
        let x = t_c - self.curve_centre_c;
        2.0 * self.quad_ppm_per_c2 + 6.0 * self.cubic_ppm_per_c3 * x
    }

    /// Scale-factor error, ppm, at coil temperature `t_c` for a rate of sign
    /// `sign` (+1, -1; 0 for the mean of both).
    pub fn sf_ppm(&self, t_c: f64, sign: f64) -> f64 {
        let mut e = self.sf_20c_ppm + self.slope_ppm_per_c * (t_c - 20.0);
        let x = t_c - self.curve_centre_c;
        e += x * x * (self.quad_ppm_per_c2 + self.cubic_ppm_per_c3 * x);
        for &(tk, ds) in self.knees.iter().take(self.n_knees.min(MAX_KNEES)) {
            e += ds * (t_c - tk).max(0.0);
        }
        e + 0.5 * self.asymmetry_ppm * sign
    }

    pub fn bias_dph(&self, t_c: f64) -> f64 {
        self.bias_20c_dph + self.bias_slope_dph_per_c * (t_c - 20.0)
    }

    /// The gyro's output (nominal scale factor) for input `rate_dps`, deg/s,
    /// noise not included.
    pub fn output_dps(&self, rate_dps: f64, t_c: f64) -> f64 {
        let sign = if rate_dps > 0.0 {
            1.0
        } else if rate_dps < 0.0 {
            -1.0
        } else {
            0.0
        };
        rate_dps * (1.0 + self.sf_ppm(t_c, sign) * 1e-6) + self.bias_dph(t_c) / 3600.0
    }
}

/// Coil and coil-sensor temperatures in a chamber.
#[derive(Clone, Copy, Debug)]
pub struct CoilThermal {
    /// Coil lag to the chamber air, s.
    pub tau_coil_s: f64,
    /// Sensor lag to the coil, s.
    pub tau_sensor_s: f64,
    pub coil_c: f64,
    pub sensor_c: f64,
}

impl CoilThermal {
    /// Soaked at `t0_c`; the reference housing: 600 s coil lag, 30 s sensor lag.
    pub fn new(t0_c: f64) -> Self {
        Self {
            tau_coil_s: 600.0,
            tau_sensor_s: 30.0,
            coil_c: t0_c,
            sensor_c: t0_c,
        }
    }

    /// Advances `dt` s with the air at `air_c` (held over dt); exact
    /// first-order steps. Returns (coil, sensor) true temperatures at the end.
    pub fn step(&mut self, dt: f64, air_c: f64) -> (f64, f64) {
        let coil0 = self.coil_c;
        let a = 1.0 - (-dt / self.tau_coil_s).exp();
        self.coil_c += (air_c - self.coil_c) * a;
        // The sensor follows the coil, taken as moving linearly over dt.
        self.sensor_c = lag_linear(self.sensor_c, coil0, self.coil_c, dt, self.tau_sensor_s);
        (self.coil_c, self.sensor_c)
    }

    /// Advances the sensor alone, with the coil driven from outside (the
    /// qemu demo sweeps the coil directly): `coil_c` is the coil at the end.
    pub fn step_coil(&mut self, dt: f64, coil_c: f64) -> f64 {
        self.sensor_c = lag_linear(self.sensor_c, self.coil_c, coil_c, dt, self.tau_sensor_s);
        self.coil_c = coil_c;
        self.sensor_c
    }
}

/// Exact response over `dt` of a first-order lag (time constant `tau`,
/// state `y`) to an input moving linearly from `u0` to `u1`.
fn lag_linear(y: f64, u0: f64, u1: f64, dt: f64, tau: f64) -> f64 {
    if tau <= 0.0 {
        return u1;
    }
    let e = (-dt / tau).exp();
    let slope = (u1 - u0) / dt;
    // y(t) = u(t) - slope*tau + (y0 - u0 + slope*tau) e^(-t/tau)
    u1 - slope * tau + (y - u0 + slope * tau) * e
}
