//! RLG thermal coefficients: the record type lives in `gyro-coeffs`, shared
//! with the build script and gyro-lab; re-exported here where the RLG code
//! uses it.

pub use gyro_coeffs::rlg_thermal::{ThermalCoeffs, COEFF_LIMIT, RECORD_LEN, VERSION};
pub use gyro_coeffs::CoeffError;
