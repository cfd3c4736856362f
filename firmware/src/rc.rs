//! RC discharge timing of the three field sensors, polled together.
//!
//! The board charges the sensors, turns their pins into inputs, records
//! the timer, then calls [`Discharge::sample`] with the timer and the pins
//! that read low until it returns true. A sensor's time is the timer ticks
//! from the start to the first sample that saw its pin low (as Pololu's
//! `QTRSensorsRC` reads it); one never seen low before [`RC_TIMEOUT_TICKS`]
//! reads the timeout. The timer is a free-running 16-bit counter; wrapping
//! is handled.
//!
//! The poll loop only records, and only when a sensor is seen low for the
//! first time: each record adds at least one sensor to the set seen, so
//! there are at most three, and a pin that glitches (low, high, low ...)
//! can never use up another sensor's record. The times are worked out
//! after the loop ([`Discharge::times`]), so a slow update never delays the
//! detection of the next pin.

use crate::config::RC_TIMEOUT_TICKS;

/// Bit of each sensor in the "pins low" mask: left, mid, right.
pub const SENSOR_BITS: [u8; 3] = [1, 2, 4];
const ALL: u8 = 0b111;

/// One discharge measurement in progress.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Discharge {
    start: u16,
    /// Sensors seen low at least once.
    seen: u8,
    /// The timer when sensors were first seen low, with those sensors' bits.
    firsts: [(u16, u8); 3],
    count: u8,
}

impl Discharge {
    /// Starts timing at timer value `now`.
    pub const fn start(now: u16) -> Discharge {
        Discharge {
            start: now,
            seen: 0,
            firsts: [(0, 0); 3],
            count: 0,
        }
    }

    /// Records one sample: `now` is the timer, bit i of `low` is set when
    /// sensor i's pin reads low. Returns true when every sensor has been
    /// seen low or the timeout has passed.
    #[inline(always)]
    pub fn sample(&mut self, now: u16, low: u8) -> bool {
        let newly = low & !self.seen & ALL;
        if newly != 0 {
            if let Some(first) = self.firsts.get_mut(usize::from(self.count)) {
                *first = (now, newly);
                self.count += 1;
            }
            self.seen |= newly;
        }
        self.seen == ALL || now.wrapping_sub(self.start) >= RC_TIMEOUT_TICKS
    }

    /// The times so far: final once [`Discharge::sample`] returned true. A
    /// sensor first seen low at or after the timeout reads the timeout.
    pub fn times(&self) -> [u16; 3] {
        let mut times = [RC_TIMEOUT_TICKS; 3];
        for &(now, bits) in self.firsts.iter().take(usize::from(self.count)) {
            let elapsed = now.wrapping_sub(self.start);
            if elapsed >= RC_TIMEOUT_TICKS {
                continue;
            }
            for (time, bit) in times.iter_mut().zip(SENSOR_BITS) {
                if bits & bit != 0 {
                    *time = elapsed;
                }
            }
        }
        times
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
    fn glitches_never_cost_another_sensor_its_reading() {
        let mut d = Discharge::start(0);
        // The left pin flickers low and high for a while: it counts once, at its first low.
        for t in 1..40u16 {
            assert!(!d.sample(t, u8::from(t % 2 == 0)));
        }
        // The mid and right sensors still get their own times.
        assert!(!d.sample(50, 0b010));
        assert!(!d.sample(60, 0b000));
        assert!(d.sample(70, 0b100));
        assert_eq!(d.times(), [2, 50, 70]);
        // Pins reading low together share one record.
        let mut d = Discharge::start(0);
        assert!(d.sample(9, 0b111));
        assert_eq!(d.times(), [9; 3]);
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
