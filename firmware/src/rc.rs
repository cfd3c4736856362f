//! RC discharge timing of the three field sensors, polled together.
//!
//! The board charges the sensors, turns their pins into inputs, records
//! the timer, then calls [`Discharge::sample`] with the timer and the pins
//! that read low until it returns true. A sensor's time is the timer ticks
//! from the start to the first sample that saw its pin low; one still high
//! at [`RC_TIMEOUT_TICKS`] reads the timeout. The timer is a free-running
//! 16-bit counter; wrapping is handled.

use crate::config::RC_TIMEOUT_TICKS;

/// Bit of each sensor in the "pins low" mask: left, mid, right.
pub const SENSOR_BITS: [u8; 3] = [1, 2, 4];
const ALL: u8 = 0b111;

/// One discharge measurement in progress.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Discharge {
    start: u16,
    times: [u16; 3],
    pending: u8,
}

impl Discharge {
    /// Starts timing at timer value `now`.
    pub const fn start(now: u16) -> Discharge {
        Discharge { start: now, times: [RC_TIMEOUT_TICKS; 3], pending: ALL }
    }

    /// Records one sample: `now` is the timer, bit i of `low` is set when
    /// sensor i's pin reads low. Returns true when every sensor has
    /// discharged or the timeout has passed.
    pub fn sample(&mut self, now: u16, low: u8) -> bool {
        let elapsed = now.wrapping_sub(self.start);
        if elapsed >= RC_TIMEOUT_TICKS {
            self.pending = 0;
            return true;
        }
        let newly = low & self.pending;
        for (time, bit) in self.times.iter_mut().zip(SENSOR_BITS) {
            if newly & bit != 0 {
                *time = elapsed;
            }
        }
        self.pending &= !newly;
        self.pending == 0
    }

    /// The times so far: final once [`Discharge::sample`] returned true.
    pub const fn times(&self) -> [u16; 3] {
        self.times
    }
}

/// Whether every sensor of a measurement timed out.
pub fn all_timed_out(times: &[u16; 3]) -> bool {
    times.iter().all(|t| *t >= RC_TIMEOUT_TICKS)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn each_sensor_keeps_its_first_low_sample() {
        let mut d = Discharge::start(1000);
        assert!(!d.sample(1010, 0));
        assert!(!d.sample(1020, 0b010));
        assert!(!d.sample(1030, 0b011));
        assert!(d.sample(1040, 0b111));
        assert_eq!(d.times(), [30, 20, 40]);
        assert!(!all_timed_out(&d.times()));
    }

    #[test]
    fn timer_wrap_and_timeout() {
        let mut d = Discharge::start(65530);
        assert!(!d.sample(4, 0b100));
        assert!(d.sample(65530u16.wrapping_add(RC_TIMEOUT_TICKS), 0b011));
        assert_eq!(d.times(), [RC_TIMEOUT_TICKS, RC_TIMEOUT_TICKS, 10]);
        let mut d = Discharge::start(0);
        assert!(d.sample(RC_TIMEOUT_TICKS + 7, 0));
        assert!(all_timed_out(&d.times()));
    }
}
