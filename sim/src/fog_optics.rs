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
//!
//! That detector is the idealised front end every test had before the board's timing
//! (docs/timing.md): the samples start at the edge, so the glitch falls on the skipped
//! sample by construction. With `chain` set ([`Chain`]) the optics run the board's chain
//! in time instead: the DAC word's update, the drive's slew (the light sweeps from the old
//! phase difference to the new one: through the bright fringe at an ordinary edge, through
//! the dark fringe and more at a 2*pi reset), the crosstalk of that slew into the
//! detector, the fibre to the detector, the detector and anti-alias filter as two real
//! poles, and the ADC sampling at a set delay after the update (the sampling phase).
//! Without `chain` the samples are exactly those of the idealised detector.

use num_traits::Float;
use rand_core::SeedableRng;
use rand_distr::{Distribution, StandardNormal};
use rand_xoshiro::Xoshiro256PlusPlus;

use gyro_sp::fog::MAX_HALF;

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
    /// The board's chain in time, with the sampling phase; None: the idealised
    /// detector (samples at the edge and every tau/samples_per_half after it).
    pub chain: Option<Chain<F>>,
}

/// The modulator-to-ADC chain of the board in time (docs/timing.md). Times are
/// from a DAC word's update (the timer's update event that starts the half period).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Chain<F> {
    /// Update -> the first ADC sample of the half period (the hold instant), s:
    /// the sampling phase. The samples follow every tau/samples_per_half and are
    /// framed from the update, as the board's DMA buffer is: past tau the train
    /// starts in the next half period. At most tau + tau/samples_per_half +
    /// `dac_delay_s`, so that the closure's samples need no word after the next
    /// closure's first.
    pub sample_delay_s: F,
    /// Update -> the DAC's output starts moving (DMA, SPI word, DAC latch), s.
    pub dac_delay_s: F,
    /// The modulator drive's slew rate, DAC codes per second: a step of c codes
    /// takes c / slew, so a 2*pi reset's step takes longest.
    pub dac_slew_codes_per_s: F,
    /// Modulator -> detector (Y junction, coupler, pigtail), s. Both waves see a
    /// modulation edge at once: the coil's transit is the half period itself.
    pub fibre_delay_s: F,
    /// The anti-alias filter's time constant, s: a second real pole after the
    /// detector's `detector_tau_s`; 0 for none. It must differ from
    /// `detector_tau_s` (the cascade's response divides by their difference).
    pub filter_tau_s: F,
    /// Electrical crosstalk of the drive's slew into the detector's input, LSB,
    /// with the sign of the DAC step, for as long as the drive slews.
    pub crosstalk_lsb: F,
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
            chain: None,
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
    chain: ChainState<F>,
}

/// Longest sub-step through a sweep of the light, s: the input is held at its
/// midpoint value over a sub-step (the filters' update is exact for it).
const SWEEP_STEP_S: f64 = 10e-9;

