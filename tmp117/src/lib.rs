//! TI TMP117 precision digital temperature sensor (+-0.1 degC, 1/128 degC
//! LSB) on I2C, generic over embedded-hal 1.0 [`I2c`]. The driver borrows the
//! bus per call, so the two monoblock sensors and the case sensor share one
//! bus at their own addresses (0x48..0x4B by the ADD0 pin).
//!
//! Any failure is an error, never a guess: a NACK (sensor absent or dead), a
//! bus fault or timeout, the power-on value 0x8000 (no conversion yet), or a
//! wrong device ID at probe. The thermal compensation turns an error into a
//! missing read (flag, hold last good value). A bus a slave holds low is
//! freed by [`recover_bus`].

#![no_std]

mod recovery;

pub use recovery::{recover_bus, BusStuck, HALF_PERIOD_NS, MAX_CLOCKS};

use embedded_hal::i2c::{ErrorKind, I2c, NoAcknowledgeSource};

/// Register pointers (datasheet SNOSD82, table 7-3).
pub const REG_TEMP: u8 = 0x00;
pub const REG_CONFIG: u8 = 0x01;
pub const REG_DEVICE_ID: u8 = 0x0F;
/// Device ID register, bits 11:0.
pub const DEVICE_ID: u16 = 0x0117;
/// Temperature register after reset, before the first conversion.
pub const TEMP_RESET: i16 = i16::MIN;
/// Configuration: continuous conversion, 8 averages, 125 ms cycle
/// (CONV = 010, AVG = 01, MOD = 00).
pub const CONFIG_8AVG_125MS: u16 = 0b0000_0010_0010_0000;

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Tmp117Error {
    /// The sensor did not acknowledge its address or data.
    Nack,
    /// Bus fault, arbitration loss, overrun or timeout.
    Bus(ErrorKind),
    /// Device ID is not a TMP117.
    WrongDevice(u16),
    /// The register still holds its reset value: no conversion yet.
    NotReady,
}

fn bus_error<E: embedded_hal::i2c::Error>(e: E) -> Tmp117Error {
    match e.kind() {
        ErrorKind::NoAcknowledge(_) => Tmp117Error::Nack,
        k => Tmp117Error::Bus(k),
    }
}

/// One TMP117 at a 7-bit address.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Tmp117 {
    pub addr: u8,
}

impl Tmp117 {
    pub const fn new(addr: u8) -> Self {
        Self { addr }
    }

    fn read_reg<B: I2c>(&self, bus: &mut B, reg: u8) -> Result<u16, Tmp117Error> {
        let mut b = [0u8; 2];
        bus.write_read(self.addr, &[reg], &mut b)
            .map_err(bus_error)?;
        Ok(u16::from_be_bytes(b))
    }

    /// Checks the device ID and sets 8-average continuous conversion.
    pub fn init<B: I2c>(&self, bus: &mut B) -> Result<(), Tmp117Error> {
        let id = self.read_reg(bus, REG_DEVICE_ID)? & 0x0FFF;
        if id != DEVICE_ID {
            return Err(Tmp117Error::WrongDevice(id));
        }
        let c = CONFIG_8AVG_125MS.to_be_bytes();
        bus.write(self.addr, &[REG_CONFIG, c[0], c[1]])
            .map_err(bus_error)
    }

    /// Temperature, Q8 degC (the register's 1/128 degC LSB times 2).
    pub fn read_q8<B: I2c>(&self, bus: &mut B) -> Result<i32, Tmp117Error> {
        let raw = self.read_reg(bus, REG_TEMP)? as i16;
        if raw == TEMP_RESET {
            return Err(Tmp117Error::NotReady);
        }
        Ok(raw as i32 * 2)
    }

    /// The read the compensation takes: `None` on any error.
    pub fn read<B: I2c>(&self, bus: &mut B) -> Option<i32> {
        self.read_q8(bus).ok()
    }
}

/// A NACK on the address, for bus models (simulated sensors).
pub const NACK_ADDRESS: ErrorKind = ErrorKind::NoAcknowledge(NoAcknowledgeSource::Address);
