//! Interferometer, modulator, photodetector and ADC of a closed-loop FOG
//! (docs/fog.md), one closure at a time.
//!
//! - Modulator: DAC code -> phase with the true V_pi (a gain error that can drift).
//! - Coil transit: half period j sees `phi(code_j) - phi(code_(j-1))` (tau delay).
//! - Detector: `P = (P0/2)(1 + cos(phi_s + dphi_m))`; at every modulation edge the
//!   phase difference sweeps through the bright fringe (a glitch) and the detector's
//!   first-order response decays from there with time constant `detector_tau_s`.
//! - Noise (switchable): shot noise `shot*sqrt(y)` and intensity noise `rin*y`.
//! - ADC: offset, `adc_bits` resolution left-aligned in 16 bits, clipped at the rails.

use num_traits::Float;
use rand_core::SeedableRng;
use rand_distr::{Distribution, StandardNormal};
use rand_xoshiro::Xoshiro256PlusPlus;

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OpticsParams<F> {
    /// Detector output at the bright fringe (P0), ADC LSB of the 16-bit scale.
    pub peak_lsb: F,
    pub adc_offset_lsb: F,
    /// ADC resolution; 12 for the STM32F405's ADC.
    pub adc_bits: u32,
    pub detector_tau_s: F,
    pub tau_s: F,
    pub samples_per_half: usize,
    /// DAC codes giving 2*pi at nominal V_pi.
    pub codes_per_turn: F,
    /// Relative error of the modulator gain (V_pi off nominal), at t = 0.
    pub vpi_gain_error: F,
    /// Drift of that error per second (temperature).
    pub vpi_drift_per_s: F,
    /// Optical power relative to nominal (0 = fiber break).
    pub power: F,
    pub noise: bool,
    /// Shot-noise coefficient: sigma = shot * sqrt(level in LSB).
    pub shot: F,
    /// Relative intensity noise per sample.
    pub rin: F,
    pub seed: u64,
}

impl<F: Float> OpticsParams<F> {
    /// STM32 12-bit ADC, 0.15 us detector, 58 000 LSB bright fringe, noise off.
    pub fn nominal(tau_s: F, samples_per_half: usize, codes_per_turn: u32) -> Self {
        let f = |x: f64| F::from(x).unwrap_or(F::zero());
        Self {
            peak_lsb: f(58_000.0),
            adc_offset_lsb: f(1_024.0),
            adc_bits: 12,
            detector_tau_s: f(0.15e-6),
            tau_s,
            samples_per_half,
            codes_per_turn: f(codes_per_turn as f64),
            vpi_gain_error: F::zero(),
            vpi_drift_per_s: F::zero(),
            power: F::one(),
            noise: false,
            shot: f(0.22),
            rin: f(1e-4),
            seed: 1,
        }
    }

    /// Detector level of one sample at the operating point (residual 0) above
    /// the dark level, LSB.
    pub fn operating_light(&self, phi0_rad: F) -> F {
        self.peak_lsb / (F::one() + F::one()) * (F::one() + phi0_rad.cos())
    }

    /// `params` with the front-end levels this detector has (nominal DC, dark level).
    pub fn matched(&self, params: gyro_sp::fog::FogParams) -> gyro_sp::fog::FogParams {
        gyro_sp::fog::FogParams {
            nominal_dc_lsb: self
                .operating_light(F::from(params.phi0_rad).unwrap_or(F::zero()))
                .to_f64()
                .unwrap_or(0.0),
            dark_lsb: self.adc_offset_lsb.to_f64().unwrap_or(0.0),
            adc_bits: self.adc_bits,
            ..params
        }
    }
}

pub struct FogOptics<F> {
    pub p: OpticsParams<F>,
    prev_code: u16,
    elapsed_s: F,
    decay: [F; gyro_sp::fog::MAX_SAMPLES_PER_HALF],
    rng: Xoshiro256PlusPlus,
}

impl<F: Float> FogOptics<F>
where
    StandardNormal: Distribution<F>,
{
    pub fn new(p: OpticsParams<F>) -> Self {
        let mut decay = [F::zero(); gyro_sp::fog::MAX_SAMPLES_PER_HALF];
        let n = F::from(p.samples_per_half).unwrap_or(F::one());
        for (i, d) in decay.iter_mut().enumerate() {
            let t = p.tau_s * F::from(i).unwrap_or(F::zero()) / n;
            *d = (-t / p.detector_tau_s).exp();
        }
        Self {
            p,
            prev_code: 0,
            elapsed_s: F::zero(),
            decay,
            rng: Xoshiro256PlusPlus::seed_from_u64(p.seed),
        }
    }

    /// Simulates one closure: DAC words `dac` (one per half period) applied
    /// while the Sagnac phase is `sagnac[j]` (rad) in half period j; writes the
    /// ADC samples into `adc` (`samples_per_half` per half period). Returns the
    /// ADC analog-watchdog flag: a conversion fell outside [AWD_LOW, AWD_HIGH].
    pub fn run_step(&mut self, dac: &[u16], sagnac: &[F], adc: &mut [u16]) -> bool {
        use gyro_sp::fog::demod::{AWD_HIGH, AWD_LOW};
        let mut watchdog = false;
        let p = self.p;
        let two = F::one() + F::one();
        let gain = F::one() + p.vpi_gain_error + p.vpi_drift_per_s * self.elapsed_s;
        let rad_per_code =
            F::from(core::f64::consts::TAU).unwrap_or(F::zero()) / p.codes_per_turn * gain;
        let a = p.peak_lsb * p.power / two;
        let glitch = p.peak_lsb * p.power;
        let lsb = F::from(1u32 << (16 - p.adc_bits.clamp(1, 16))).unwrap_or(F::one());
        let top = F::from(65_536.0).unwrap_or(F::one()) - lsb;
        let sph = p.samples_per_half;
        for ((&code, &phi_s), out) in dac.iter().zip(sagnac).zip(adc.chunks_exact_mut(sph)) {
            let dphi_m =
                F::from(code as i32 - self.prev_code as i32).unwrap_or(F::zero()) * rad_per_code;
            self.prev_code = code;
            let level = a * (F::one() + (phi_s + dphi_m).cos());
            for (s, &d) in out.iter_mut().zip(self.decay.iter()) {
                let mut y = level + (glitch - level) * d;
                if p.noise {
                    let n1: F = StandardNormal.sample(&mut self.rng);
                    y = y + n1 * (p.shot * y.max(F::zero()).sqrt() + p.rin * y);
                }
                let v = ((p.adc_offset_lsb + y) / lsb).round() * lsb;
                *s = v.max(F::zero()).min(top).to_u16().unwrap_or(0);
                watchdog |= !(AWD_LOW..AWD_HIGH).contains(s);
            }
        }
        self.elapsed_s = self.elapsed_s + p.tau_s * F::from(dac.len()).unwrap_or(F::zero());
        watchdog
    }
}
