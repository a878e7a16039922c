//! Phase in fixed point: one full turn (2*pi rad) is 2^32 LSB, so the
//! wrapping arithmetic of a `u32` is the 2*pi reset. Every phase constant of
//! the core is defined here, once.

#[allow(unused_imports)] // f64 maths comes from libm where core lacks it
use num_traits::float::Float;

/// Phase with one turn = 2^32 LSB (wrapping on purpose).
pub type Phase = u32;

/// Phase LSB in one turn.
pub const PHASE_LSB_PER_TURN: f64 = 4_294_967_296.0;

/// Radians per [`Phase`] LSB.
pub const RAD_PER_PHASE_LSB: f64 = core::f64::consts::TAU / PHASE_LSB_PER_TURN;

/// [`Phase`] LSB per radian.
pub const PHASE_LSB_PER_RAD: f64 = PHASE_LSB_PER_TURN / core::f64::consts::TAU;

/// Converts radians to phase LSB (rounded, wrapping to one turn).
pub fn phase_from_rad(rad: f64) -> Phase {
    let turns = rad / core::f64::consts::TAU;
    let frac = turns - turns.floor();
    (frac * PHASE_LSB_PER_TURN + 0.5) as u64 as u32
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn turns_wrap_and_constants_agree() {
        assert_eq!(phase_from_rad(0.0), 0);
        assert_eq!(phase_from_rad(core::f64::consts::PI), 1 << 31);
        assert_eq!(phase_from_rad(-core::f64::consts::FRAC_PI_2), 3 << 30);
        assert_eq!(phase_from_rad(core::f64::consts::TAU), 0);
        assert!((RAD_PER_PHASE_LSB * PHASE_LSB_PER_RAD - 1.0).abs() < 1e-15);
    }
}
