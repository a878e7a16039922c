//! Depth dither: the modulation depth of each closure is phi0 + r, r a
//! few ADC codes of level, so the ADC's rounding averages out of the scale
//! factor instead of beating with the rate (docs/fog.md, "Depth dither").
//! A closure of depth phi0 + r has the error slope sin(phi0 + r); the
//! closure undoes that to first order with the gain factor 1 - r*cot(phi0).
//!
//! r is triangular (the sum of two uniform halves of one random word): a
//! uniform dither spans a whole number of ADC codes only by chance, and the
//! leftover fraction of a code (up to 1/(2W) of the rounding error for W
//! codes) then becomes a rounding bias that a vibration commensurate with
//! the closure rate does not average out (+5 % of the eps^2 drift at 3pi/4,
//! 200 Hz, 1 000 deg/s^2 with 240 codes). A triangular density's leftover
//! falls as 1/W^2.

use crate::phase::{Phase, PHASE_LSB_PER_RAD as LSB_PER_RAD};
#[allow(unused_imports)] // f64 maths comes from libm where core lacks it
use num_traits::float::Float;

/// The dither's width and the gain correction that goes with it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DitherConfig {
    /// Width, bits: r spans [-2^(bits-1), 2^(bits-1)) phase LSB (0 = off,
    /// at most 28).
    pub bits: u32,
    /// With r = y >> (32 - bits) (y the spread triangular word), the gain factor less one
    /// is (y * gain) >> 32 in Q32: gain = -cot(phi0) * 2*pi * 2^bits, below
    /// 2^30 in magnitude because |r*cot(phi0)| <= 1/8.
    pub gain: i32,
}

impl DitherConfig {
    /// `adc_codes` of half-period level at the operating point (codes of an
    /// `adc_bits` ADC, left-aligned in 16 bits), at the level's slope
    /// A*sin(phi0) per rad (A from the nominal DC per sample above dark,
    /// `nominal_dc_lsb`), rounded to a power of two and narrowed until
    /// |r*cot(phi0)| <= 1/8.
    pub fn new(adc_codes: f64, adc_bits: u32, nominal_dc_lsb: f64, phi0_rad: f64) -> Self {
        if adc_codes <= 0.0 || adc_codes.is_nan() {
            return Self { bits: 0, gain: 0 };
        }
        let cot_phi0 = 1.0 / phi0_rad.tan();
        let amplitude = nominal_dc_lsb / (1.0 + phi0_rad.cos());
        let code_lsb = (1u32 << (16 - adc_bits.clamp(1, 16))) as f64;
        let half_width_rad = adc_codes * code_lsb / (amplitude * phi0_rad.sin());
        let mut bits = ((2.0 * half_width_rad * LSB_PER_RAD).log2().round() as u32).clamp(1, 28);
        while bits > 1 && (1u64 << (bits - 1)) as f64 / LSB_PER_RAD * cot_phi0.abs() > 0.125 {
            bits -= 1;
        }
        Self {
            bits,
            gain: (-cot_phi0 * core::f64::consts::TAU * (1u64 << bits) as f64).round() as i32,
        }
    }

    /// Half width w of the dither, rad (0 when off).
    pub fn half_width_rad(&self) -> f64 {
        if self.bits == 0 {
            0.0
        } else {
            (1u64 << (self.bits - 1)) as f64 / LSB_PER_RAD
        }
    }

    /// Moments of the triangular r over [-w, w] (the sum of two uniforms
    /// of half width b = w/2): <cos r> = (sin(b)/b)^2, <r sin r> = 2
    /// sin(b)/b * (sin(b)/b - cos b), <r^2> = w^2/6.
    pub fn mean_cos(&self) -> f64 {
        let b = self.half_width_rad() / 2.0;
        let s = sinc(b);
        s * s
    }

    pub fn mean_r_sin(&self) -> f64 {
        let b = self.half_width_rad() / 2.0;
        let s = sinc(b);
        2.0 * s * (s - b.cos())
    }

    pub fn mean_square(&self) -> f64 {
        let w = self.half_width_rad();
        w * w / 6.0
    }
}

/// sin(x)/x (1 at 0).
fn sinc(x: f64) -> f64 {
    if x == 0.0 {
        1.0
    } else {
        x.sin() / x
    }
}

/// The dither's sequence: xorshift32 (a golden-ratio sequence was tried and
/// its lines beat with the reset pattern at some rates).
#[derive(Clone, Copy, Debug)]
pub struct Dither {
    state: u32,
}

impl Default for Dither {
    fn default() -> Self {
        Self { state: 0x9E37_79B9 }
    }
}

