//! I2C1 master (STM32F4 I2C v1 peripheral, RM0090 section 27) as an
//! embedded-hal 1.0 [`I2c`] bus for the TMP117 driver: blocking, polled,
//! every wait bounded. The HAL's I2C waits without a bound (a bus held low
//! would stall the idle loop, and the frames with it, until the watchdog),
//! hence this driver. A wait that runs out, a bus error or a lost
//! arbitration ends the transfer with STOP and an error; a bus a slave holds
//! low (BUSY with no transfer of ours, or a wait that ran out) is freed by
//! clocking SCL as a GPIO until SDA is released ([`tmp117::recover_bus`]),
//! then the peripheral is reset. A dead sensor costs at most a few hundred
//! microseconds of the idle loop, flagged, and never hangs it.
//!
//! Pins PB8 (SCL) and PB9 (SDA), AF4, open drain with pull-ups; 400 kHz fast
//! mode from APB1 at 42 MHz. Used from thread mode only (the idle loop reads
//! the sensors at 10 Hz); the interrupts never touch it.

use core::convert::Infallible;
use embedded_hal::digital::{ErrorType as PinErrorType, InputPin, OutputPin};
use embedded_hal::i2c::{
    ErrorKind, ErrorType, I2c, NoAcknowledgeSource, Operation, SevenBitAddress,
};
use stm32f4::stm32f405 as pac;

/// Register polls before a wait gives up: one byte at 400 kHz is 22.5 us,
/// a poll a few core cycles at 168 MHz; 20 000 polls are several bytes long.
const POLLS: u32 = 20_000;

// SR1 bits.
const SB: u16 = 1 << 0;
const ADDR: u16 = 1 << 1;
const BTF: u16 = 1 << 2;
const RXNE: u16 = 1 << 6;
const TXE: u16 = 1 << 7;
const BERR: u16 = 1 << 8;
const ARLO: u16 = 1 << 9;
const AF: u16 = 1 << 10;
// CR1 bits.
const PE: u16 = 1 << 0;
const START: u16 = 1 << 8;
const STOP: u16 = 1 << 9;
const ACK: u16 = 1 << 10;
const POS: u16 = 1 << 11;
const SWRST: u16 = 1 << 15;

/// SCL and SDA on GPIOB.
const SCL_PIN: u32 = 8;
const SDA_PIN: u32 = 9;

/// Core cycles per microsecond at 168 MHz (the delays only need to be
/// long enough).
const CYCLES_PER_US: u32 = 168;

pub struct I2c1 {
    i2c: pac::I2C1,
    gpiob: pac::GPIOB,
    /// Bus recoveries so far (a stuck SDA freed), and ones that failed.
    pub recoveries: u32,
    pub recovery_failures: u32,
}

impl I2c1 {
    /// Configures PB8/PB9 and the peripheral (clocks for GPIOB and I2C1 must
    /// be on). `gpiob`: only PB8/PB9's bits are touched, here and in
    /// recovery.
    pub fn new(i2c: pac::I2C1, gpiob: pac::GPIOB) -> Self {
        // PB8, PB9: open drain, pull-up, AF4.
        gpiob
            .otyper()
            .modify(|r, w| unsafe { w.bits(r.bits() | (0b11 << 8)) });
        gpiob
            .pupdr()
            .modify(|r, w| unsafe { w.bits((r.bits() & !(0xF << 16)) | (0x5 << 16)) });
        gpiob
            .afrh()
            .modify(|r, w| unsafe { w.bits((r.bits() & !0xFF) | 0x44) });
        let bus = Self {
            i2c,
            gpiob,
            recoveries: 0,
            recovery_failures: 0,
        };
        bus.pins_to_i2c();
        bus.configure();
        bus
    }

    /// PB8/PB9 to the I2C peripheral (MODER 10, alternate function).
    fn pins_to_i2c(&self) {
        self.gpiob
            .moder()
            .modify(|r, w| unsafe { w.bits((r.bits() & !(0xF << 16)) | (0xA << 16)) });
    }

    /// PB8/PB9 to open-drain GPIO outputs (MODER 01), released (high).
    fn pins_to_gpio(&self) {
        self.gpiob
            .bsrr()
            .write(|w| unsafe { w.bits((1 << SCL_PIN) | (1 << SDA_PIN)) });
        self.gpiob
            .moder()
            .modify(|r, w| unsafe { w.bits((r.bits() & !(0xF << 16)) | (0x5 << 16)) });
    }