/// The chain's running state (`OpticsParams::chain`).
#[derive(Clone, Copy, Debug)]
struct ChainState<F> {
    /// Detector and anti-alias filter outputs, LSB above the dark level.
    y1: F,
    y2: F,
    /// DAC codes of the last three half periods before this closure (oldest first).
    codes: [u16; 3],
    /// Sagnac phase of the last half period before this closure, rad.
    sagnac: F,
    /// Time of the filter state, s from this closure's first update (at the
    /// previous closure's last sample).
    t: F,
    /// The filters' decay over one whole sweep sub-step: (a1, a2, k) of [`Poles::step`].
    sub: (F, F, F),
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
        let mut chain = ChainState {
            y1: F::zero(),
            y2: F::zero(),
            codes: [0; 3],
            sagnac: F::zero(),
            t: F::zero(),
            sub: (F::zero(), F::zero(), F::zero()),
        };
        if let Some(c) = p.chain {
            let ts = p.tau_s / n;
            let full_scale = F::from(65_536.0).unwrap_or(F::one()) / c.dac_slew_codes_per_s;
            // A closure's window starts at the previous closure's last sample:
            // the sweep of the half period before this closure's first must be
            // over by then, so that half periods -1 ..= n describe the window.
            // It ends before the edge after the next closure's first word.
            assert!(
                c.sample_delay_s >= F::zero()
                    && c.sample_delay_s < p.tau_s + ts + c.dac_delay_s
                    && c.dac_delay_s + c.fibre_delay_s + full_scale + ts <= p.tau_s
                    && c.filter_tau_s != p.detector_tau_s,
                "chain timing outside the half period"
            );
            chain.t = c.sample_delay_s - ts;
            chain.sub = Poles::new(p.detector_tau_s, c.filter_tau_s).decay(sweep_step::<F>());
        }
        Self {
            p,
            prev_code: 0,
            elapsed_s: F::zero(),
            decay,
            rng: Xoshiro256PlusPlus::seed_from_u64(p.seed),
            chain,
        }
    }

    /// [`run_step_next`](Self::run_step_next) without the next closure's first
    /// word: the chain, where its last samples need that word, extrapolates it
    /// from the same-sign half period before (the hw ping-pong knows it).
    pub fn run_step(&mut self, dac: &[u16], sagnac: &[F], adc: &mut [u16]) -> bool {
        self.run_step_next(dac, None, sagnac, adc)
    }

    /// Simulates one closure: DAC words `dac` (one per half period) applied
    /// while the Sagnac phase is `sagnac[j]` (rad) in half period j; writes the
    /// ADC samples into `adc` (`samples_per_half` per half period). Returns the
    /// ADC analog-watchdog flag: a conversion fell outside [AWD_LOW, AWD_HIGH].
    /// `next`: the first DAC word of the next closure, if known (the chain's
    /// last samples may fall after its edge).
    pub fn run_step_next(
        &mut self,
        dac: &[u16],
        next: Option<u16>,
        sagnac: &[F],
        adc: &mut [u16],
    ) -> bool {
        use gyro_sp::fog::demod::{AWD_HIGH, AWD_LOW};
        if let Some(c) = self.p.chain {
            return self.run_chain(&c, dac, next, sagnac, adc);
        }
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

    /// One closure through the board's chain (`OpticsParams::chain`): the
    /// detector's input followed in time from the last sample of the previous
    /// closure to the last of this one, event by event (slew and crosstalk on and
    /// off, light sweep on and off, samples), exact for an input held constant
    /// between events and over the sweep's sub-steps.
    fn run_chain(
        &mut self,
        c: &Chain<F>,
        dac: &[u16],
        next: Option<u16>,
        sagnac: &[F],
        adc: &mut [u16],
    ) -> bool {
        use gyro_sp::fog::demod::{AWD_HIGH, AWD_LOW};
        let p = self.p;
        let n = dac.len().min(sagnac.len()).min(MAX_HALF);
        let sph = p.samples_per_half;
        if n == 0 || sph == 0 {
            return false;
        }
        let fl = |x: usize| F::from(x).unwrap_or(F::zero());
        let two = F::one() + F::one();
        let tau = p.tau_s;
        let ts = tau / fl(sph);
        let gain = F::one() + p.vpi_gain_error + p.vpi_drift_per_s * self.elapsed_s;
        let lsb = F::from(1u32 << (16 - p.adc_bits.clamp(1, 16))).unwrap_or(F::one());
        let top = F::from(65_536.0).unwrap_or(F::one()) - lsb;
        let drive = Drive {
            rad_per_code: F::from(core::f64::consts::TAU).unwrap_or(F::zero()) / p.codes_per_turn
                * gain,
            a: p.peak_lsb * p.power / two,
            codes: {
                // Half period j's code at j + 3, j = -3 ..= n: the three before
                // this closure, this closure's, the next one's first.
                let mut codes = [0i32; MAX_HALF + 4];
                let known = self.chain.codes.iter().chain(&dac[..n]);
                for (d, &w) in codes.iter_mut().zip(known) {
                    *d = w as i32;
                }
                // Unknown: the same-sign half period's step again.
                codes[n + 3] = next.map_or(codes[n + 2] + codes[n + 1] - codes[n], i32::from);
                codes
            },
            sagnac_before: self.chain.sagnac,
            sagnac,
            n,
            tau,
            light_delay_s: c.dac_delay_s + c.fibre_delay_s,
            slew: c.dac_slew_codes_per_s,
        };
        let poles = Poles::new(p.detector_tau_s, c.filter_tau_s);
        let h = sweep_step::<F>();
        let mut at = At::default();
        let mut events = Events::new(&drive, c.dac_delay_s);
        let mut t = self.chain.t;
        // The state at the window's start: the events before it.
        while let Some((te, e)) = events.peek() {
            if te > t {
                break;
            }
            at.apply(e);
            events.advance();
        }
        let (mut y1, mut y2) = (self.chain.y1, self.chain.y2);
        let mut watchdog = false;
        for (k, s) in adc.iter_mut().take(n * sph).enumerate() {
            let tk = c.sample_delay_s + fl(k) * ts;
            loop {
                // An event at a sample's instant comes after it.
                let stop = match events.peek() {
                    Some((te, _)) if te < tk => te,
                    _ => tk,
                };
                // Through a sweep in sub-steps, else in one step.
                while t < stop {
                    let whole = at.sweeping && stop - t > h;
                    let dt = if whole { h } else { stop - t };
                    let x = drive.light(&at, t + dt / two)
                        + if at.crosstalk {
                            c.crosstalk_lsb * drive.step_sign(at.crosstalk_j)
                        } else {
                            F::zero()
                        };
                    let d = if whole {
                        self.chain.sub
                    } else {
                        poles.decay(dt)
                    };
                    (y1, y2) = poles.step(d, x, y1, y2);
                    t = if whole { t + h } else { stop };
                }
                match events.peek() {
                    Some((te, e)) if te < tk => {
                        at.apply(e);
                        events.advance();
                    }
                    _ => break,
                }
            }
            let mut y = y2;
            if p.noise {
                let n1: F = StandardNormal.sample(&mut self.rng);
                y = y + n1 * (p.shot * y.max(F::zero()).sqrt() + p.rin * y);
            }
            let v = ((p.adc_offset_lsb + y) / lsb).round() * lsb;
            *s = v.max(F::zero()).min(top).to_u16().unwrap_or(0);
            watchdog |= !(AWD_LOW..AWD_HIGH).contains(s);
        }
        let st = &mut self.chain;
        (st.y1, st.y2) = (y1, y2);
        st.t = t - tau * fl(n);
        for (d, &w) in st.codes.iter_mut().zip(&drive.codes[n..n + 3]) {
            *d = w as u16;
        }
        st.sagnac = sagnac[n - 1];
        self.prev_code = dac[n - 1];
        self.elapsed_s = self.elapsed_s + tau * fl(n);
        watchdog
    }
}

