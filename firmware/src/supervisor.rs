//! The robot's modes, buttons, faults and LEDs, one control period at a time.
//!
//! - Button A starts and stops driving; it starts only with a valid
//!   calibration.
//! - Button B (while not driving) starts a calibration sweep: the robot
//!   spins in place for [`CALIBRATION_PERIODS`] periods, recording each
//!   sensor's extremes, then saves them (or flags the failure). A during a
//!   sweep aborts it.
//! - While driving, any runtime fault ([`Health`]) stops the motors until
//!   the readings return.
//!
//! LEDs: yellow on = driving, yellow blinking (1 Hz) = ready; green on =
//! calibrating; red blinking (5 Hz) = camera or sensor fault; red steady =
//! no valid calibration (missing, corrupt, or the last sweep failed).

use crate::config::CALIBRATION_PERIODS;
use crate::health::Health;
use crate::rc::all_timed_out;
use crate::sweep::Sweep;
use shared::{FieldCalibration, Faults, RunMode};

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
    /// The calibration spin.
    Spin,
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
    sweep: Sweep,
    sweep_left: u16,
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
            sweep: Sweep::new(),
            sweep_left: 0,
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
                self.sweep = Sweep::new();
                self.sweep_left = CALIBRATION_PERIODS;
                self.sticky = self.sticky.without(Faults::CALIBRATION_FAILED);
                RunMode::Calibrating
            }
            RunMode::Driving if a => RunMode::Idle,
            RunMode::Calibrating if a => RunMode::Idle,
            RunMode::Calibrating => {
                self.sweep.add(times);
                self.sweep_left = self.sweep_left.saturating_sub(1);
                if self.sweep_left > 0 {
                    RunMode::Calibrating
                } else {
                    save = self.sweep.finish();
                    self.calibrated |= save.is_some();
                    self.sticky = self
                        .sticky
                        .set(Faults::CALIBRATION_FAILED, save.is_none())
                        .set(Faults::NO_CALIBRATION, !self.calibrated);
                    RunMode::Idle
                }
            }
            mode => mode,
        };
        let motors = match self.mode {
            RunMode::Driving if runtime.is_empty() => MotorSource::Policy,
            RunMode::Calibrating => MotorSource::Spin,
            _ => MotorSource::Stop,
        };
        let blink = |periods: u32| (self.tick / periods) % 2 == 0;
        let leds = Leds {
            yellow: match self.mode {
                RunMode::Driving => true,
                RunMode::Idle => self.calibrated && blink(25),
                RunMode::Calibrating => false,
            },
            green: self.mode == RunMode::Calibrating,
            red: if !runtime.is_empty() { blink(5) } else { !self.sticky.is_empty() },
        };
        Plan { mode: self.mode, faults: self.sticky.with(runtime), motors, save, leds }
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
        assert!(p.faults.contains(Faults::CAMERA_SILENT.with(Faults::SENSORS_TIMEOUT)));
        assert_eq!(p.mode, RunMode::Driving);
        let p = s.period(NONE, &SEEN, true);
        assert_eq!((p.motors, p.faults), (MotorSource::Policy, Faults::NONE));
    }

    #[test]
    fn a_sweep_calibrates_and_enables_driving() {
        let mut s = Supervisor::new(false);
        let mut p = press(&mut s, B);
        assert_eq!((p.mode, p.motors), (RunMode::Calibrating, MotorSource::Spin));
        assert!(p.leds.green);
        let mut n = 1;
        while p.mode == RunMode::Calibrating {
            let t = 100 + (n % 2) * (CALIBRATION_MIN_SPAN + 50);
            p = s.period(NONE, &[t; 3], true);
            n += 1;
        }
        assert_eq!(n, CALIBRATION_PERIODS);
        let cal = p.save.expect("a calibration to save");
        assert_eq!(cal.ranges[0].bright, 100);
        assert!(p.faults.is_empty());
        assert_eq!(press(&mut s, A).mode, RunMode::Driving);
    }

    #[test]
    fn a_sweep_without_contrast_fails_and_keeps_the_old_state() {
        let mut s = Supervisor::new(false);
        let mut p = press(&mut s, B);
        while p.mode == RunMode::Calibrating {
            p = s.period(NONE, &SEEN, true);
        }
        assert_eq!(p.save, None);
        assert!(p.faults.contains(Faults::CALIBRATION_FAILED.with(Faults::NO_CALIBRATION)));
        assert_eq!(press(&mut s, A).mode, RunMode::Idle);
    }
}