    /// Frees a bus a slave holds low, then resets the peripheral.
    fn recover(&mut self) {
        self.pins_to_gpio();
        let (mut scl, mut sda) = (
            BusPin {
                gpiob: &self.gpiob,
                pin: SCL_PIN,
            },
            BusPin {
                gpiob: &self.gpiob,
                pin: SDA_PIN,
            },
        );
        match tmp117::recover_bus(&mut scl, &mut sda, &mut CycleDelay) {
            Ok(_) => self.recoveries = self.recoveries.wrapping_add(1),
            Err(_) => self.recovery_failures = self.recovery_failures.wrapping_add(1),
        }
        self.pins_to_i2c();
        self.configure();
    }

    /// Reset and set 400 kHz fast mode (APB1 42 MHz): CCR = 42 MHz / (3 x 400 kHz)
    /// = 35 (duty 2:1), TRISE = 300 ns x 42 MHz + 1 = 13.
    fn configure(&self) {
        let r = &self.i2c;
        r.cr1().write(|w| unsafe { w.bits(SWRST) });
        r.cr1().write(|w| unsafe { w.bits(0) });
        r.cr2().write(|w| unsafe { w.bits(42) }); // FREQ = 42 MHz
        r.ccr().write(|w| unsafe { w.bits((1 << 15) | 35) }); // F/S, CCR
        r.trise().write(|w| unsafe { w.bits(13) });
        r.cr1().write(|w| unsafe { w.bits(PE) });
    }

    fn cr1_set(&self, bits: u16) {
        self.i2c
            .cr1()
            .modify(|r, w| unsafe { w.bits(r.bits() | bits) });
    }

    fn cr1_clear(&self, bits: u16) {
        self.i2c
            .cr1()
            .modify(|r, w| unsafe { w.bits(r.bits() & !bits) });
    }

    /// Waits for any of `bits` in SR1; errors on NACK, bus error, lost
    /// arbitration or when the polls run out.
    fn wait(&self, bits: u16, nack: NoAcknowledgeSource) -> Result<u16, ErrorKind> {
        for _ in 0..POLLS {
            let sr1 = self.i2c.sr1().read().bits();
            if sr1 & (AF | BERR | ARLO) != 0 {
                // Clear the error flags (rc_w0).
                self.i2c
                    .sr1()
                    .write(|w| unsafe { w.bits(!(AF | BERR | ARLO)) });
                return Err(if sr1 & AF != 0 {
                    ErrorKind::NoAcknowledge(nack)
                } else if sr1 & ARLO != 0 {
                    ErrorKind::ArbitrationLoss
                } else {
                    ErrorKind::Bus
                });
            }
            if sr1 & bits != 0 {
                return Ok(sr1);
            }
        }
        Err(ErrorKind::Other)
    }

    /// (Repeated) START and the address byte; `read` sets the direction bit.
    fn start(&self, addr: u8, read: bool) -> Result<(), ErrorKind> {
        self.cr1_set(START);
        self.wait(SB, NoAcknowledgeSource::Unknown)?;
        self.i2c
            .dr()
            .write(|w| unsafe { w.bits(((addr as u16) << 1) | read as u16) });
        self.wait(ADDR, NoAcknowledgeSource::Address)?;
        Ok(())
    }

    /// Clears ADDR (read SR1 then SR2), which releases the clock stretch.
    fn clear_addr(&self) {
        let _ = self.i2c.sr1().read().bits();
        let _ = self.i2c.sr2().read().bits();
    }

    fn write_bytes(&self, bytes: &[u8]) -> Result<(), ErrorKind> {
        for &b in bytes {
            self.wait(TXE, NoAcknowledgeSource::Data)?;
            self.i2c.dr().write(|w| unsafe { w.bits(b as u16) });
        }
        self.wait(BTF, NoAcknowledgeSource::Data)?;
        Ok(())
    }

    fn read_dr(&self) -> u8 {
        self.i2c.dr().read().bits() as u8
    }