fn sweep_step<F: Float>() -> F {
    F::from(SWEEP_STEP_S).unwrap_or(F::zero())
}

/// The detector (tau1) and the anti-alias filter (tau2, 0: none): two real
/// poles in cascade.
#[derive(Clone, Copy, Debug)]
struct Poles<F> {
    tau1: F,
    tau2: F,
}

impl<F: Float> Poles<F> {
    fn new(tau1: F, tau2: F) -> Self {
        Self { tau1, tau2 }
    }

    /// Over `dt`: each pole's decay and the second's response to the first's
    /// excess, `tau1/(tau1 - tau2) * (a1 - a2)`.
    fn decay(&self, dt: F) -> (F, F, F) {
        let a1 = (-dt / self.tau1).exp();
        if self.tau2 > F::zero() {
            let a2 = (-dt / self.tau2).exp();
            (a1, a2, self.tau1 / (self.tau1 - self.tau2) * (a1 - a2))
        } else {
            (a1, F::zero(), F::zero())
        }
    }

    /// Both outputs after an interval with the input held at `x` (exact).
    fn step(&self, (a1, a2, k): (F, F, F), x: F, y1: F, y2: F) -> (F, F) {
        let y1n = x + (y1 - x) * a1;
        if self.tau2 > F::zero() {
            (y1n, x + (y2 - x) * a2 + (y1 - x) * k)
        } else {
            (y1n, y1n)
        }
    }
}

/// What one closure's chain needs from the drive: the codes around it and
/// the light they give.
struct Drive<'a, F> {
    rad_per_code: F,
    /// Light at the operating point's half level, LSB: `P0/2`.
    a: F,
    codes: [i32; MAX_HALF + 4],
    sagnac_before: F,
    sagnac: &'a [F],
    n: usize,
    tau: F,
    /// Update -> the light starts to sweep at the detector.
    light_delay_s: F,
    slew: F,
}

