//! Immutable loop configuration: physical parameters in, fixed-point constants out.
//! Built once (host or MCU start-up, floating point allowed); the interrupt only
//! reads it.

use super::{MAX_HALF, MAX_SAMPLES_PER_HALF};
use crate::{phase_from_rad, Phase};
use core::f64::consts::{PI, TAU};
#[allow(unused_imports)] // f64 maths comes from libm where core lacks it
use num_traits::float::Float;

/// Speed of light in vacuum, m/s.
pub const C_LIGHT: f64 = 299_792_458.0;

/// Physical and design parameters of one FOG channel (SI units).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FogParams {
    /// Fiber length L, m.
    pub fiber_length_m: f64,
    /// Coil diameter D, m.
    pub coil_diameter_m: f64,
    /// Source mean wavelength, m.
    pub wavelength_m: f64,
    /// Half period tau (coil transit time; modulation at the proper frequency), s.
    pub tau_s: f64,
    /// Bias modulation depth phi0, rad (the phase difference alternates +-phi0).
    pub phi0_rad: f64,
    /// Closure rate, Hz. Must give a whole, even number of half periods.
    pub closure_hz: f64,
    /// ADC samples per half period.
    pub samples_per_half: usize,
    /// Samples skipped after each modulation edge (detector transient).
    pub skip_samples: usize,
    /// Main-loop gain: fraction of the measured residual corrected per step.
    pub loop_gain: f64,
    /// Steps between the closure writing DAC words and the ADC sampling them,
    /// beyond the next step: 0 when the words written now are applied next
    /// step (QEMU, host rigs), 1 for the hw board's DMA ping-pong (the
    /// interrupt writes the buffer half the DMA has just left, applied the
    /// step after next). At most 1.
    pub dac_latency_steps: u32,
    /// 2*pi gain-loop gain: fraction of a measured gain error corrected per reset.
    pub gain_loop_gain: f64,
    /// DAC codes that give 2*pi at the modulator at nominal V_pi.
    pub dac_codes_per_turn: u32,
    /// Depth dither, half width in ADC codes of the half-period level at the
    /// operating point (0 = off). 60 codes of a 12-bit ADC (+-0.05 rad) average
    /// its rounding to about 0.5 ppm of scale factor at 50 deg/s; the width in
    /// phase follows the ADC, so a finer ADC gets a smaller dither and the
    /// epsilon-squared coefficient (it depends on the depth) moves less.
    pub dither_adc_codes: f64,
    /// ADC resolution, bits (left-aligned in 16).
    pub adc_bits: u32,
    /// Online epsilon-squared correction on.
    pub vibration_correction: bool,
    /// Expected DC level of one kept ADC sample at the operating point, above
    /// the dark level, LSB (sets the optical-power-low threshold and the
    /// start-up normalisation).
    pub nominal_dc_lsb: f64,
    /// ADC reading with no light (detector dark output plus ADC offset), LSB per
    /// sample; the front end sits above zero so a dark fringe is not clipped.
    pub dark_lsb: f64,
}

impl Default for FogParams {
    /// The reference instrument of docs/fog.md: L = 1000 m, D = 0.1 m,
    /// 1.55 um, tau = 5 us, phi0 = 3*pi/4, closure 12.5 kHz.
    fn default() -> Self {
        Self {
            fiber_length_m: 1000.0,
            coil_diameter_m: 0.1,
            wavelength_m: 1.55e-6,
            tau_s: 5e-6,
            phi0_rad: 0.75 * PI,
            closure_hz: 12_500.0,
            samples_per_half: 4,
            skip_samples: 1,
            loop_gain: 1.0,
            dac_latency_steps: 0,
            gain_loop_gain: 0.05,
            dac_codes_per_turn: 49_152,
            dither_adc_codes: 60.0,
            adc_bits: 12,
            vibration_correction: true,
            nominal_dc_lsb: 8_000.0,
            dark_lsb: 1_024.0,
        }
    }
}

