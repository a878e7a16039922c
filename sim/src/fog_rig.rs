//! Test rig: the firmware's FOG core closed around the simulated optics, sample
//! by sample, on an input-rate profile. Used by the host tests, `gyro-lab` and
//! (in f32) by the `qemu` firmware.

use super::{FogOptics, OpticsParams, Profile};
use gyro_sp::fog::{ClosureOutput, FogConfig, FogLoop, MAX_HALF, MAX_SAMPLES_PER_HALF};
use num_traits::Float;
use rand_distr::{Distribution, StandardNormal};

pub struct FogRig<F> {
    pub cfg: FogConfig,
    pub fog: FogLoop,
    pub optics: FogOptics<F>,
    pub profile: Profile<F>,
    /// The coil's true scale-factor error (relative) and bias (rad/s) at
    /// its present temperature (`sim::fog_thermal`); 0 by default. The
    /// Sagnac phase is `K_s * ((1 + scale_error) * rate + bias)`.
    pub scale_error: F,
    pub bias_rad_s: F,
    k_sagnac: F,
    closure_index: u64,
    /// DAC buffers: [0] is applied this closure and receives the closure's new
    /// words. With one closure of DAC latency the two swap after each closure (the
    /// hw DMA ping-pong: words written now are applied the closure after next).
    dac: [[u16; MAX_HALF]; 2],
    adc: [u16; MAX_HALF * MAX_SAMPLES_PER_HALF],
    sagnac: [F; MAX_HALF],
    /// The ADC analog watchdog fired during the last simulated closure.
    adc_over_range: bool,
}

/// One closure of the rig: the core's output and the truth.
#[derive(Clone, Copy, Debug)]
pub struct RigClosure<F> {
    pub out: ClosureOutput,
    /// Mean true rate over the closure (of the per-half-period rates), rad/s.
    pub true_rate: F,
    /// Time at the end of the closure, s.
    pub t_end: F,
}

impl<F: Float> FogRig<F>
where
    StandardNormal: Distribution<F>,
{
    pub fn new(cfg: FogConfig, optics: OpticsParams<F>, profile: Profile<F>) -> Self {
        let mut fog = FogLoop::new(&cfg);
        let mut dac = [[0u16; MAX_HALF]; 2];
        fog.start(&cfg, &mut dac[0]);
        dac[1] = dac[0];
        Self {
            k_sagnac: F::from(cfg.k_sagnac_s).unwrap_or(F::one()),
            cfg,
            fog,
            optics: FogOptics::new(optics),
            profile,
            scale_error: F::zero(),
            bias_rad_s: F::zero(),
            closure_index: 0,
            dac,
            adc: [0; MAX_HALF * MAX_SAMPLES_PER_HALF],
            sagnac: [F::zero(); MAX_HALF],
            adc_over_range: false,
        }
    }

    /// The DAC words the next closure applies (one per half period).
    pub fn applied_dac(&self) -> &[u16] {
        &self.dac[0][..self.cfg.n_half]
    }

    pub fn closure_index(&self) -> u64 {
        self.closure_index
    }

    /// Runs one closure.
    pub fn run_closure(&mut self) -> RigClosure<F> {
        let true_rate = self.simulate_optics();
        let out = self.process_core();
        self.finish_step(out, true_rate)
    }

    /// First half of a closure: the optics produce the ADC samples of the DAC words
    /// now applied. Returns the mean true rate over the closure, rad/s.
    pub fn simulate_optics(&mut self) -> F {
        let n = self.cfg.n_half;
        let tau = F::from(self.cfg.params.tau_s).unwrap_or(F::zero());
        let half = F::from(0.5).unwrap_or(F::zero());
        let first = self.closure_index * n as u64;
        let gain = self.k_sagnac * (F::one() + self.scale_error);
        let offset = self.k_sagnac * self.bias_rad_s;
        let mut sum = F::zero();
        for (j, s) in self.sagnac.iter_mut().take(n).enumerate() {
            let t = (F::from(first + j as u64).unwrap_or(F::zero()) + half) * tau;
            let rate = self.profile.rate_at(t);
            sum = sum + rate;
            *s = gain * rate + offset;
        }
        let ns = self.cfg.n_samples;
        let (dac, adc, sagnac) = (&self.dac[0][..n], &mut self.adc[..ns], &self.sagnac[..n]);
        // The next closure's first word: known here only with the DAC latency's
        // ping-pong (the optics' chain may sample past the closure's last edge).
        let next = (self.cfg.params.dac_latency != 0).then_some(self.dac[1][0]);
        self.adc_over_range = self.optics.run_step_next(dac, next, sagnac, adc);
        sum / F::from(n).unwrap_or(F::one())
    }

    /// Second half: the firmware's closure on those samples (this is what
    /// the interrupt runs on the MCU).
    #[inline(never)]
    pub fn process_core(&mut self) -> ClosureOutput {
        let (n, ns) = (self.cfg.n_half, self.cfg.n_samples);
        self.fog.process(
            &self.cfg,
            &self.adc[..ns],
            self.adc_over_range,
            &mut self.dac[0][..n],
        )
    }

    /// A closure the firmware missed (its interrupt ran too late, so its
    /// samples were overwritten): the optics run on the words already
    /// applied, which the DMA sends again, and the core never sees them.
    pub fn skip_closure(&mut self) {
        let _ = self.simulate_optics();
        self.closure_index += 1;
        if self.cfg.params.dac_latency != 0 {
            self.dac.swap(0, 1);
        }
    }

    /// Completes a closure run as `simulate_optics` + `process_core`.
    pub fn finish_step(&mut self, out: ClosureOutput, true_rate: F) -> RigClosure<F> {
        self.closure_index += 1;
        // The slow side, as the board's frame path runs it (there once per
        // frame; the gear's acquisition time is 0.25 s, so the rig's every
        // closure behaves the same).
        self.fog.supervise(&self.cfg, 1);
        if self.cfg.params.dac_latency != 0 {
            self.dac.swap(0, 1);
        }
        let tau = F::from(self.cfg.params.tau_s).unwrap_or(F::zero());
        let t_end = F::from(self.closure_index * self.cfg.n_half as u64).unwrap_or(F::zero()) * tau;
        RigClosure {
            out,
            true_rate,
            t_end,
        }
    }
}
