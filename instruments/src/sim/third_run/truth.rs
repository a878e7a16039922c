//! What a run of the third generator holds: its error terms by physics.md's
//! formulas, on the true temperatures and their exact derivatives and the
//! rows' exact means of what moves within them; and the same truth in the
//! library's names and parameters, for scoring only.

use std::collections::BTreeMap;

/// The physical state over a run, before noise, row by row.
#[derive(Clone, Debug, Default)]
pub struct Physics {
    pub t: Vec<f64>,
    /// Row means of the input rate w (deg/s), w^2, |w|, w |w|; the
    /// angular acceleration's mean square (deg/s^2)^2 and its value as a
    /// reference sensor samples it (the row's middle).
    pub w: Vec<f64>,
    pub w2: Vec<f64>,
    pub wabs: Vec<f64>,
    pub wabsw: Vec<f64>,
    pub acc2: Vec<f64>,
    pub acc: Option<Vec<f64>>,
    /// Sub-samples of w within each row (for lock-in's beat), if kept.
    pub w_sub: Option<Vec<Vec<f64>>>,
    /// The coil (FOG) or die (MEMS) temperature; the RLG's case and
    /// monoblocks.
    pub main: Option<super::thermal::Temp>,
    pub case: Option<super::thermal::Temp>,
    pub mono: Option<(super::thermal::Temp, super::thermal::Temp)>,
}

/// The error terms a run holds (zero: absent).
#[derive(Clone, Debug, Default)]
pub struct Truth {
    pub bias_dph: f64,
    pub sf_ppm: f64,
    pub asym_ppm: f64,
    pub sf_ppm_per_c: f64,
    pub knee: Option<(f64, f64)>,
    pub vib: f64,
    pub lock_in_dps: f64,
    pub k_dt: f64,
    pub k_grad: f64,
    pub k_dt2: f64,
    pub k_case: f64,
    /// Warm-up amplitude, time constant, and whether it decays to nothing.
    pub warm: Option<(f64, f64, bool)>,
    pub bias_per_c: f64,
    pub rate_coef: f64,
    // Outside the library.
    pub sine: Option<(f64, f64, f64)>,
    pub curv: f64,
    pub step: Option<(f64, f64)>,
    pub ageing_dph_per_h: f64,
    pub w2: f64,
    pub wabsw: f64,
    pub temp2: f64,
    pub case_minus_mono: f64,
}

fn beat(w: f64, wl: f64) -> f64 {
    if w.abs() <= wl {
        0.0
    } else {
        w.signum() * (w * w - wl * wl).sqrt()
    }
}

impl Truth {
    /// Every coefficient times `f` (the non-linear parameters kept).
    pub fn scaled(&self, f: f64) -> Self {
        let mut o = self.clone();
        o.bias_dph *= f;
        o.sf_ppm *= f;
        o.asym_ppm *= f;
        o.sf_ppm_per_c *= f;
        o.knee = o.knee.map(|(k, s)| (k, s * f));
        o.vib *= f;
        o.k_dt *= f;
        o.k_grad *= f;
        o.k_dt2 *= f;
        o.k_case *= f;
        o.warm = o.warm.map(|(a, t, d)| (a * f, t, d));
        o.bias_per_c *= f;
        o.rate_coef *= f;
        o.sine = o.sine.map(|(a, p, ph)| (a * f, p, ph));
        o.curv *= f;
        o.step = o.step.map(|(t, s)| (t, s * f));
        o.ageing_dph_per_h *= f;
        o.w2 *= f;
        o.wabsw *= f;
        o.temp2 *= f;
        o.case_minus_mono *= f;
        o
    }