/// Why a parameter set was refused.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ConfigError {
    /// Closure period is not a whole multiple of 4 half periods (each half of a
    /// step holds whole +-phi0 pairs), or too many.
    HalfPeriods,
    /// Samples per half period or skipped samples out of range, or more
    /// kept samples per step than the 2*pi loop's 32-bit estimate holds
    /// (n_half^2 * kept < 8192: 16 half periods take up to 15 kept samples,
    /// 32 up to 7, 64 one).
    Samples,
    /// phi0 outside [0.1, pi - 0.1] rad.
    Phi0,
    /// Loop gain outside (0, 2) (the one-step integrator is unstable beyond),
    /// or DAC latency above one step.
    LoopGain,
    /// DAC codes per turn leave no headroom for the 2*pi loop in 16 bits.
    DacRange,
    /// The epsilon-squared correction's coefficient |cot(phi0)|/n_half is 0.637
    /// or more (phi0 within 0.37 rad of 0 or pi at 4 half periods per step,
    /// within 0.19 rad at 8): turn the correction off or use more half periods.
    VibrationCoeff,
    /// Non-finite or non-positive physical parameter, or a nominal detector
    /// level too dim for the error scaling's range.
    Physical,
}

/// The compiled copies of the closure step: the reference instruments'
/// layouts (16 or 32 half periods of 4 samples, 1 skipped, no DAC latency)
/// with the sizes as constants (divisions become shifts, loops unroll), and
/// any layout with runtime sizes, without or with one step of DAC latency.
/// Chosen once here so the interrupt dispatches on one load.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Kernel {
    Half16,
    Half32,
    Any,
    AnyLatency1,
}

/// Fixed-point constants derived from [`FogParams`]; read-only in the interrupt.
#[derive(Clone, Copy, Debug)]
pub struct FogConfig {
    /// The physical parameters this was built from.
    pub params: FogParams,
    /// Sagnac scale factor K_s = 2*pi*L*D/(lambda*c), rad per rad/s.
    pub k_sagnac_s: f64,
    /// Half periods per closure step (16 at 12.5 kHz).
    pub n_half: usize,
    /// ADC samples per closure step.
    pub n_samples: usize,
    /// Samples per half period and samples skipped after each edge.
    pub samples_per_half: usize,
    pub skip_samples: usize,
    /// Which compiled copy of the closure step runs this layout.
    pub kernel: Kernel,
    /// phi0 as [`Phase`] LSB.
    pub phi0: Phase,
    /// Residual per normalised demodulator count: `cot(phi0/2) * 2^32/(2*pi*n_half)`
    /// (phase LSB per unit of sum(sign*h)/H0; dither-corrected, see `new`).
    pub k_meas: u32,
    /// Main-loop gain in Q16 (65 536 = unit gain).
    pub loop_gain_q16: i32,
    /// 2*pi-loop gain: DAC Q8 codes-per-turn per unit normalised reset error
    /// (sum c_j*h_j / H), divided by n_half (the estimate comes n times
    /// larger), Q4; below 2^27 (the reference loop: about 41 500; the largest
    /// valid configuration about 4.3e7).
    pub gain_loop: i32,
    /// Nominal DAC codes per turn, Q8.
    pub cpt_nominal_q8: u32,
    /// Clamp of the digital gain (codes per turn, Q8).
    pub cpt_min_q8: u32,
    pub cpt_max_q8: u32,
    /// Epsilon-squared correction: -(cot(phi0)/n_half) * 512*pi in Q21, the
    /// factor from the in-step slope (2^-3 phase LSB) to -(cot(phi0)/n_half) *
    /// slope in rad, Q32, by one `smmul` (see vibration.rs). Below 2^31 in
    /// magnitude.
    pub vib_coeff: i32,
    /// DC moment correction: weight of the in-step spread, 2^8 * 2(n^2-1)/(3n^2).
    pub dc_spread_q8: i32,
    /// DC excess (ADC LSB of one half period's kept sum) per unit of the
    /// moment m (ADC LSB x phase LSB), Q60: -(cot(phi0)/(2n)) * 2*pi/2^32.
    pub dc_moment_q60: i32,
    pub vibration_correction: bool,
    /// Depth dither width, bits (0 = off, at most 28).
    pub dither_bits: u32,
    /// Per-step gain factor of the dither: a step of depth phi0 + r has the
    /// error slope sin(phi0 + r), so its error is scaled by 1 - r*cot(phi0).
    /// With the dither drawn as r = x >> (32 - dither_bits) (x an i32),
    /// (f - 1) * 2^32 = (x * dither_gain) >> 32: dither_gain =
    /// -cot(phi0) * 2*pi * 2^dither_bits, below 2^30 in magnitude because the
    /// width is bounded by |r*cot(phi0)| <= 1/8.
    pub dither_gain: i32,
    /// Kept-sample sum of one half period at the nominal operating point, LSB.
    pub h0_nominal: u32,
    /// Dark level of one half period's kept-sample sum, LSB.
    pub dark_half: u32,
    /// Below this DC (per-half sum above dark) the optical power is flagged low.
    pub h0_min: u32,
    /// Residual beyond which a step counts toward loss of lock, phase LSB.
    pub lock_limit: u32,
    /// Residual beyond which the 2*pi loop holds (0.1 rad), phase LSB.
    pub gain_hold_limit: u32,
    /// Consecutive steps beyond `lock_limit` that declare loss of lock.
    pub lock_steps: u16,
}

