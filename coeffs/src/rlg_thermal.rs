//! RLG thermal bias model coefficients (`gyro-lab fit thermal`).

use crate::record::{self, CoeffError};

/// Thermal bias model (units in the names):
/// `B = bias0 + k1*dT + k2*d(dT)/dt + k3*dT^2 + k4*T_K + k5*(1 - exp(-t/tau_warm))`,
/// dT = T_mono_a - T_mono_b.
#[derive(Clone, Copy, Debug, PartialEq)]
#[cfg_attr(
    feature = "std",
    derive(serde::Serialize, serde::Deserialize),
    serde(deny_unknown_fields)
)]
pub struct ThermalCoeffs {
    pub bias0_dph: f64,
    pub k1_dph_per_c: f64,
    pub k2_dph_per_c_per_s: f64,
    pub k3_dph_per_c2: f64,
    pub k4_dph_per_c: f64,
    pub k5_dph: f64,
    pub tau_warm_s: f64,
}

/// Record: magic "RLGT", version, reserved word (0), 7 x f64, CRC-32.
pub const RECORD_LEN: usize = record::len(7);
pub const VERSION: u16 = 1;
const MAGIC: &[u8; 4] = b"RLGT";

/// Largest coefficient magnitude accepted, deg/h per unit (fixed-point
/// headroom: coefficients are Q24 in an i64, see gyro-sp's rlg/thermal.rs).
pub const COEFF_LIMIT: f64 = 1.0e3;

impl ThermalCoeffs {
    /// No compensation: the defined fallback.
    pub const SAFE: Self = Self {
        bias0_dph: 0.0,
        k1_dph_per_c: 0.0,
        k2_dph_per_c_per_s: 0.0,
        k3_dph_per_c2: 0.0,
        k4_dph_per_c: 0.0,
        k5_dph: 0.0,
        tau_warm_s: 600.0,
    };

    /// The values' names in record order (the file's keys).
    pub const NAMES: [&'static str; 7] = [
        "bias0_dph",
        "k1_dph_per_c",
        "k2_dph_per_c_per_s",
        "k3_dph_per_c2",
        "k4_dph_per_c",
        "k5_dph",
        "tau_warm_s",
    ];

    /// The values in record order: bias0, k1..k5, tau_warm.
    pub fn values(&self) -> [f64; 7] {
        [
            self.bias0_dph,
            self.k1_dph_per_c,
            self.k2_dph_per_c_per_s,
            self.k3_dph_per_c2,
            self.k4_dph_per_c,
            self.k5_dph,
            self.tau_warm_s,
        ]
    }

    /// From values in record order (see [`Self::values`]); not checked.
    pub fn from_values(v: [f64; 7]) -> Self {
        Self {
            bias0_dph: v[0],
            k1_dph_per_c: v[1],
            k2_dph_per_c_per_s: v[2],
            k3_dph_per_c2: v[3],
            k4_dph_per_c: v[4],
            k5_dph: v[5],
            tau_warm_s: v[6],
        }
    }

    /// Every value finite and within the fixed-point range; tau_warm in 1 s .. 1e6 s.
    pub fn check(&self) -> Result<(), CoeffError> {
        let v = self.values();
        let ok = v.iter().all(|x| x.is_finite())
            && v[..6].iter().all(|x| x.abs() <= COEFF_LIMIT)
            && (1.0..=1.0e6).contains(&self.tau_warm_s);
        if ok {
            Ok(())
        } else {
            Err(CoeffError::Range)
        }
    }

    pub fn to_record(self) -> [u8; RECORD_LEN] {
        let mut r = [0u8; RECORD_LEN];
        record::encode(MAGIC, VERSION, 0, &self.values(), &mut r);
        r
    }

    /// Parses and checks a stored record.
    pub fn from_record(r: &[u8]) -> Result<Self, CoeffError> {
        let mut v = [0f64; 7];
        record::decode(MAGIC, VERSION, r, &mut v)?;
        let c = Self::from_values(v);
        c.check()?;
        Ok(c)
    }
}
