//! Stack high-water mark: paint the free stack at start-up, look for the lowest
//! overwritten word later. With flip-link the stack sits at the bottom of RAM
//! and grows down toward 0x2000_0000, so an overflow faults instead of
//! corrupting .bss.

const PAINT: u32 = 0xC0FF_EE55;
const RAM_START: usize = 0x2000_0000;

extern "C" {
    static _stack_start: u32;
}

fn stack_top() -> usize {
    core::ptr::addr_of!(_stack_start) as usize
}

/// Paints from the bottom of RAM up to 256 bytes below the current SP.
pub fn paint() {
    let sp = cortex_m::register::msp::read() as usize;
    let end = sp.saturating_sub(256) & !3;
    let mut a = RAM_START;
    while a < end {
        unsafe { core::ptr::write_volatile(a as *mut u32, PAINT) };
        a += 4;
    }
}

/// Bytes of stack ever used.
pub fn high_water() -> u32 {
    let top = stack_top();
    let mut a = RAM_START;
    while a < top && unsafe { core::ptr::read_volatile(a as *const u32) } == PAINT {
        a += 4;
    }
    (top - a) as u32
}
