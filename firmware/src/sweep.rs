//! A calibration sweep: the shortest and longest time each field sensor
//! sees while the robot turns over the field.

use crate::config::CALIBRATION_MIN_SPAN;
use shared::{FieldCalibration, SensorRange};

/// Extremes seen so far.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Sweep {
    bright: [u16; 3],
    dark: [u16; 3],
}

impl Default for Sweep {
    fn default() -> Sweep {
        Sweep::new()
    }
}

impl Sweep {
    /// Nothing seen yet.
    pub const fn new() -> Sweep {
        Sweep { bright: [u16::MAX; 3], dark: [0; 3] }
    }

    /// Adds one measurement (timeouts included: the darkest spots may be
    /// beyond the timeout).
    pub fn add(&mut self, times: &[u16; 3]) {
        for ((bright, dark), t) in self.bright.iter_mut().zip(self.dark.iter_mut()).zip(times) {
            *bright = (*bright).min(*t);
            *dark = (*dark).max(*t);
        }
    }

    /// The calibration, or `None` if a sensor saw less than
    /// [`CALIBRATION_MIN_SPAN`] ticks of contrast.
    pub fn finish(&self) -> Option<FieldCalibration> {
        let range = |i: usize| SensorRange::new(self.bright[i], self.dark[i], CALIBRATION_MIN_SPAN);
        Some(FieldCalibration { ranges: [range(0)?, range(1)?, range(2)?] })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn extremes_per_sensor() {
        let mut s = Sweep::new();
        assert_eq!(s.finish(), None);
        s.add(&[100, 200, 300]);
        s.add(&[400, 50, 500]);
        s.add(&[250, 250, 250]);
        let c = s.finish().unwrap();
        assert_eq!(c.ranges.map(|r| (r.bright, r.dark)), [(100, 400), (50, 250), (250, 500)]);
    }

    #[test]
    fn too_little_contrast_on_one_sensor_fails() {
        let mut s = Sweep::new();
        s.add(&[100, 200, 300]);
        s.add(&[400, 500, 310]);
        assert_eq!(s.finish(), None);
    }
}
