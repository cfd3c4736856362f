//! The robot's modes, buttons, faults and LEDs, one control period at a time.
//!
//! - Button A starts and stops driving; it starts only with a valid
//!   calibration.
//! - Button B (while not driving) arms the calibration from the display's
//!   screens ([`ScreenCalibration`]): the robot stands still while the
//!   display shows white, then black; it saves each sensor's two readings,
//!   or flags the failure when no such sequence came within
//!   [`CALIBRATION_PERIODS`](crate::config::CALIBRATION_PERIODS). A during
//!   a calibration aborts it.
//! - While driving, any runtime fault ([`Health`]) stops the motors until
//!   the readings return.
//!
//! LEDs: yellow on = driving, yellow blinking (1 Hz) = ready; green on =
//! calibrating, waiting for white; green blinking (5 Hz) = white seen,
//! waiting for black; red blinking (5 Hz) = camera or sensor fault; red steady =
//! no valid calibration (missing, corrupt, or the last calibration failed).

use crate::health::Health;
use crate::rc::all_timed_out;
use crate::screen_calibration::{Progress, ScreenCalibration};
use shared::{Faults, FieldCalibration, RunMode};

/// Button levels sampled this period (true = pressed).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Buttons {
    /// Button A: start / stop.
    pub a: bool,
    /// Button B: calibrate.
    pub b: bool,
}

/// Where this period's motor outputs come from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum MotorSource {
    /// Motors off.
    Stop,
    /// The policy's decision.
    Policy,
}

/// LED states (true = lit).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Leds {
    /// Yellow (PC7).
    pub yellow: bool,
    /// Green (PD5).
    pub green: bool,
    /// Red (PB0).
    pub red: bool,
}

/// What to do this period.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Plan {
    /// The mode, for the log.
    pub mode: RunMode,
    /// Active faults, for the log.
    pub faults: Faults,
    /// Which motor outputs to apply.
    pub motors: MotorSource,
    /// A new calibration to store in EEPROM and use from now on.
    pub save: Option<FieldCalibration>,
    /// LED states.
    pub leds: Leds,
}

/// Mode state across periods.
#[derive(Clone, Debug)]
pub struct Supervisor {
    mode: RunMode,
    calibrated: bool,
    sticky: Faults,
    health: Health,
    calibration: ScreenCalibration,
    last: Buttons,
    tick: u32,
}

impl Supervisor {
    /// At start-up, with or without a valid stored calibration.
    pub fn new(calibrated: bool) -> Supervisor {
        Supervisor {
            mode: RunMode::Idle,
            calibrated,
            sticky: Faults::NONE.set(Faults::NO_CALIBRATION, !calibrated),
            health: Health::default(),
            calibration: ScreenCalibration::new(),
            last: Buttons::default(),
            tick: 0,
        }
    }

    /// Control periods seen.
    pub fn tick(&self) -> u32 {
        self.tick
    }

