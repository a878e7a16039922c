//! The simulated temperature sensors' bus.

/// Simulated TMP117s on one I2C bus: they answer temperature reads with the
/// chamber's readings; one address can be made to NACK.
pub struct SimI2c {
    /// 0x48 monoblock A, 0x49 monoblock B, 0x4A case, 0x4B FOG coil.
    pub(crate) temps_c: [f64; 4],
    pub(crate) nack: Option<u8>,
}

impl SimI2c {
    pub(crate) fn new() -> Self {
        Self {
            temps_c: [20.0; 4],
            nack: None,
        }
    }
}

impl embedded_hal::i2c::ErrorType for SimI2c {
    type Error = embedded_hal::i2c::ErrorKind;
}

impl embedded_hal::i2c::I2c for SimI2c {
    fn transaction(
        &mut self,
        address: u8,
        operations: &mut [embedded_hal::i2c::Operation<'_>],
    ) -> Result<(), Self::Error> {
        let i = match address {
            0x48..=0x4B if self.nack != Some(address) => (address - 0x48) as usize,
            _ => return Err(tmp117::NACK_ADDRESS),
        };
        let reg = ((self.temps_c[i] * 128.0) as i16).to_be_bytes();
        for op in operations {
            if let embedded_hal::i2c::Operation::Read(buf) = op {
                for (b, r) in buf.iter_mut().zip(reg) {
                    *b = r;
                }
            }
        }
        Ok(())
    }
}