    /// Receives `buf` after the address phase (ADDR set, not yet cleared) and
    /// ends with STOP, by RM0090's sequences for 1, 2 and more bytes (the v1
    /// peripheral must be told to NACK before the last bytes arrive).
    fn read_bytes(&self, buf: &mut [u8]) -> Result<(), ErrorKind> {
        match buf {
            [] => {
                self.clear_addr();
                self.cr1_set(STOP);
            }
            [only] => {
                self.cr1_clear(ACK);
                self.clear_addr();
                self.cr1_set(STOP);
                self.wait(RXNE, NoAcknowledgeSource::Data)?;
                *only = self.read_dr();
            }
            [first, second] => {
                self.cr1_set(POS);
                self.cr1_clear(ACK);
                self.clear_addr();
                self.wait(BTF, NoAcknowledgeSource::Data)?;
                self.cr1_set(STOP);
                *first = self.read_dr();
                *second = self.read_dr();
                self.cr1_clear(POS);
            }
            _ => {
                self.cr1_set(ACK);
                self.clear_addr();
                let n = buf.len();
                for (i, b) in buf.iter_mut().enumerate() {
                    match n - i {
                        3 => {
                            // Data N-2 in DR, N-1 in the shift register.
                            self.wait(BTF, NoAcknowledgeSource::Data)?;
                            self.cr1_clear(ACK);
                            *b = self.read_dr();
                        }
                        2 => {
                            self.wait(BTF, NoAcknowledgeSource::Data)?;
                            self.cr1_set(STOP);
                            *b = self.read_dr();
                        }
                        _ => {
                            self.wait(RXNE, NoAcknowledgeSource::Data)?;
                            *b = self.read_dr();
                        }
                    }
                }
            }
        }
        Ok(())
    }

    fn run(&mut self, address: u8, ops: &mut [Operation<'_>]) -> Result<(), ErrorKind> {
        if self.i2c.sr2().read().bits() & 0b10 != 0 {
            // BUSY with no transfer of ours: a slave holds SDA.
            self.recover();
            if self.i2c.sr2().read().bits() & 0b10 != 0 {
                return Err(ErrorKind::Bus);
            }
        }
        let last = ops.len().saturating_sub(1);
        let mut prev_write = false;
        for (i, op) in ops.iter_mut().enumerate() {
            match op {
                Operation::Write(bytes) => {
                    // Adjacent writes continue the same segment (no restart).
                    if !prev_write {
                        self.start(address, false)?;
                        self.clear_addr();
                    }
                    self.write_bytes(bytes)?;
                    prev_write = true;
                    if i == last {
                        self.cr1_set(STOP);
                    }
                }
                Operation::Read(buf) => {
                    // A read ends with NACK + STOP; only a final read is
                    // supported (what register reads need); adjacent reads
                    // would have to share one NACK sequence.
                    if i != last {
                        return Err(ErrorKind::Other);
                    }
                    self.start(address, true)?;
                    self.read_bytes(buf)?;
                    prev_write = false;
                }
            }
        }
        Ok(())
    }
}

impl ErrorType for I2c1 {
    type Error = ErrorKind;
}

impl I2c<SevenBitAddress> for I2c1 {
    fn transaction(
        &mut self,
        address: u8,
        operations: &mut [Operation<'_>],
    ) -> Result<(), ErrorKind> {
        let r = self.run(address, operations);
        if r.is_err() {
            // Release the bus whatever state the transfer stopped in.
            self.cr1_set(STOP);
            if r == Err(ErrorKind::Other) {
                // A wait ran out: a slave may hold the bus mid-byte.
                self.recover();
            }
        }
        r
    }
}

/// One of the bus pins as an open-drain GPIO during recovery.
struct BusPin<'a> {
    gpiob: &'a pac::GPIOB,
    pin: u32,
}

impl PinErrorType for BusPin<'_> {
    type Error = Infallible;
}

impl OutputPin for BusPin<'_> {
    fn set_low(&mut self) -> Result<(), Infallible> {
        self.gpiob
            .bsrr()
            .write(|w| unsafe { w.bits(1 << (self.pin + 16)) });
        Ok(())
    }
    fn set_high(&mut self) -> Result<(), Infallible> {
        self.gpiob
            .bsrr()
            .write(|w| unsafe { w.bits(1 << self.pin) });
        Ok(())
    }
}

impl InputPin for BusPin<'_> {
    fn is_high(&mut self) -> Result<bool, Infallible> {
        Ok(self.gpiob.idr().read().bits() & (1 << self.pin) != 0)
    }
    fn is_low(&mut self) -> Result<bool, Infallible> {
        self.is_high().map(|h| !h)
    }
}

/// Busy-wait delay on the core clock (recovery only: microseconds).
struct CycleDelay;

impl embedded_hal::delay::DelayNs for CycleDelay {
    fn delay_ns(&mut self, ns: u32) {
        cortex_m::asm::delay(ns.div_ceil(1000).saturating_mul(CYCLES_PER_US));
    }
}