impl<F: Float> Drive<'_, F> {
    /// Half period j's DAC step (codes), j = -2 ..= n.
    fn step(&self, j: i32) -> i32 {
        let i = (j + 3) as usize;
        self.codes[i] - self.codes[i - 1]
    }

    fn step_sign(&self, j: i32) -> F {
        F::from(self.step(j).signum()).unwrap_or(F::zero())
    }

    /// How long half period j's step slews, s.
    fn slew_s(&self, j: i32) -> F {
        F::from(self.step(j).unsigned_abs()).unwrap_or(F::zero()) / self.slew
    }

    fn sagnac_of(&self, j: i32) -> F {
        match usize::try_from(j) {
            Err(_) => self.sagnac_before,
            Ok(j) => self.sagnac[j.min(self.n - 1)],
        }
    }

    /// The light at the detector at time t (s from the closure's first update),
    /// LSB. Settled: half period j's phase difference is its DAC step (the wave
    /// through the coil saw the step before). Sweeping: the wave entering the
    /// coil now slews by step j while the one leaving it slews by step j - 1, both
    /// at the drive's slew rate from the edge.
    fn light(&self, at: &At, t: F) -> F {
        let j = at.light_j;
        let codes = if at.sweeping {
            let u = (t - self.time(j, self.light_delay_s)) * self.slew;
            let moved = |s: i32| {
                let s = F::from(s).unwrap_or(F::zero());
                u.min(s.abs()) * s.signum()
            };
            F::from(self.step(j - 1)).unwrap_or(F::zero()) + moved(self.step(j))
                - moved(self.step(j - 1))
        } else {
            F::from(self.step(j)).unwrap_or(F::zero())
        };
        self.a * (F::one() + (self.sagnac_of(j) + codes * self.rad_per_code).cos())
    }

    /// Half period j's update plus `delay`, s.
    fn time(&self, j: i32, delay: F) -> F {
        F::from(j).unwrap_or(F::zero()) * self.tau + delay
    }
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum Event {
    CrosstalkOn(i32),
    CrosstalkOff,
    SweepOn(i32),
    SweepOff,
}

/// The chain's state between events.
#[derive(Clone, Copy, Debug, Default)]
struct At {
    light_j: i32,
    sweeping: bool,
    crosstalk_j: i32,
    crosstalk: bool,
}

impl At {
    fn apply(&mut self, e: Event) {
        match e {
            Event::CrosstalkOn(j) => (self.crosstalk, self.crosstalk_j) = (true, j),
            Event::CrosstalkOff => self.crosstalk = false,
            Event::SweepOn(j) => (self.sweeping, self.light_j) = (true, j),
            Event::SweepOff => self.sweeping = false,
        }
    }
}

/// The edges' events in time order, half period -1 ..= n.
struct Events<'a, 'b, F> {
    drive: &'b Drive<'a, F>,
    dac_delay_s: F,
    j: i32,
    list: [(F, Event); 4],
    i: usize,
}

impl<'a, 'b, F: Float> Events<'a, 'b, F> {
    fn new(drive: &'b Drive<'a, F>, dac_delay_s: F) -> Self {
        let mut e = Self {
            drive,
            dac_delay_s,
            j: -1,
            list: [(F::zero(), Event::SweepOff); 4],
            i: 0,
        };
        e.fill();
        e
    }

    /// Half period j's four events, sorted (stable: a step of no codes turns
    /// its crosstalk on and off at once).
    fn fill(&mut self) {
        let (d, j) = (self.drive, self.j);
        let on = d.time(j, self.dac_delay_s);
        let light = d.time(j, d.light_delay_s);
        self.list = [
            (on, Event::CrosstalkOn(j)),
            (on + d.slew_s(j), Event::CrosstalkOff),
            (light, Event::SweepOn(j)),
            (light + d.slew_s(j).max(d.slew_s(j - 1)), Event::SweepOff),
        ];
        for i in 1..4 {
            let mut k = i;
            while k > 0 && self.list[k].0 < self.list[k - 1].0 {
                self.list.swap(k, k - 1);
                k -= 1;
            }
        }
    }

    fn peek(&self) -> Option<(F, Event)> {
        (self.j <= self.drive.n as i32).then(|| self.list[self.i])
    }

    fn advance(&mut self) {
        self.i += 1;
        if self.i == 4 {
            self.j += 1;
            self.i = 0;
            if self.j <= self.drive.n as i32 {
                self.fill();
            }
        }
    }
}