    /// The gyro's output less its input, deg/s, row by row.
    pub fn error(&self, ph: &Physics) -> Vec<f64> {
        let h = 1.0 / 3600.0;
        (0..ph.t.len())
            .map(|k| {
                let t = ph.t[k];
                let w = ph.w[k];
                let mut e = self.bias_dph * h + 1e-6 * self.sf_ppm * w;
                e += 0.5e-6 * self.asym_ppm * ph.wabs[k];
                if let Some(m) = &ph.main {
                    let tc = m.v[k];
                    e += 1e-6 * self.sf_ppm_per_c * w * (tc - 20.0);
                    if let Some((kc, s)) = self.knee {
                        e += 1e-6 * s * w * (tc - kc).max(0.0);
                    }
                    e += h * (self.bias_per_c * (tc - 20.0) + self.rate_coef * m.d1[k]);
                    e += h * (self.curv * m.d2[k] + self.temp2 * (tc - 20.0).powi(2));
                }
                e += h * self.vib * ph.acc2[k];
                if self.lock_in_dps > 0.0 {
                    let out = match &ph.w_sub {
                        Some(sub) => {
                            sub[k]
                                .iter()
                                .map(|&x| beat(x, self.lock_in_dps))
                                .sum::<f64>()
                                / sub[k].len() as f64
                        }
                        None => beat(w, self.lock_in_dps),
                    };
                    e += out - w;
                }
                if let (Some(c), Some((a, b))) = (&ph.case, &ph.mono) {
                    let dt = a.v[k] - b.v[k];
                    let ddt = a.d1[k] - b.d1[k];
                    e += h * (self.k_dt * dt + self.k_grad * ddt + self.k_dt2 * dt * dt);
                    e += h * (self.k_case * (c.v[k] - 20.0));
                    e += h * self.case_minus_mono * (c.v[k] - a.v[k]);
                }
                if let Some((a, tau, decays)) = self.warm {
                    let x = (-t / tau).exp();
                    e += h * a * if decays { x } else { 1.0 - x };
                }
                if let Some((a, p, phase)) = self.sine {
                    e += h * a * (std::f64::consts::TAU * t / p + phase).sin();
                }
                if let Some((at, size)) = self.step {
                    if t >= at {
                        e += h * size;
                    }
                }
                e += h * self.ageing_dph_per_h * t / 3600.0;
                e += h * (self.w2 * ph.w2[k] + self.wabsw * ph.wabsw[k]);
                e
            })
            .collect()
    }

    /// The truth in the library's names and parameters (a decaying
    /// warm-up A exp(-t/tau) as the constant A and a warm-up of -A).
    pub fn library(&self, mems: bool) -> BTreeMap<String, BTreeMap<String, f64>> {
        let mut m: BTreeMap<String, BTreeMap<String, f64>> = BTreeMap::new();
        let mut put = |e: &str, p: &[(&str, f64)]| {
            m.insert(
                e.to_owned(),
                p.iter().map(|(k, v)| (k.to_string(), *v)).collect(),
            );
        };
        let mut bias = self.bias_dph;
        if let Some((a, tau, decays)) = self.warm {
            let amp = if decays {
                bias += a;
                -a
            } else {
                a
            };
            put("warm_up", &[("amplitude_dph", amp), ("tau_s", tau)]);
        }
        let nz = |v: f64| v != 0.0;
        if nz(bias) {
            put("bias", &[("bias_dph", bias)]);
        }
        if nz(self.sf_ppm) {
            put("scale_factor_error", &[("error_ppm", self.sf_ppm)]);
        }
        if nz(self.asym_ppm) {
            put(
                "scale_factor_asymmetry",
                &[("asymmetry_ppm", self.asym_ppm)],
            );
        }
        if nz(self.sf_ppm_per_c) {
            put(
                "scale_factor_temperature",
                &[("ppm_per_c", self.sf_ppm_per_c)],
            );
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
        if nz(self.lock_in_dps) {
            put("lock_in", &[("lock_in_dps", self.lock_in_dps)]);
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
        if nz(self.bias_per_c) {
            put("bias_temperature", &[("dph_per_c", self.bias_per_c)]);
        }
        if nz(self.rate_coef) {
            put(
                Self::rate_name(mems),
                &[("dph_per_c_per_s", self.rate_coef)],
            );
        }
        m
    }

    /// The library's name of the rate-of-temperature term on this gyro.
    pub fn rate_name(mems: bool) -> &'static str {
        if mems {
            "bias_temperature_rate"
        } else {
            "shupe"
        }
    }

    /// What the run holds outside the library, described.
    pub fn outside(&self) -> Vec<String> {
        let mut v = vec![];
        if let Some((a, p, _)) = self.sine {
            v.push(format!("a sinusoidal bias of {a} deg/h, period {p} s"));
        }
        if self.curv != 0.0 {
            v.push(format!("{} deg/h per degC/s^2 times d2T/dt2", self.curv));
        }
        if let Some((t, s)) = self.step {
            v.push(format!("a bias step of {s} deg/h at {t} s"));
        }
        if self.ageing_dph_per_h != 0.0 {
            v.push(format!("ageing {} deg/h per hour", self.ageing_dph_per_h));
        }
        if self.w2 != 0.0 {
            v.push(format!("{} deg/h per (deg/s)^2 times w^2", self.w2));
        }
        if self.wabsw != 0.0 {
            v.push(format!("{} deg/h per (deg/s)^2 times w|w|", self.wabsw));
        }
        if self.temp2 != 0.0 {
            v.push(format!("{} deg/h per degC^2 times (T - 20)^2", self.temp2));
        }
        if self.case_minus_mono != 0.0 {
            v.push(format!(
                "{} deg/h per degC times (T_case - T_mono_a)",
                self.case_minus_mono
            ));
        }
        v
    }
}
