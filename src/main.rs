//! Firmware of the gyro signal processor (STM32F405).
//!
//! `--features qemu`: runs on qemu-system-arm `netduinoplus2` with the gyro
//! simulated on-chip (`sim`), SysTick driving the 12.5 kHz closure.
//! `--features hw`: the real board: ADC1 + DMA at 4 samples per half period, the
//! modulator DAC on SPI1 + DMA, the closure in the ADC DMA interrupt, IWDG.
//! Both send the frames of `gyro_sp::frame` over USART1 and log with defmt.
#![no_std]
#![no_main]

mod fw;

#[cfg(feature = "qemu")]
#[cortex_m_rt::entry]
fn main() -> ! {
    fw::qemu::run()
}

#[cfg(all(feature = "hw", not(feature = "qemu")))]
#[cortex_m_rt::entry]
fn main() -> ! {
    fw::hw::run()
}
