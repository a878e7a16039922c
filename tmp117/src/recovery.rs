//! I2C bus recovery (the NXP UM10204 procedure, section 3.1.16): a slave
//! that lost clocks in the middle of a byte keeps SDA low and the master can
//! never send START. Clocking SCL until the slave has shifted out its byte
//! (at most nine clocks) releases SDA; a STOP then resets every slave's
//! state machine. Generic over embedded-hal pins, so the board drives the
//! bus pins as GPIOs for it and a host test drives a model slave.

use embedded_hal::delay::DelayNs;
use embedded_hal::digital::{InputPin, OutputPin};

/// Clocks before giving up: a byte and its acknowledge.
pub const MAX_CLOCKS: u32 = 9;
/// Half a clock period, ns: 100 kHz, the slowest standard mode, so any
/// slave keeps up.
pub const HALF_PERIOD_NS: u32 = 5_000;

/// The bus stayed held: SDA still low after [`MAX_CLOCKS`] clocks (a dead
/// slave or a short), so the sensors on it are flagged until it frees.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BusStuck;

/// Frees SDA by clocking SCL (open drain: high is released), then sends
/// STOP. Returns the clocks it took (0: the bus was already free). Pin
/// errors count as a stuck bus.
pub fn recover_bus<SCL: OutputPin, SDA: InputPin + OutputPin, D: DelayNs>(
    scl: &mut SCL,
    sda: &mut SDA,
    delay: &mut D,
) -> Result<u32, BusStuck> {
    let mut clocks = 0;
    // Release both lines; SDA is only read until it is free.
    scl.set_high().map_err(|_| BusStuck)?;
    sda.set_high().map_err(|_| BusStuck)?;
    delay.delay_ns(HALF_PERIOD_NS);
    while sda.is_low().map_err(|_| BusStuck)? {
        if clocks == MAX_CLOCKS {
            return Err(BusStuck);
        }
        scl.set_low().map_err(|_| BusStuck)?;
        delay.delay_ns(HALF_PERIOD_NS);
        scl.set_high().map_err(|_| BusStuck)?;
        delay.delay_ns(HALF_PERIOD_NS);
        clocks += 1;
    }
    // STOP: SDA low while SCL is low, then SCL high, then SDA high.
    scl.set_low().map_err(|_| BusStuck)?;
    delay.delay_ns(HALF_PERIOD_NS);
    sda.set_low().map_err(|_| BusStuck)?;
    delay.delay_ns(HALF_PERIOD_NS);
    scl.set_high().map_err(|_| BusStuck)?;
    delay.delay_ns(HALF_PERIOD_NS);
    sda.set_high().map_err(|_| BusStuck)?;
    delay.delay_ns(HALF_PERIOD_NS);
    Ok(clocks)
}
