//! Helpers for the end-to-end tests in `tests/tests/`.
//!
//! [`zumo::Zumo`] runs the firmware's release ELF in simavr on an emulated
//! Zumo 32U4 (field sensors, Pixy, buttons, motors, serial log).

pub mod zumo;
