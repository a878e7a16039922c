//! RLG thermal coefficients: what `gyro-lab fit thermal` writes and the
//! firmware loads. The board stores them as a versioned binary record with a
//! CRC; a corrupt, out-of-range or wrong-version record is refused and the
//! firmware runs on [`ThermalCoeffs::SAFE`] (no compensation) with a flag set.

use crc::{Crc, CRC_32_ISO_HDLC};

/// Thermal bias model of physics.md 2.3 (units in the names):
/// `B = bias0 + k1*dT + k2*d(dT)/dt + k3*dT^2 + k4*T_K + k5*(1 - exp(-t/tau_warm))`,
/// dT = T_mono_a - T_mono_b.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ThermalCoeffs {
    pub bias0_dph: f64,
    pub k1_dph_per_c: f64,
    pub k2_dph_per_c_per_s: f64,
    pub k3_dph_per_c2: f64,
    pub k4_dph_per_c: f64,
    pub k5_dph: f64,
    pub tau_warm_s: f64,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CoeffError {
    /// Record too short or its CRC does not match.
    Corrupt,
    /// A format version this firmware does not know.
    Version,
    /// A coefficient outside the range the fixed-point compensation holds.
    Range,
}

/// Record layout: magic "RLGT", version u16, reserved u16, 7 x f64 (LE), CRC-32
/// (ISO-HDLC) of everything before it.
pub const RECORD_LEN: usize = 4 + 2 + 2 + 7 * 8 + 4;
pub const VERSION: u16 = 1;
const MAGIC: &[u8; 4] = b"RLGT";
const CRC32: Crc<u32> = Crc::<u32>::new(&CRC_32_ISO_HDLC);

/// Largest coefficient magnitude accepted, deg/h per unit (fixed-point headroom:
/// coefficients are Q24 in an i64, see thermal.rs).
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

    pub fn to_record(self) -> [u8; RECORD_LEN] {
        let mut r = [0u8; RECORD_LEN];
        r[..4].copy_from_slice(MAGIC);
        r[4..6].copy_from_slice(&VERSION.to_le_bytes());
        for (chunk, v) in r[8..8 + 56].chunks_exact_mut(8).zip(self.values()) {
            chunk.copy_from_slice(&v.to_le_bytes());
        }
        let crc = CRC32.checksum(&r[..RECORD_LEN - 4]);
        r[RECORD_LEN - 4..].copy_from_slice(&crc.to_le_bytes());
        r
    }

    /// Parses and checks a stored record.
    pub fn from_record(r: &[u8]) -> Result<Self, CoeffError> {
        let r = r.get(..RECORD_LEN).ok_or(CoeffError::Corrupt)?;
        let (body, crc) = r.split_at(RECORD_LEN - 4);
        let stored = u32::from_le_bytes(crc.try_into().map_err(|_| CoeffError::Corrupt)?);
        if body.get(..4) != Some(MAGIC.as_slice()) || CRC32.checksum(body) != stored {
            return Err(CoeffError::Corrupt);
        }
        if u16::from_le_bytes([body[4], body[5]]) != VERSION {
            return Err(CoeffError::Version);
        }
        let mut v = [0f64; 7];
        for (x, chunk) in v.iter_mut().zip(body[8..].chunks_exact(8)) {
            let mut b = [0u8; 8];
            b.copy_from_slice(chunk);
            *x = f64::from_le_bytes(b);
        }
        let c = Self::from_values(v);
        c.check()?;
        Ok(c)
    }
}
