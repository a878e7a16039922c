//! What a run of the second generator holds, by its own formulas (the
//! true temperatures and their exact derivatives, the rows' means of what
//! moves within them), and the same truth in the library's names and
//! parameters for scoring.

use super::physics::Physics;
use std::collections::BTreeMap;

/// What a run holds.
#[derive(Clone, Debug, Default)]
pub struct Truth {
    pub bias: f64,
    pub sf_ppm: f64,
    pub asym_ppm: f64,
    pub sf_t: f64,
    pub knee: Option<(f64, f64)>,
    pub vib: f64,
    pub lock_in: f64,
    pub k_dt: f64,
    pub k_grad: f64,
    pub k_dt2: f64,
    pub k_case: f64,
    /// Warm-up: amplitude, tau, and whether it decays (A exp(-t/tau)).
    pub warm: Option<(f64, f64, bool)>,
    pub b_t: f64,
    pub shupe: f64,
    /// Outside the library.
    pub w2: f64,
    pub w3: f64,
    pub step: Option<(f64, f64)>,
    pub ramp: f64,
    pub curv: f64,
}

impl Truth {
    /// Every linear coefficient times `f`.
    pub fn scaled(&self, f: f64) -> Self {
        Self {
            bias: self.bias * f,
            sf_ppm: self.sf_ppm * f,
            asym_ppm: self.asym_ppm * f,
            sf_t: self.sf_t * f,
            knee: self.knee.map(|(k, s)| (k, s * f)),
            vib: self.vib * f,
            lock_in: self.lock_in,
            k_dt: self.k_dt * f,
            k_grad: self.k_grad * f,
            k_dt2: self.k_dt2 * f,
            k_case: self.k_case * f,
            warm: self.warm.map(|(a, t, d)| (a * f, t, d)),
            b_t: self.b_t * f,
            shupe: self.shupe * f,
            w2: self.w2 * f,
            w3: self.w3 * f,
            step: self.step.map(|(a, s)| (a, s * f)),
            ramp: self.ramp * f,
            curv: self.curv * f,
        }
    }

    /// The output less the input, deg/s, row by row.
    pub fn output(&self, ph: &Physics) -> Vec<f64> {
        let d = 1.0 / 3600.0;
        (0..ph.t.len())
            .map(|k| {
                let t = ph.t[k];
                let w = ph.w[k];
                let mut y = self.bias * d;
                y += 1e-6 * self.sf_ppm * w + 0.5e-6 * self.asym_ppm * ph.wabs[k];
                if !ph.temp.is_empty() {
                    let tc = ph.temp[k];
                    y += 1e-6 * self.sf_t * w * (tc - 20.0);
                    if let Some((kn, sl)) = self.knee {
                        y += 1e-6 * sl * w * (tc - kn).max(0.0);
                    }
                    y += d * self.b_t * (tc - 20.0) + d * self.shupe * ph.temp_rate[k];
                    y += d * self.k_case * (tc - 20.0) + d * self.curv * ph.temp_curv[k];
                }
                y += d * self.vib * ph.acc2[k];
                if self.lock_in > 0.0 {
                    let a = w.abs();
                    let out = if a <= self.lock_in {
                        0.0
                    } else {
                        w.signum() * (a * a - self.lock_in * self.lock_in).sqrt()
                    };
                    y += out - w;
                }
                if let Some((a, b, dr)) = &ph.mono {
                    let dt = a[k] - b[k];
                    y += d * (self.k_dt * dt + self.k_grad * dr[k] + self.k_dt2 * dt * dt);
                }
                if let Some((amp, tau, decays)) = self.warm {
                    let e = (-t / tau).exp();
                    y += d * amp * if decays { e } else { 1.0 - e };
                }
                y += d * (self.w2 * ph.w2[k] + self.w3 * ph.w3[k]);
                if let Some((at, size)) = self.step {
                    if t >= at {
                        y += d * size;
                    }
                }
                y += d * self.ramp * t / 3600.0;
                y
            })
            .collect()
    }

    /// The truth in the library's names and parameters.
    pub fn library(&self, rlg: bool) -> BTreeMap<String, BTreeMap<String, f64>> {
        let mut m: BTreeMap<String, BTreeMap<String, f64>> = BTreeMap::new();
        let mut put = |e: &str, p: &[(&str, f64)]| {
            m.insert(
                e.into(),
                p.iter().map(|(k, v)| (k.to_string(), *v)).collect(),
            );
        };
        let mut bias = self.bias;
        if let Some((a, tau, decays)) = self.warm {
            if decays {
                bias += a;
                put("warm_up", &[("amplitude_dph", -a), ("tau_s", tau)]);
            } else {
                put("warm_up", &[("amplitude_dph", a), ("tau_s", tau)]);
            }
        }
        if rlg && self.k_case != 0.0 {
            // k4 (T_K - 20) is the library's form already.
        }
        if bias != 0.0 {
            put("bias", &[("bias_dph", bias)]);
        }
        let nz = |v: f64| v != 0.0;
        if nz(self.sf_ppm) {
            put("scale_factor_error", &[("error_ppm", self.sf_ppm)]);
        }
        if nz(self.asym_ppm) {
            put(
                "scale_factor_asymmetry",
                &[("asymmetry_ppm", self.asym_ppm)],
            );
        }
        if nz(self.sf_t) {
            put("scale_factor_temperature", &[("ppm_per_c", self.sf_t)]);
        }
        if let Some((k, s)) = self.knee {
            put(
                "scale_factor_knee",
                &[("knee_c", k), ("slope_change_ppm_per_c", s)],
            );
        }
        if nz(self.vib) {
            put("vibration_rectification", &[("dph_per_dps2_sq", self.vib)]);
        }
        if nz(self.lock_in) {
            put("lock_in", &[("lock_in_dps", self.lock_in)]);
        }
        if nz(self.k_dt) {
            put("thermal_difference", &[("dph_per_c", self.k_dt)]);
        }
        if nz(self.k_grad) {
            put("thermal_gradient", &[("dph_per_c_per_s", self.k_grad)]);
        }
        if nz(self.k_dt2) {
            put("thermal_difference_squared", &[("dph_per_c2", self.k_dt2)]);
        }
        if nz(self.k_case) {
            put("case_temperature", &[("dph_per_c", self.k_case)]);
        }
        if nz(self.b_t) {
            put("bias_temperature", &[("dph_per_c", self.b_t)]);
        }
        if nz(self.shupe) {
            put("shupe", &[("dph_per_c_per_s", self.shupe)]);
        }
        m
    }

    pub fn outside(&self) -> Vec<String> {
        let mut v = vec![];
        if self.w2 != 0.0 {
            v.push(format!("{} deg/h per (deg/s)^2 times w^2", self.w2));
        }
        if self.w3 != 0.0 {
            v.push(format!("{} deg/h per (deg/s)^3 times w^3", self.w3));
        }
        if let Some((at, s)) = self.step {
            v.push(format!("a bias step of {s} deg/h at {at} s"));
        }
        if self.ramp != 0.0 {
            v.push(format!("a rate ramp of {} deg/h per hour", self.ramp));
        }
        if self.curv != 0.0 {
            v.push(format!("{} deg/h per degC/s^2 times d2T/dt2", self.curv));
        }
        v
    }
}
