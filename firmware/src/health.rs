//! Fault detection: a silent camera or blind field sensors stop the robot.
//!
//! A fault is raised after [`FAULT_PERIODS`] bad control periods in a row
//! (one glitch is not a fault) and cleared by the first good period, so
//! the robot resumes as soon as readings return. "Blind" means every field
//! sensor timed out: one sensor may legitimately time out over a dark part
//! of the field, but all three at once mean the sensor board is
//! unplugged, the robot was lifted, or the projector is off.

use crate::config::FAULT_PERIODS;
use shared::Faults;

/// Consecutive bad periods per fault.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Health {
    camera_bad: u8,
    sensors_bad: u8,
}

impl Health {
    /// Records one period; returns the active runtime faults.
    pub fn update(&mut self, camera_ok: bool, sensors_timed_out: bool) -> Faults {
        self.camera_bad = if camera_ok {
            0
        } else {
            self.camera_bad.saturating_add(1)
        };
        self.sensors_bad = if sensors_timed_out {
            self.sensors_bad.saturating_add(1)
        } else {
            0
        };
        Faults::NONE
            .set(Faults::CAMERA_SILENT, self.camera_bad >= FAULT_PERIODS)
            .set(Faults::SENSORS_TIMEOUT, self.sensors_bad >= FAULT_PERIODS)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn faults_need_consecutive_bad_periods_and_clear_at_once() {
        let mut h = Health::default();
        for _ in 1..FAULT_PERIODS {
            assert_eq!(h.update(false, true), Faults::NONE);
        }
        assert_eq!(
            h.update(false, true),
            Faults::CAMERA_SILENT.with(Faults::SENSORS_TIMEOUT)
        );
        assert_eq!(h.update(true, true), Faults::SENSORS_TIMEOUT);
        assert_eq!(h.update(true, false), Faults::NONE);
        assert_eq!(h.update(false, false), Faults::NONE);
    }
}