/// One closure's depth offset and the gain factor that undoes its slope change.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct DepthStep {
    /// Depth offset r, phase LSB (wrapping: negative offsets are high values).
    pub offset: Phase,
    /// 1 - r*cot(phi0) less one, Q32.
    pub gain_m1_q32: i32,
}

impl Dither {
    /// The next closure's depth offset r and its gain factor less one
    /// (the dropped low bits of r are under 2^-bits of it).
    #[inline(always)]
    pub fn update(&mut self, cfg: &DitherConfig) -> DepthStep {
        let mut x = self.state;
        x ^= x << 13;
        x ^= x >> 17;
        x ^= x << 5;
        self.state = x;
        // The two signed halves of x summed (one `sxtah`): triangular over
        // [-2^16, 2^16 - 2], spread over the i32 range by << 15.
        let wide = (((x as i32) >> 16) + (x as i16 as i32)) << 15;
        // bits = 0: off.
        let r = wide.checked_shr(32 - cfg.bits).unwrap_or(0);
        let gain_m1_q32 = ((wide as i64 * cfg.gain as i64) >> 32) as i32;
        DepthStep {
            offset: r as Phase,
            gain_m1_q32,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The offsets stay inside the width, are centred with the triangular
    /// variance w^2/6, and the gain factor matches 1 - r*cot(phi0) to the
    /// dropped bits.
    #[test]
    fn offsets_and_gain_follow_the_width() {
        let phi0 = 0.75 * core::f64::consts::PI;
        let cfg = DitherConfig::new(60.0, 12, 8_000.0, phi0);
        assert!(cfg.bits > 0 && cfg.bits <= 28);
        let cot = 1.0 / phi0.tan();
        assert!(cfg.half_width_rad() * cot.abs() <= 0.125);
        let mut d = Dither::default();
        let half = 1i64 << (cfg.bits - 1);
        let (mut sum, mut sq, n) = (0f64, 0f64, 100_000);
        for _ in 0..n {
            let DepthStep {
                offset: r,
                gain_m1_q32: g,
            } = d.update(&cfg);
            let r = r as i32 as i64;
            assert!((-half..half).contains(&r));
            sum += r as f64;
            sq += (r as f64).powi(2);
            let expect = -(r as f64) / LSB_PER_RAD * cot * 4_294_967_296.0;
            // x's dropped low bits (< 2^(32 - bits)) are worth under
            // 2*pi*|cot(phi0)| of the Q32 factor, the gain's rounding a
            // quarter, the shift's floor one.
            let tol = core::f64::consts::TAU * cot.abs() + 1.25;
            assert!((g as f64 - expect).abs() <= tol, "{g} vs {expect}");
        }
        // Triangular over +-half: variance half^2/6, so the mean's standard
        // error is half/sqrt(6n); the variance's own is about 0.3 % here.
        let se = half as f64 / (6.0 * n as f64).sqrt();
        assert!((sum / n as f64).abs() < 5.0 * se);
        let var = sq / n as f64 / (half as f64).powi(2);
        assert!((var - 1.0 / 6.0).abs() < 0.01 / 6.0, "{var}");
        assert!((cfg.mean_square() - cfg.half_width_rad().powi(2) / 6.0).abs() < 1e-15);
    }

    /// The closed-form moments against the density's numeric integral.
    #[test]
    fn triangular_moments() {
        let cfg = DitherConfig::new(240.0, 16, 2_208.0, 0.875 * core::f64::consts::PI);
        let w = cfg.half_width_rad();
        let m = 200_000;
        let (mut c, mut rs) = (0.0, 0.0);
        for k in 0..m {
            let r = -w + (k as f64 + 0.5) * 2.0 * w / m as f64;
            let p = (w - r.abs()) / (w * w) * 2.0 * w / m as f64;
            c += r.cos() * p;
            rs += r * r.sin() * p;
        }
        assert!(
            (cfg.mean_cos() - c).abs() < 1e-9,
            "{} vs {c}",
            cfg.mean_cos()
        );
        assert!(
            (cfg.mean_r_sin() - rs).abs() < 1e-9,
            "{} vs {rs}",
            cfg.mean_r_sin()
        );
    }

    #[test]
    fn zero_codes_turn_it_off() {
        let cfg = DitherConfig::new(0.0, 12, 8_000.0, 0.75 * core::f64::consts::PI);
        assert_eq!((cfg.bits, cfg.gain), (0, 0));
        assert_eq!(Dither::default().update(&cfg), DepthStep::default());
    }
}
