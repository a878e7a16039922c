//! Fringe-signal simulator of an RLG near lock-in (docs/rlg.md): integrates
//! `dpsi/dt = 2*pi*K*(Omega_I - Omega_L*sin(psi + beta))` numerically (RK4,
//! at most 0.05 rad of phase per step) and samples the photodiodes
//! `S = A*sin(psi) + offset` (and `Q = A*cos(psi) + offset`) with additive white
//! noise and an optional ADC of `bits` over +-1.1*A around the offset.
//! The estimator uses the closed-form periodic solution; this simulator does
//! not, so the two check each other.

use rand_core::SeedableRng;
use rand_distr::{Distribution, StandardNormal};
use rand_xoshiro::Xoshiro256PlusPlus;
use std::f64::consts::TAU;

#[derive(Clone, Debug)]
pub struct FringeParams {
    /// Scale factor K, fringes (pulses) per degree.
    pub pulses_per_deg: f64,
    /// Input rate Omega_I, deg/s.
    pub input_rate_dps: f64,
    /// Lock-in rate Omega_L, deg/s.
    pub lock_in_dps: f64,
    /// Constant phase beta, rad.
    pub beta_rad: f64,
    /// Initial phase psi(0), rad.
    pub psi0_rad: f64,
    pub sample_hz: f64,
    pub samples: usize,
    pub amplitude: f64,
    pub offset: f64,
    /// Noise standard deviation relative to the amplitude.
    pub noise_rel: f64,
    /// ADC resolution; `None`: no quantization.
    pub bits: Option<u32>,
    pub seed: u64,
}

impl Default for FringeParams {
    /// The reference conditions of docs/rlg.md (K = 2000, 20 kHz, 3 s).
    fn default() -> Self {
        Self {
            pulses_per_deg: 2000.0,
            input_rate_dps: 1.0,
            lock_in_dps: 0.1,
            beta_rad: 0.0,
            psi0_rad: 0.3,
            sample_hz: 20_000.0,
            samples: 60_000,
            amplitude: 1.0,
            offset: 0.0,
            noise_rel: 0.0,
            bits: None,
            seed: 1,
        }
    }
}

/// A simulated record: time and the two photodiode channels.
pub struct Fringe {
    pub t: Vec<f64>,
    pub s: Vec<f64>,
    pub q: Vec<f64>,
}

impl FringeParams {
    /// Beat frequency of the lock-in equation, Hz (0 when locked in).
    pub fn beat_hz(&self) -> f64 {
        let (wi, wl) = (self.input_rate_dps, self.lock_in_dps);
        self.pulses_per_deg * (wi * wi - wl * wl).max(0.0).sqrt()
    }

    pub fn simulate(&self) -> Fringe {
        let wi = TAU * self.pulses_per_deg * self.input_rate_dps;
        let wl = TAU * self.pulses_per_deg * self.lock_in_dps;
        let f = |psi: f64| wi - wl * (psi + self.beta_rad).sin();
        let dt = 1.0 / self.sample_hz;
        let sub = ((dt * (wi.abs() + wl.abs()) / 0.05).ceil() as usize).max(1);
        let h = dt / sub as f64;
        let mut rng = Xoshiro256PlusPlus::seed_from_u64(self.seed);
        let mut noise = || -> f64 {
            let n: f64 = StandardNormal.sample(&mut rng);
            n * self.noise_rel * self.amplitude
        };
        let adc = |x: f64| match self.bits {
            Some(b) => {
                let full = 1.1 * self.amplitude;
                let lsb = 2.0 * full / (1u64 << b) as f64;
                let code = ((x - self.offset + full) / lsb)
                    .floor()
                    .clamp(0.0, ((1u64 << b) - 1) as f64);
                self.offset - full + (code + 0.5) * lsb
            }
            None => x,
        };
        let mut psi = self.psi0_rad;
        let n = self.samples;
        let (mut t, mut s, mut q) = (
            Vec::with_capacity(n),
            Vec::with_capacity(n),
            Vec::with_capacity(n),
        );
        for k in 0..n {
            t.push(k as f64 * dt);
            s.push(adc(self.amplitude * psi.sin() + self.offset + noise()));
            q.push(adc(self.amplitude * psi.cos() + self.offset + noise()));
            for _ in 0..sub {
                let k1 = f(psi);
                let k2 = f(psi + 0.5 * h * k1);
                let k3 = f(psi + 0.5 * h * k2);
                let k4 = f(psi + h * k3);
                psi += h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
            }
        }
        Fringe { t, s, q }
    }
}
