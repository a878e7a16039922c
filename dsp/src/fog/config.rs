//! Immutable loop configuration: physical parameters in, fixed-point constants out.
//! Built once (host or MCU start-up, floating point allowed); the interrupt only
//! reads it.

use super::agc::AgcConfig;
use super::dither::DitherConfig;
use super::gain_loop::{GainLoopConfig, GainLoopGears};
use super::layout::{Kernel, MAX_HALF, MAX_SAMPLES_PER_HALF};
use super::lock::LockConfig;
use super::vibration::VibrationConfig;
use crate::phase::{phase_from_rad, Phase, PHASE_LSB_PER_RAD, RAD_PER_PHASE_LSB};
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
    /// Main-loop gain: fraction of the measured residual corrected per closure.
    pub loop_gain: f64,
    /// Closures between the closure writing DAC words and the ADC sampling
    /// them, beyond the next closure: 0 when the words written now are
    /// applied in the next closure (QEMU, host rigs), 1 for the hw board's
    /// DMA ping-pong (the interrupt writes the buffer half the DMA has just
    /// left, applied the closure after next). At most 1.
    pub dac_latency: u32,
    /// 2*pi gain-loop gain while it acquires: fraction of a measured gain
    /// error corrected per reset.
    pub gain_loop_gain: f64,
    /// Its gain once acquired (the gear shift, gain_loop.rs): V_pi then only
    /// drifts with temperature, and a fast loop's fluctuations follow a
    /// vibration's resets and rectify (docs/fog.md, "The 2*pi loop's gear").
    pub gain_loop_track_gain: f64,
    /// Time in lock (no fault) before the 2*pi loop shifts to the tracking
    /// gain, s.
    pub gain_loop_acquire_s: f64,
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
    /// Detector (front end) response time, s: at each modulation edge the
    /// phase difference sweeps through the bright fringe, and the kept
    /// samples still carry exp(-t/detector_tau_s) of that glitch. It adds a
    /// DC the AGC would read as light (0.2 % at 7pi/8 with one of four
    /// samples skipped); the error scale takes it out (docs/fog.md, "AGC and
    /// the DC moment"). 0: an ideal detector.
    pub detector_tau_s: f64,
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
            dac_latency: 0,
            gain_loop_gain: 0.05,
            gain_loop_track_gain: 0.0001,
            gain_loop_acquire_s: 0.25,
            dac_codes_per_turn: 49_152,
            dither_adc_codes: 60.0,
            adc_bits: 12,
            vibration_correction: true,
            nominal_dc_lsb: 8_000.0,
            dark_lsb: 1_024.0,
            detector_tau_s: 0.15e-6,
        }
    }
}

/// Why a parameter set was refused.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ConfigError {
    /// Closure period is not a whole multiple of 4 half periods (each half of a
    /// closure holds whole +-phi0 pairs), or too many.
    HalfPeriods,
    /// Samples per half period or skipped samples out of range, or more
    /// kept samples per closure than the 2*pi loop's 32-bit estimate holds
    /// (n_half^2 * kept < 8192: 16 half periods take up to 15 kept samples,
    /// 32 up to 7, 64 one).
    Samples,
    /// phi0 outside [0.1, pi - 0.1] rad.
    Phi0,
    /// Loop gain outside (0, 2) (the one-closure integrator is unstable beyond),
    /// a 2*pi loop gain outside [0, 1) or its acquisition time outside [0 s,
    /// 1 h), or DAC latency above one closure.
    LoopGain,
    /// DAC codes per turn leave no headroom for the 2*pi loop in 16 bits.
    DacRange,
    /// The epsilon-squared correction's coefficient |cot(phi0)|/n_half is 0.637
    /// or more (phi0 within 0.37 rad of 0 or pi at 4 half periods per closure,
    /// within 0.19 rad at 8): turn the correction off or use more half periods.
    VibrationCoeff,
    /// Non-finite or non-positive physical parameter, or a nominal detector
    /// level too dim for the error scaling's range.
    Physical,
}

