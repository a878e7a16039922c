//! The binary record shared by every coefficient set: magic (4 bytes),
//! format version (u16), a count (u16, what the set says it holds), the
//! values as little-endian f64, then a CRC-32 (ISO-HDLC) of everything
//! before it.

use crc::{Crc, CRC_32_ISO_HDLC};

const CRC32: Crc<u32> = Crc::<u32>::new(&CRC_32_ISO_HDLC);
/// Bytes before the values.
pub const HEADER_LEN: usize = 8;

/// Why a stored record was refused.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum CoeffError {
    /// Record too short, wrong magic or its CRC does not match.
    Corrupt,
    /// A format version this firmware does not know.
    Version,
    /// A value outside the range the fixed-point compensation holds.
    Range,
}

/// Record length for `n` values.
pub const fn len(n: usize) -> usize {
    HEADER_LEN + 8 * n + 4
}

/// Writes a record of `values` into `out` (`len(values.len())` bytes).
pub fn encode(magic: &[u8; 4], version: u16, count: u16, values: &[f64], out: &mut [u8]) {
    let n = len(values.len());
    let Some(out) = out.get_mut(..n) else { return };
    out.fill(0);
    out[..4].copy_from_slice(magic);
    out[4..6].copy_from_slice(&version.to_le_bytes());
    out[6..8].copy_from_slice(&count.to_le_bytes());
    for (chunk, v) in out[HEADER_LEN..n - 4].chunks_exact_mut(8).zip(values) {
        chunk.copy_from_slice(&v.to_le_bytes());
    }
    let crc = CRC32.checksum(&out[..n - 4]);
    out[n - 4..].copy_from_slice(&crc.to_le_bytes());
}

/// Checks magic, CRC and version of a record of `values.len()` values and
/// reads them; returns the count word.
pub fn decode(
    magic: &[u8; 4],
    version: u16,
    r: &[u8],
    values: &mut [f64],
) -> Result<u16, CoeffError> {
    let n = len(values.len());
    let r = r.get(..n).ok_or(CoeffError::Corrupt)?;
    let (body, crc) = r.split_at(n - 4);
    let mut stored = [0u8; 4];
    stored.copy_from_slice(crc);
    if body.get(..4) != Some(magic.as_slice()) || CRC32.checksum(body) != u32::from_le_bytes(stored)
    {
        return Err(CoeffError::Corrupt);
    }
    if u16::from_le_bytes([body[4], body[5]]) != version {
        return Err(CoeffError::Version);
    }
    for (x, chunk) in values.iter_mut().zip(body[HEADER_LEN..].chunks_exact(8)) {
        let mut b = [0u8; 8];
        b.copy_from_slice(chunk);
        *x = f64::from_le_bytes(b);
    }
    Ok(u16::from_le_bytes([body[6], body[7]]))
}

/// The CRC word of a record (its last four bytes), for the fit's notes.
pub fn crc_of(record: &[u8]) -> u32 {
    let n = record.len();
    match record.get(n.saturating_sub(4)..) {
        Some(b) if n >= 4 => u32::from_le_bytes([b[0], b[1], b[2], b[3]]),
        _ => 0,
    }
}
