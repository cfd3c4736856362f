//! Firmware entry point. On the host this binary is empty so that the
//! workspace builds; the AVR build is `scripts/build-firmware`.
#![cfg_attr(target_arch = "avr", no_std)]
#![cfg_attr(target_arch = "avr", no_main)]

#[cfg(not(target_arch = "avr"))]
fn main() {}