/// Fixed-point constants derived from [`FogParams`]; read-only in the
/// interrupt. Each block derives its own ([`AgcConfig`], [`DitherConfig`],
/// [`GainLoopConfig`], [`VibrationConfig`], [`LockConfig`]); this checks the
/// parameters and composes them with the main loop's.
#[derive(Clone, Copy, Debug)]
pub struct FogConfig {
    /// The physical parameters this was built from.
    pub params: FogParams,
    /// Sagnac scale factor K_s = 2*pi*L*D/(lambda*c), rad per rad/s.
    pub k_sagnac_s: f64,
    /// Half periods per closure (16 at 12.5 kHz).
    pub n_half: usize,
    /// ADC samples per closure.
    pub n_samples: usize,
    /// Samples per half period and samples skipped after each edge.
    pub samples_per_half: usize,
    pub skip_samples: usize,
    /// Which compiled copy of the closure runs this layout.
    pub kernel: Kernel,
    /// phi0 as [`Phase`] LSB.
    pub phi0: Phase,
    /// Residual per normalised demodulator count: `cot(phi0/2) *
    /// 2^32/(2*pi*n_half)` (phase LSB per unit of sum(sign*h)/H0),
    /// dither-corrected (see `new`).
    pub residual_per_count: u32,
    /// Main-loop gain in Q16 (65 536 = unit gain).
    pub loop_gain_q16: i32,
    pub agc: AgcConfig,
    pub dither: DitherConfig,
    pub gain_loop: GainLoopConfig,
    pub vibration: VibrationConfig,
    pub lock: LockConfig,
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
            && p.dark_lsb.is_finite()
            && p.detector_tau_s.is_finite()
            && p.detector_tau_s >= 0.0)
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
            && p.gain_loop_track_gain >= 0.0
            && p.gain_loop_track_gain < 1.0
            && p.gain_loop_acquire_s >= 0.0
            && p.gain_loop_acquire_s < 3600.0
            && p.dac_latency <= 1)
        {
            return Err(ConfigError::LoopGain);
        }
        // The 2*pi loop may raise the gain by up to 25 %: keep that inside 16 bits.
        if p.dac_codes_per_turn < 1024 || p.dac_codes_per_turn as f64 * 1.25 > 65_535.0 {
            return Err(ConfigError::DacRange);
        }
        let k_sagnac_s = TAU * p.fiber_length_m * p.coil_diameter_m / (p.wavelength_m * C_LIGHT);
        let kept_per_half = p.samples_per_half - p.skip_samples;
        let agc = AgcConfig::new(
            p.nominal_dc_lsb,
            p.dark_lsb,
            kept_per_half,
            p.phi0_rad,
            n_half,
        );
        let dither =
            DitherConfig::new(p.dither_adc_codes, p.adc_bits, p.nominal_dc_lsb, p.phi0_rad);
        let vibration = VibrationConfig::new(
            p.vibration_correction,
            p.phi0_rad,
            n_half,
            dither.mean_square(),
        )
        .ok_or(ConfigError::VibrationCoeff)?;
        let gain_loop = GainLoopConfig::new(
            GainLoopGears {
                acquire: p.gain_loop_gain,
                track: p.gain_loop_track_gain,
                acquire_closures: (p.gain_loop_acquire_s * p.closure_hz).ceil() as u32,
            },
            p.dac_codes_per_turn,
            p.phi0_rad,
            n_half,
        );

        // Residual per normalised demodulator count. With depth phi0 + r (the
        // dither) the error slope is A*sin(phi0 + r), which the closure scales
        // by 1 - r*cot(phi0), and the DC A*(1 + cos(phi0 + r)). Over the
        // dither (triangular, [`DitherConfig::mean_cos`]) the mean slope is
        // A*sin(phi0)*G, G = <cos r> - cot^2(phi0)*<r sin r>, and the DC
        // A*(1 + c*<cos r>) (c = cos phi0), so the unit-gain scale is
        // cot(phi0/2)/n times (1 + c*<cos r>)/((1 + c)*G) (docs/fog.md,
        // "Depth dither"). The residual's own spread moves the DC the same
        // way; the AGC's DC moment removes that.
        let cot_half = 1.0 / (p.phi0_rad / 2.0).tan();
        let cot_phi0 = 1.0 / p.phi0_rad.tan();
        let c = p.phi0_rad.cos();
        let w = dither.half_width_rad();
        let sinc = dither.mean_cos();
        let slope_mean = sinc - cot_phi0 * cot_phi0 * dither.mean_r_sin();
        // The detector's settling: sample i of a half period (t = i*tau/spp)
        // reads level*(1 - e_i) + P0*e_i, e_i = exp(-t/detector_tau), P0 =
        // 2A the bright fringe the edge swept through. The kept sum is then
        // A*(1 + c)*(kept - e) + 2A*e (e the kept samples' sum of e_i), the
        // slope A*sin(phi0)*(kept - e): the normalised error is short by
        // 1 + 2e/((1 + c)(kept - e)), which the scale restores. Left in, it
        // is a loop gain error the AGC's DC moment amplifies under
        // vibration (by 1/(1 - excess share), docs/fog.md).
        let settle: f64 = if p.detector_tau_s > 0.0 {
            (p.skip_samples..p.samples_per_half)
                .map(|i| {
                    (-(i as f64) * p.tau_s / p.samples_per_half as f64 / p.detector_tau_s).exp()
                })
                .sum()
        } else {
            0.0
        };
        let kept = kept_per_half as f64;
        let settle_gain = 1.0 + 2.0 * settle / ((1.0 + c * sinc) * (kept - settle));
        let per_count = cot_half * PHASE_LSB_PER_RAD / n_half as f64 * (1.0 + c * sinc)
            / ((1.0 + c) * slope_mean)
            * settle_gain;
        // The closure scales the error by per_count * (2^32/H) / 2^16 with H
        // >= h0_min; below 2^31 its products with the closure's sums (below
        // 2^27) are single 32x32 multiplies. That needs the operating point's
        // DC above about 700 LSB per sample at 3pi/4 (45 codes of a 12-bit
        // ADC); a dimmer nominal level is refused. The dither's factor
        // reaches 1 + |cot(phi0)|*w (at most 9/8).
        let dither_max = 1.0 + cot_phi0.abs() * w;
        if per_count >= u32::MAX as f64
            || per_count * 65_536.0 / agc.h0_min as f64 * dither_max >= i32::MAX as f64
        {
            return Err(ConfigError::Physical);
        }
        Ok(Self {
            params: p,
            k_sagnac_s,
            n_half,
            n_samples: n_half * p.samples_per_half,
            samples_per_half: p.samples_per_half,
            skip_samples: p.skip_samples,
            kernel: Kernel::for_layout(n_half, p.samples_per_half, p.skip_samples, p.dac_latency),
            phi0: phase_from_rad(p.phi0_rad),
            residual_per_count: per_count.round() as u32,
            loop_gain_q16: (p.loop_gain * 65_536.0).round() as i32,
            agc,
            dither,
            gain_loop,
            vibration,
            lock: LockConfig::new(p.closure_hz),
        })
    }

    /// Closure period dt_p, s.
    pub fn closure_period_s(&self) -> f64 {
        self.n_half as f64 * self.params.tau_s
    }

    /// Rate (rad/s) of one phase LSB of the feedback phase.
    pub fn rad_s_per_phase_lsb(&self) -> f64 {
        RAD_PER_PHASE_LSB / self.k_sagnac_s
    }

    /// Angle (rad) of one unit of the angle-increment word (one closure LSB held
    /// for one half period).
    pub fn rad_per_angle_lsb(&self) -> f64 {
        self.rad_s_per_phase_lsb() * self.params.tau_s
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
        let lag_closures = 1.0 / p.loop_gain + p.dac_latency as f64;
        -(1.0 / p.phi0_rad.tan()) / 2.0
            * self.k_sagnac_s
            * p.tau_s
            * self.closure_period_s()
            * lag_closures
            * mean_eps_sq
    }
}