impl FogConfig {
    pub fn new(p: FogParams) -> Result<Self, ConfigError> {
        let finite_pos = |x: f64| x.is_finite() && x > 0.0;
        if !(finite_pos(p.fiber_length_m)
            && finite_pos(p.coil_diameter_m)
            && finite_pos(p.wavelength_m)
            && finite_pos(p.tau_s)
            && finite_pos(p.closure_hz)
            && finite_pos(p.nominal_dc_lsb)
            && p.dark_lsb.is_finite())
        {
            return Err(ConfigError::Physical);
        }
        let halves = 1.0 / (p.closure_hz * p.tau_s);
        let n_half = halves.round() as usize;
        if (halves - n_half as f64).abs() > 1e-6
            || n_half < 2
            || !n_half.is_multiple_of(4)
            || n_half > MAX_HALF
        {
            return Err(ConfigError::HalfPeriods);
        }
        if p.samples_per_half == 0
            || p.samples_per_half > MAX_SAMPLES_PER_HALF
            || p.skip_samples >= p.samples_per_half
            || n_half * n_half * (p.samples_per_half - p.skip_samples) >= 8192
        {
            return Err(ConfigError::Samples);
        }
        // Near 0 or pi the error slope vanishes and cot(phi0) explodes.
        if !(p.phi0_rad >= 0.1 && p.phi0_rad <= PI - 0.1) {
            return Err(ConfigError::Phi0);
        }
        if !(p.loop_gain > 0.0
            && p.loop_gain < 2.0
            && p.gain_loop_gain >= 0.0
            && p.gain_loop_gain < 1.0
            && p.dac_latency_steps <= 1)
        {
            return Err(ConfigError::LoopGain);
        }
        // The 2*pi loop may raise the gain by up to 25 %: keep that inside 16 bits.
        if p.dac_codes_per_turn < 1024 || p.dac_codes_per_turn as f64 * 1.25 > 65_535.0 {
            return Err(ConfigError::DacRange);
        }
        let k_sagnac_s = TAU * p.fiber_length_m * p.coil_diameter_m / (p.wavelength_m * C_LIGHT);
        let cot_half = 1.0 / (p.phi0_rad / 2.0).tan();
        let lsb_per_rad = 4_294_967_296.0 / TAU;
        let kept = (p.samples_per_half - p.skip_samples) as f64;
        let cot_phi0 = 1.0 / p.phi0_rad.tan();
        let h0_nominal = p.nominal_dc_lsb * kept;

        // Epsilon-squared correction (vibration.rs): u = -(cot(phi0)/n) * d
        // [rad, Q32] from the slope d in units of 2^-3 LSB is
        // smmul(slope, coeff) with coeff = -(cot(phi0)/n) * 512*pi * 2^21
        // (the reference instruments: 5.3e7 and 6.4e7).
        let coeff_real = -(cot_phi0 / n_half as f64)
            * 512.0
            * PI
            * (1u64 << super::vibration::COEFF_FRAC) as f64;
        if p.vibration_correction && coeff_real.abs() >= 2_147_483_647.0 {
            return Err(ConfigError::VibrationCoeff);
        }
        let vib_coeff = coeff_real.round().clamp(i32::MIN as f64, i32::MAX as f64) as i32;

        // Dither: +-codes * (ADC LSB) of level, at A*sin(phi0) level per rad.
        let amplitude = p.nominal_dc_lsb / (1.0 + p.phi0_rad.cos());
        let code_lsb = (1u32 << (16 - p.adc_bits.clamp(1, 16))) as f64;
        let half_width_rad =
            p.dither_adc_codes.max(0.0) * code_lsb / (amplitude * p.phi0_rad.sin());
        let mut dither_bits = if p.dither_adc_codes > 0.0 {
            ((2.0 * half_width_rad * lsb_per_rad).log2().round() as u32).clamp(1, 28)
        } else {
            0
        };
        // The closure undoes each step's slope change to first order, 1 -
        // r*cot(phi0); a dither wider than |r*cot(phi0)| = 1/8 is narrowed.
        while dither_bits > 1
            && (1u64 << (dither_bits - 1)) as f64 / lsb_per_rad * cot_phi0.abs() > 0.125
        {
            dither_bits -= 1;
        }
        let dither_gain = if dither_bits > 0 {
            (-cot_phi0 * TAU * (1u64 << dither_bits) as f64).round() as i32
        } else {
            0
        };

        // Residual per normalised demodulator count. With depth phi0 + r (the
        // dither) the error slope is A*sin(phi0 + r), which the closure scales
        // by 1 - r*cot(phi0), and the DC A*(1 + cos(phi0 + r)). Over a uniform
        // dither of half width w the mean slope is A*sin(phi0)*G, G = <cos r> -
        // cot^2(phi0)*<r sin r> = sin(w)/w - cot^2(phi0)*(sin w - w cos w)/w,
        // and the DC A*(1 + c*sin(w)/w) (c = cos phi0), so the unit-gain scale
        // is cot(phi0/2)/n times (1 + c*sin(w)/w)/((1 + c)*G): +0.25 % at
        // 7pi/8 with the 12-bit ADC's dither (w = 0.025 rad). (The residual's own spread moves the
        // DC the same way; the closure measures that per step.)
        let c = p.phi0_rad.cos();
        let w = if dither_bits > 0 {
            (1u64 << (dither_bits - 1)) as f64 / lsb_per_rad
        } else {
            0.0
        };
        let (sinc, r_sin) = if w > 0.0 {
            (w.sin() / w, (w.sin() - w * w.cos()) / w)
        } else {
            (1.0, 0.0)
        };
        let slope_mean = sinc - cot_phi0 * cot_phi0 * r_sin;
        let k_meas =
            cot_half * lsb_per_rad / n_half as f64 * (1.0 + c * sinc) / ((1.0 + c) * slope_mean);

        // DC moment correction (closure.rs): a residual spread within the
        // period raises the DC by -A*cos(phi0)*<delta^2>/2, which would lower
        // the loop gain; the closure removes dc_moment * RAD * m, m =
        // spread_q8*diff*slope - sum*residual >= 0 (docs/fog.md, "AGC and the
        // DC moment").
        let nf = n_half as f64;
        let dc_spread_q8 = (256.0 * 2.0 * (nf * nf - 1.0) / (3.0 * nf * nf)).round() as i32;
        let dc_moment = -(1.0 / p.phi0_rad.tan()) / (2.0 * nf) * crate::RAD_PER_PHASE_LSB;
        // Q60: below 2^31 for every valid depth (|cot| <= 10, n >= 4).
        let dc_moment_q60 = (dc_moment * (1u64 << 60) as f64)
            .round()
            .clamp(i32::MIN as f64, i32::MAX as f64) as i32;

        // The closure scales the error by kn = k_meas * (2^32/H) / 2^16 with
        // H >= h0_min; kn < 2^31 makes its products with the step's sums
        // (below 2^27) single 32x32 multiplies. That needs the operating
        // point's DC above about 700 LSB per sample at 3pi/4 (45 codes of a
        // 12-bit ADC); a dimmer nominal level is refused.
        let h0_min = (h0_nominal * 0.25).round().max(2.0);
        // The dither's per-step factor reaches 1 + |cot(phi0)|*w (at most 9/8).
        let dither_max = 1.0 + cot_phi0.abs() * w;
        if k_meas >= u32::MAX as f64 || k_meas * 65_536.0 / h0_min * dither_max >= i32::MAX as f64 {
            return Err(ConfigError::Physical);
        }

        let gain_loop = p.gain_loop_gain * p.dac_codes_per_turn as f64 * 256.0 * cot_half / TAU
            * 16.0
            / n_half as f64;
        Ok(Self {
            params: p,
            k_sagnac_s,
            n_half,
            n_samples: n_half * p.samples_per_half,
            samples_per_half: p.samples_per_half,
            skip_samples: p.skip_samples,
            kernel: match (
                n_half,
                p.samples_per_half,
                p.skip_samples,
                p.dac_latency_steps,
            ) {
                (16, 4, 1, 0) => Kernel::Half16,
                (32, 4, 1, 0) => Kernel::Half32,
                (_, _, _, 0) => Kernel::Any,
                _ => Kernel::AnyLatency1,
            },
            phi0: phase_from_rad(p.phi0_rad),
            k_meas: k_meas.round() as u32,
            loop_gain_q16: (p.loop_gain * 65_536.0).round() as i32,
            gain_loop: gain_loop.round().clamp(0.0, ((1 << 27) - 1) as f64) as i32,
            cpt_nominal_q8: p.dac_codes_per_turn << 8,
            cpt_min_q8: ((p.dac_codes_per_turn as f64 * 0.8) * 256.0) as u32,
            cpt_max_q8: ((p.dac_codes_per_turn as f64 * 1.25) * 256.0) as u32,
            vib_coeff,
            dc_spread_q8,
            dc_moment_q60,
            vibration_correction: p.vibration_correction,
            dither_bits,
            dither_gain,
            h0_nominal: h0_nominal.round() as u32,
            h0_min: h0_min as u32,
            dark_half: (p.dark_lsb.max(0.0) * kept).round() as u32,
            lock_limit: phase_from_rad(0.5 * PI),
            gain_hold_limit: phase_from_rad(0.1),
            lock_steps: 8,
        })
    }

