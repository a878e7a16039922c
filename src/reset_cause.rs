//! Why the board started: RCC_CSR's reset flags, and a word the firmware
//! leaves in RAM that survives a reset (not a power cycle) when it resets
//! itself after a hard fault. A pure decision over those values, tested on
//! the host; the first frame after a start carries it.

pub use gyro_sp::frame::ResetCause;

/// The word the HardFault handler leaves before it resets (RAM keeps it
/// across a system reset, not across power loss).
pub const HARD_FAULT_MARK: u32 = 0x4846_4C54; // "HFLT"
/// The word the panic handler leaves before it resets.
pub const PANIC_MARK: u32 = 0x5041_4E43; // "PANC"

/// RCC_CSR's reset flags (RM0090 7.3.21), as bits of the register.
pub mod csr {
    /// Brown-out reset.
    pub const BORRSTF: u32 = 1 << 25;
    /// Reset pin.
    pub const PINRSTF: u32 = 1 << 26;
    /// Power-on / power-down reset.
    pub const PORRSTF: u32 = 1 << 27;
    /// Software reset (SYSRESETREQ).
    pub const SFTRSTF: u32 = 1 << 28;
    /// Independent watchdog.
    pub const IWDGRSTF: u32 = 1 << 29;
    /// Window watchdog.
    pub const WWDGRSTF: u32 = 1 << 30;
}

/// The cause from RCC_CSR and the RAM mark. Every internal reset also pulls
/// the reset pin, so PINRSTF alone means the pin; power-on wins over the
/// rest (RAM then holds garbage, so the mark is not trusted).
pub const fn reset_cause(csr_bits: u32, mark: u32) -> ResetCause {
    if csr_bits & (csr::PORRSTF | csr::BORRSTF) != 0 {
        ResetCause::PowerOn
    } else if csr_bits & (csr::IWDGRSTF | csr::WWDGRSTF) != 0 {
        ResetCause::Watchdog
    } else if csr_bits & csr::SFTRSTF != 0 {
        match mark {
            HARD_FAULT_MARK => ResetCause::HardFault,
            PANIC_MARK => ResetCause::Panic,
            _ => ResetCause::Software,
        }
    } else if csr_bits & csr::PINRSTF != 0 {
        ResetCause::Pin
    } else {
        // No flag (cleared by a debugger): say nothing we do not know.
        ResetCause::None
    }
}

#[cfg(test)]
mod tests {
    use super::csr::*;
    use super::*;

    #[test]
    fn causes_from_the_flags_and_the_mark() {
        assert_eq!(reset_cause(PORRSTF | PINRSTF, 0), ResetCause::PowerOn);
        assert_eq!(
            reset_cause(PORRSTF | PINRSTF | BORRSTF, HARD_FAULT_MARK),
            ResetCause::PowerOn
        );
        assert_eq!(reset_cause(IWDGRSTF | PINRSTF, 0), ResetCause::Watchdog);
        assert_eq!(
            reset_cause(IWDGRSTF | PINRSTF, HARD_FAULT_MARK),
            ResetCause::Watchdog
        );
        assert_eq!(
            reset_cause(SFTRSTF | PINRSTF, HARD_FAULT_MARK),
            ResetCause::HardFault
        );
        assert_eq!(
            reset_cause(SFTRSTF | PINRSTF, PANIC_MARK),
            ResetCause::Panic
        );
        assert_eq!(reset_cause(SFTRSTF | PINRSTF, 0x1234), ResetCause::Software);
        assert_eq!(reset_cause(PORRSTF, PANIC_MARK), ResetCause::PowerOn);
        assert_eq!(reset_cause(PINRSTF, HARD_FAULT_MARK), ResetCause::Pin);
        assert_eq!(reset_cause(0, 0), ResetCause::None);
        assert!(ResetCause::HardFault.is_recovery() && ResetCause::Watchdog.is_recovery());
        assert!(ResetCause::Panic.is_recovery());
        assert!(!ResetCause::PowerOn.is_recovery());
    }
}
