//! Platform-independent logic of the Zumo 32U4 firmware, unit-tested on the host.
//!
//! The board layer (`src/board.rs`, AVR only) does register access and
//! calls into these modules; everything the simulator also needs
//! (calibration arithmetic, blob classification, drive mixing, log frames)
//! is in `shared`.
#![no_std]
#![forbid(unsafe_code)]
#![warn(missing_docs)]

pub mod calibration_record;
pub mod camera;
pub mod config;
pub mod decision;
pub mod embedded;
pub mod health;
pub mod log_queue;
pub mod odometry;
pub mod pins;
pub mod pixy;
pub mod rc;
pub mod screen_calibration;
#[cfg(not(target_arch = "avr"))]
pub mod source_hash;
pub mod supervisor;
pub mod usb;
