//! Helpers for the end-to-end tests in `tests/tests/`.
//!
//! [`zumo::Zumo`] runs the firmware's release ELF in simavr on an emulated
//! Zumo 32U4 (field sensors, Pixy, buttons, motors, serial log);
//! [`equivalence`] samples robot states from simulated episodes and
//! computes what the firmware must do with them; [`playback`] plays
//! stimuli to the firmware one control period each; [`usb_host`] is a USB
//! host for the firmware's serial port; [`figures`] keeps the figures the
//! tests measure current in the docs; [`in_the_loop`] drives the simulated
//! world with one firmware instance per robot.

pub mod equivalence;
pub mod figures;
pub mod in_the_loop;
pub mod playback;
pub mod usb_host;
pub mod zumo;
