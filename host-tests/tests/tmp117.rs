//! TMP117 driver against mocked I2C transactions (embedded-hal-mock), and the
//! compensation's fallback when a sensor NACKs, times out or sticks.

use embedded_hal::i2c::ErrorKind;
use embedded_hal_mock::eh1::i2c::{Mock, Transaction as T};
use gyro_sp::rlg::thermal::{RlgFlags, Temperatures, ThermalComp, ThermalConfig};
use gyro_sp::rlg::ThermalCoeffs;
use tmp117::{Tmp117, Tmp117Error, NACK_ADDRESS};

const A: u8 = 0x48;

#[test]
fn init_checks_id_and_configures() {
    let mut bus = Mock::new(&[
        T::write_read(A, vec![0x0F], vec![0x01, 0x17]),
        T::write(A, vec![0x01, 0x02, 0x20]),
    ]);
    assert_eq!(Tmp117::new(A).init(&mut bus), Ok(()));
    bus.done();

    // Another part at the address (e.g. a TMP116, ID 0x1116): refused.
    let mut bus = Mock::new(&[T::write_read(A, vec![0x0F], vec![0x11, 0x16])]);
    assert_eq!(
        Tmp117::new(A).init(&mut bus),
        Err(Tmp117Error::WrongDevice(0x116))
    );
    bus.done();
}

/// Datasheet examples (7.3.1): 0x0C80 = 25 degC, 0xFF80 = -1 degC, 0x0001 =
/// 7.8125 mdegC; in Q8 that is the register value times 2.
#[test]
fn temperature_conversion() {
    let s = Tmp117::new(A);
    for (bytes, q8) in [
        ([0x0C, 0x80], 25 * 256),
        ([0xFF, 0x80], -256),
        ([0x00, 0x01], 2),
        ([0xE4, 0x80], -55 * 256),
        ([0x4B, 0x00], 150 * 256),
    ] {
        let mut bus = Mock::new(&[T::write_read(A, vec![0x00], bytes.to_vec())]);
        assert_eq!(s.read_q8(&mut bus), Ok(q8));
        bus.done();
    }
}

#[test]
fn failures_are_errors() {
    let s = Tmp117::new(A);
    let mut bus = Mock::new(&[
        T::write_read(A, vec![0x00], vec![0, 0]).with_error(NACK_ADDRESS),
        T::write_read(A, vec![0x00], vec![0, 0]).with_error(ErrorKind::Bus),
        T::write_read(A, vec![0x00], vec![0, 0]).with_error(ErrorKind::ArbitrationLoss),
        T::write_read(A, vec![0x00], vec![0x80, 0x00]),
    ]);
    assert_eq!(s.read_q8(&mut bus), Err(Tmp117Error::Nack));
    assert_eq!(s.read_q8(&mut bus), Err(Tmp117Error::Bus(ErrorKind::Bus)));
    assert_eq!(
        s.read_q8(&mut bus),
        Err(Tmp117Error::Bus(ErrorKind::ArbitrationLoss))
    );
    assert_eq!(s.read_q8(&mut bus), Err(Tmp117Error::NotReady));
    bus.done();
}

/// Three sensors on one bus into the compensation: the case sensor NACKs for
/// a while, its flag rises, its last good value is held (B_TC unchanged),
/// and the flag clears when it answers again.
#[test]
fn nack_raises_flag_and_holds_value() {
    let (a, b, k) = (Tmp117::new(0x48), Tmp117::new(0x49), Tmp117::new(0x4A));
    let coeffs = ThermalCoeffs {
        k4_dph_per_c: 0.01,
        ..ThermalCoeffs::SAFE
    };
    let cfg = ThermalConfig::new(&coeffs, 0.125);
    let mut comp = ThermalComp::default();
    let reg = |t_c: f64| ((t_c * 128.0).round() as i16).to_be_bytes().to_vec();
    let mut expect = Vec::new();
    // 10 reads with the case at 30 degC, 5 NACKs, 3 good reads at 31 degC.
    for i in 0..18 {
        expect.push(T::write_read(0x48, vec![0], reg(20.0 + 0.01 * i as f64)));
        expect.push(T::write_read(0x49, vec![0], reg(20.5)));
        let t = T::write_read(0x4A, vec![0], reg(if i < 10 { 30.0 } else { 31.0 }));
        expect.push(if (10..15).contains(&i) {
            t.with_error(NACK_ADDRESS)
        } else {
            t
        });
    }
    let mut bus = Mock::new(&expect);
    let mut last = 0;
    for i in 0..18 {
        let t = Temperatures {
            mono_a_q8: a.read(&mut bus),
            mono_b_q8: b.read(&mut bus),
            case_q8: k.read(&mut bus),
        };
        let bias = comp.update(&cfg, &t);
        let bad = comp.flags().contains(RlgFlags::SENSOR_CASE);
        assert_eq!(bad, (10..15).contains(&i), "read {i}");
        let k4_term = 0.01 * if i < 15 { 30.0 } else { 31.0 };
        assert!(
            (bias as f64 / 65_536.0 - k4_term).abs() < 1e-4,
            "read {i}: {}",
            bias as f64 / 65_536.0
        );
        last = bias;
    }
    assert!(last > 0);
    bus.done();
}

