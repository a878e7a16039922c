//! USART1 transmit (PA9), blocking on TXE. 2 Mbaud on the board (84 MHz APB2).

use stm32f4::stm32f405::USART1;

pub fn init(usart: &USART1, brr: u16) {
    usart.brr().write(|w| unsafe { w.bits(brr) });
    usart.cr1().write(|w| w.ue().set_bit().te().set_bit());
}

pub fn write(usart: &USART1, bytes: &[u8]) {
    for &b in bytes {
        while usart.sr().read().txe().bit_is_clear() {}
        usart.dr().write(|w| w.dr().set(b as u16));
    }
}