    /// One period: button levels, the field sensors' raw times and whether
    /// the camera answered.
    pub fn period(&mut self, buttons: Buttons, times: &[u16; 3], camera_ok: bool) -> Plan {
        self.tick = self.tick.wrapping_add(1);
        let a = buttons.a && !self.last.a;
        let b = buttons.b && !self.last.b;
        self.last = buttons;
        let runtime = self.health.update(camera_ok, all_timed_out(times));
        let mut save = None;
        self.mode = match self.mode {
            RunMode::Idle if a && self.calibrated => RunMode::Driving,
            RunMode::Idle if b => {
                self.calibration = ScreenCalibration::new();
                self.sticky = self.sticky.without(Faults::CALIBRATION_FAILED);
                RunMode::Calibrating
            }
            RunMode::Driving if a => RunMode::Idle,
            RunMode::Calibrating if a => RunMode::Idle,
            RunMode::Calibrating => match self.calibration.add(times) {
                Progress::Waiting => RunMode::Calibrating,
                progress => {
                    save = match progress {
                        Progress::Done(c) => Some(c),
                        _ => None,
                    };
                    self.calibrated |= save.is_some();
                    self.sticky = self
                        .sticky
                        .set(Faults::CALIBRATION_FAILED, save.is_none())
                        .set(Faults::NO_CALIBRATION, !self.calibrated);
                    RunMode::Idle
                }
            },
            mode => mode,
        };
        let motors = match self.mode {
            RunMode::Driving if runtime.is_empty() => MotorSource::Policy,
            _ => MotorSource::Stop,
        };
        let blink = |periods: u32| (self.tick / periods) % 2 == 0;
        let leds = Leds {
            yellow: match self.mode {
                RunMode::Driving => true,
                RunMode::Idle => self.calibrated && blink(25),
                RunMode::Calibrating => false,
            },
            green: self.mode == RunMode::Calibrating && (!self.calibration.saw_white() || blink(5)),
            red: if !runtime.is_empty() {
                blink(5)
            } else {
                !self.sticky.is_empty()
            },
        };
        Plan {
            mode: self.mode,
            faults: self.sticky.with(runtime),
            motors,
            save,
            leds,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::config::{CALIBRATION_MIN_SPAN, RC_TIMEOUT_TICKS};

    const SEEN: [u16; 3] = [200, 200, 200];
    const A: Buttons = Buttons { a: true, b: false };
    const B: Buttons = Buttons { a: false, b: true };
    const NONE: Buttons = Buttons { a: false, b: false };

    fn press(s: &mut Supervisor, buttons: Buttons) -> Plan {
        s.period(buttons, &SEEN, true);
        s.period(NONE, &SEEN, true)
    }

    #[test]
    fn without_calibration_a_does_not_drive() {
        let mut s = Supervisor::new(false);
        let p = press(&mut s, A);
        assert_eq!(p.mode, RunMode::Idle);
        assert_eq!(p.motors, MotorSource::Stop);
        assert!(p.faults.contains(Faults::NO_CALIBRATION));
        assert!(p.leds.red);
    }

    #[test]
    fn a_starts_and_stops_on_presses_not_levels() {
        let mut s = Supervisor::new(true);
        assert_eq!(s.period(A, &SEEN, true).motors, MotorSource::Policy);
        // Held: still driving.
        assert_eq!(s.period(A, &SEEN, true).mode, RunMode::Driving);
        s.period(NONE, &SEEN, true);
        let p = press(&mut s, A);
        assert_eq!((p.mode, p.motors), (RunMode::Idle, MotorSource::Stop));
    }

    #[test]
    fn faults_stop_the_motors_until_readings_return() {
        let mut s = Supervisor::new(true);
        press(&mut s, A);
        let mut p = s.period(NONE, &SEEN, false);
        assert_eq!(p.motors, MotorSource::Policy);
        for _ in 0..3 {
            p = s.period(NONE, &[RC_TIMEOUT_TICKS; 3], false);
        }
        assert_eq!(p.motors, MotorSource::Stop);
        assert!(p
            .faults
            .contains(Faults::CAMERA_SILENT.with(Faults::SENSORS_TIMEOUT)));
        assert_eq!(p.mode, RunMode::Driving);
        let p = s.period(NONE, &SEEN, true);
        assert_eq!((p.motors, p.faults), (MotorSource::Policy, Faults::NONE));
    }

    #[test]
    fn white_then_black_calibrates_standing_still_and_enables_driving() {
        let mut s = Supervisor::new(false);
        let mut p = press(&mut s, B);
        assert_eq!(
            (p.mode, p.motors),
            (RunMode::Calibrating, MotorSource::Stop)
        );
        assert!(p.leds.green);
        let mut periods = 0;
        while p.mode == RunMode::Calibrating {
            let t = if periods < 20 {
                40
            } else {
                40 + CALIBRATION_MIN_SPAN + 50
            };
            p = s.period(NONE, &[t; 3], true);
            assert_eq!(p.motors, MotorSource::Stop);
            periods += 1;
        }
        assert_eq!(periods, 20 + crate::screen_calibration::WINDOW);
        let cal = p.save.expect("a calibration to save");
        assert_eq!(
            (cal.ranges[0].bright, cal.ranges[0].dark),
            (40, 40 + CALIBRATION_MIN_SPAN + 50)
        );
        assert!(p.faults.is_empty());
        assert_eq!(press(&mut s, A).mode, RunMode::Driving);
    }

    #[test]
    fn a_calibration_that_never_sees_black_fails_and_keeps_the_old_state() {
        let mut s = Supervisor::new(false);
        let mut p = press(&mut s, B);
        while p.mode == RunMode::Calibrating {
            p = s.period(NONE, &SEEN, true);
        }
        assert_eq!(p.save, None);
        assert!(p
            .faults
            .contains(Faults::CALIBRATION_FAILED.with(Faults::NO_CALIBRATION)));
        assert_eq!(press(&mut s, A).mode, RunMode::Idle);
    }

    #[test]
    fn a_aborts_a_calibration() {
        let mut s = Supervisor::new(true);
        press(&mut s, B);
        let p = press(&mut s, A);
        assert_eq!(
            (p.mode, p.save, p.faults),
            (RunMode::Idle, None, Faults::NONE)
        );
    }
}