/// A model slave for bus recovery: it lost clocks mid-byte and drives SDA
/// low until it has seen `bits_left` more SCL rising edges; it records the
/// STOP (SDA rising while SCL is high).
struct StuckSlave {
    bits_left: u32,
    scl_high: bool,
    sda_released_by_master: bool,
    rising_edges: u32,
    stop_seen: bool,
}

impl StuckSlave {
    fn sda_level(&self) -> bool {
        self.sda_released_by_master && self.bits_left == 0
    }
}

/// The board's two pins on one shared model (interior mutability, as the
/// two GPIOs share one bus).
struct Pin<'a> {
    bus: &'a std::cell::RefCell<StuckSlave>,
    is_scl: bool,
}

impl embedded_hal::digital::ErrorType for Pin<'_> {
    type Error = core::convert::Infallible;
}

impl embedded_hal::digital::OutputPin for Pin<'_> {
    fn set_low(&mut self) -> Result<(), Self::Error> {
        let mut b = self.bus.borrow_mut();
        if self.is_scl {
            b.scl_high = false;
        } else {
            b.sda_released_by_master = false;
        }
        Ok(())
    }
    fn set_high(&mut self) -> Result<(), Self::Error> {
        let mut b = self.bus.borrow_mut();
        if self.is_scl {
            if !b.scl_high {
                b.rising_edges += 1;
                b.bits_left = b.bits_left.saturating_sub(1);
            }
            b.scl_high = true;
        } else {
            let was_low = !b.sda_level();
            b.sda_released_by_master = true;
            if was_low && b.sda_level() && b.scl_high {
                b.stop_seen = true;
            }
        }
        Ok(())
    }
}

impl embedded_hal::digital::InputPin for Pin<'_> {
    fn is_high(&mut self) -> Result<bool, Self::Error> {
        let b = self.bus.borrow();
        Ok(if self.is_scl {
            b.scl_high
        } else {
            b.sda_level()
        })
    }
    fn is_low(&mut self) -> Result<bool, Self::Error> {
        self.is_high().map(|h| !h)
    }
}

struct NoDelay;
impl embedded_hal::delay::DelayNs for NoDelay {
    fn delay_ns(&mut self, _: u32) {}
}

/// A slave holding SDA through k more bits is freed after exactly k clocks
/// and sees a STOP; a free bus takes no clock; one held beyond nine clocks
/// (a dead slave or a short) is reported stuck, never waited on.
#[test]
fn bus_recovery_frees_a_held_sda() {
    for held in 0..=9u32 {
        let bus = std::cell::RefCell::new(StuckSlave {
            bits_left: held,
            scl_high: true,
            sda_released_by_master: true,
            rising_edges: 0,
            stop_seen: false,
        });
        let (mut scl, mut sda) = (
            Pin {
                bus: &bus,
                is_scl: true,
            },
            Pin {
                bus: &bus,
                is_scl: false,
            },
        );
        let r = tmp117::recover_bus(&mut scl, &mut sda, &mut NoDelay);
        assert_eq!(r, Ok(held), "held for {held} bits");
        let b = bus.borrow();
        assert!(b.stop_seen, "no STOP after {held} bits");
        assert!(b.sda_level() && b.scl_high, "bus left held");
    }
    let bus = std::cell::RefCell::new(StuckSlave {
        bits_left: u32::MAX,
        scl_high: true,
        sda_released_by_master: true,
        rising_edges: 0,
        stop_seen: false,
    });
    let r = tmp117::recover_bus(
        &mut Pin {
            bus: &bus,
            is_scl: true,
        },
        &mut Pin {
            bus: &bus,
            is_scl: false,
        },
        &mut NoDelay,
    );
    assert_eq!(r, Err(tmp117::BusStuck));
    assert_eq!(bus.borrow().rising_edges, tmp117::MAX_CLOCKS);
}