    /// Closure period dt_p, s.
    pub fn closure_period_s(&self) -> f64 {
        self.n_half as f64 * self.params.tau_s
    }

    /// Rate (rad/s) of one phase LSB of the feedback step.
    pub fn rad_s_per_step_lsb(&self) -> f64 {
        crate::RAD_PER_PHASE_LSB / self.k_sagnac_s
    }

    /// Angle (rad) of one unit of the angle-increment word (one step LSB held
    /// for one half period).
    pub fn rad_per_angle_lsb(&self) -> f64 {
        self.rad_s_per_step_lsb() * self.params.tau_s
    }

    /// Predicted epsilon-squared drift of this loop, rad/s, for mean eps^2 (rad/s^2)^2
    /// in the quasi-static limit (vibration well below the loop bandwidth):
    /// `-(cot(phi0)/2) * K_s * tau * dt_p * (1/g + L) * <eps^2>`; for unit gain
    /// and no latency this is the textbook `-(1/4) cot(phi0) K_s eps^2 dt_m dt_p`.
    /// The mean residual under a rate ramp a is a*dt_p*(1/g + L): the loop
    /// `s(k+1+L) = s(k+L) + g*(m(k) - s(k+L))` (closure.rs) settles with
    /// `s(k) = a*(k - 1/g - L)`, and the drift is proportional to it.
    pub fn predicted_vibration_drift(&self, mean_eps_sq: f64) -> f64 {
        let p = &self.params;
        let lag_steps = 1.0 / p.loop_gain + p.dac_latency_steps as f64;
        -(1.0 / p.phi0_rad.tan()) / 2.0
            * self.k_sagnac_s
            * p.tau_s
            * self.closure_period_s()
            * lag_steps
            * mean_eps_sq
    }
}
