//! Calibration from the display's screens: each field sensor's reading on
//! the full-white screen and on the full-black screen, the robot standing
//! still. These are exactly what the simulator's calibration is
//! (`sim::PhotoSensorConfig::calibration`: each sensor's ticks at field 1.0
//! and at 0.0), so a calibrated robot and the simulator turn the same
//! discharge times into the same field values.
//!
//! Button B arms it; then the display's calibration sequence
//! (`host display`: white, black, each held for a while, then the field)
//! does the rest. Every period adds the three raw times to a window of the
//! last [`WINDOW`] periods. A window is *stable* when each sensor's times
//! in it lie within [`stable_tolerance`] of each other; its *plateau* is
//! each sensor's median there. The brightest plateau seen so far (smallest
//! sum of the three medians) is the white candidate; the first plateau at
//! least [`CALIBRATION_MIN_SPAN`] ticks darker than it on every sensor is
//! black, and the pair is the calibration. So the screen that showed
//! before white (the field, usually) and the fades between screens do not
//! matter, and a robot armed while black already shows never calibrates
//! on the field after it: it fails after [`CALIBRATION_PERIODS`]. The
//! sequence must go straight from white to black: a grey screen held
//! between them would count as black.

use crate::config::{CALIBRATION_MIN_SPAN, CALIBRATION_PERIODS};
use shared::{FieldCalibration, SensorRange};

/// Periods in a window (140 ms): a screen must hold at least this long.
pub const WINDOW: usize = 7;

/// What one period of calibration gave.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Progress {
    /// Still waiting for the white or the black screen.
    Waiting,
    /// White and black were seen: the calibration to store.
    Done(FieldCalibration),
    /// No white-then-black sequence within [`CALIBRATION_PERIODS`].
    Failed,
}

/// How far apart a sensor's times in a stable window may lie: 1/16 of
/// their median, at least 2 ticks (a sensor's jitter grows with its time).
pub const fn stable_tolerance(median: u16) -> u16 {
    let t = median / 16;
    if t < 2 {
        2
    } else {
        t
    }
}

/// The calibration in progress.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ScreenCalibration {
    /// The last periods' times, a ring.
    window: [[u16; 3]; WINDOW],
    /// Periods in the window, up to [`WINDOW`].
    filled: u8,
    /// Where the next period goes.
    next: u8,
    /// The brightest plateau so far.
    white: Option<[u16; 3]>,
    periods_left: u16,
}

impl Default for ScreenCalibration {
    fn default() -> ScreenCalibration {
        ScreenCalibration::new()
    }
}

impl ScreenCalibration {
    /// Armed: nothing seen yet.
    pub const fn new() -> ScreenCalibration {
        ScreenCalibration {
            window: [[0; 3]; WINDOW],
            filled: 0,
            next: 0,
            white: None,
            periods_left: CALIBRATION_PERIODS,
        }
    }

    /// Whether a white candidate has been seen.
    pub const fn saw_white(&self) -> bool {
        self.white.is_some()
    }

    /// Adds one period's raw times.
    pub fn add(&mut self, times: &[u16; 3]) -> Progress {
        self.periods_left = self.periods_left.saturating_sub(1);
        if let Some(slot) = self.window.get_mut(usize::from(self.next)) {
            *slot = *times;
        }
        self.next = if usize::from(self.next) + 1 >= WINDOW {
            0
        } else {
            self.next + 1
        };
        self.filled = self.filled.saturating_add(1).min(WINDOW as u8);
        if let Some(plateau) = self.plateau() {
            match self.white {
                Some(white) => {
                    if let Some(calibration) = calibration_of(&white, &plateau) {
                        return Progress::Done(calibration);
                    }
                    if sum(&plateau) < sum(&white) {
                        self.white = Some(plateau);
                    }
                }
                None => self.white = Some(plateau),
            }
        }
        if self.periods_left == 0 {
            Progress::Failed
        } else {
            Progress::Waiting
        }
    }

    /// Each sensor's median over a full, stable window.
    fn plateau(&self) -> Option<[u16; 3]> {
        if usize::from(self.filled) < WINDOW {
            return None;
        }
        let mut plateau = [0u16; 3];
        for (sensor, out) in plateau.iter_mut().enumerate() {
            let mut column = [0u16; WINDOW];
            for (c, row) in column.iter_mut().zip(self.window.iter()) {
                *c = row[sensor];
            }
            insertion_sort(&mut column);
            let median = column[WINDOW / 2];
            if column[WINDOW - 1] - column[0] > stable_tolerance(median) {
                return None;
            }
            *out = median;
        }
        Some(plateau)
    }
}

/// Sorts a window's column (a few bytes of code; `sort_unstable` links a heapsort).
fn insertion_sort(column: &mut [u16; WINDOW]) {
    for i in 1..WINDOW {
        let mut j = i;
        while j > 0 && column[j - 1] > column[j] {
            column.swap(j - 1, j);
            j -= 1;
        }
    }
}

fn sum(times: &[u16; 3]) -> u32 {
    times.iter().map(|t| u32::from(*t)).sum()
}

/// The calibration of a white and a black plateau, if black is at least
/// [`CALIBRATION_MIN_SPAN`] darker on every sensor.
fn calibration_of(white: &[u16; 3], black: &[u16; 3]) -> Option<FieldCalibration> {
    let range = |i: usize| SensorRange::new(white[i], black[i], CALIBRATION_MIN_SPAN);
    Some(FieldCalibration {
        ranges: [range(0)?, range(1)?, range(2)?],
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    const WHITE: [u16; 3] = [38, 40, 43];
    const BLACK: [u16; 3] = [425, 440, 455];
    const FIELD: [u16; 3] = [120, 300, 90];

    fn hold(c: &mut ScreenCalibration, times: [u16; 3], periods: usize) -> Progress {
        let mut last = Progress::Waiting;
        for _ in 0..periods {
            last = c.add(&times);
            if last != Progress::Waiting {
                return last;
            }
        }
        last
    }

    fn expected() -> FieldCalibration {
        FieldCalibration {
            ranges: [0, 1, 2].map(|i| SensorRange {
                bright: WHITE[i],
                dark: BLACK[i],
            }),
        }
    }

    #[test]
    fn white_then_black_gives_each_sensors_two_readings() {
        let mut c = ScreenCalibration::new();
        assert_eq!(hold(&mut c, FIELD, 20), Progress::Waiting);
        assert_eq!(hold(&mut c, WHITE, 10), Progress::Waiting);
        assert!(c.saw_white());
        // Black must hold for a whole window before it counts.
        assert_eq!(hold(&mut c, BLACK, WINDOW - 1), Progress::Waiting);
        assert_eq!(c.add(&BLACK), Progress::Done(expected()));
    }

    #[test]
    fn jitter_within_the_tolerance_reads_as_the_median_and_fades_do_not_count() {
        let mut c = ScreenCalibration::new();
        for i in 0..10u16 {
            c.add(&[WHITE[0] + i % 2, WHITE[1] + (i % 3), WHITE[2]]);
        }
        // A fade: every period darker, never stable.
        for step in 1..=5u16 {
            assert_eq!(c.add(&WHITE.map(|w| w + step * 70)), Progress::Waiting);
        }
        let mut last = Progress::Waiting;
        for i in 0..WINDOW as u16 {
            last = c.add(&[BLACK[0] + i % 3 * 5, BLACK[1], BLACK[2] - i % 2 * 9]);
        }
        let Progress::Done(cal) = last else {
            panic!("{last:?}")
        };
        // The brightest stable window's medians: 38 + {0, 1}: 38 (four 0s), 40 + {0, 1, 2}: 41.
        assert_eq!(
            cal.ranges.map(|r| r.bright),
            [WHITE[0], WHITE[1] + 1, WHITE[2]]
        );
        // Black's medians: 425 + {0, 5, 10, 0, 5, 10, 0} -> 430; 455 - {0, 9, 0, 9, 0, 9, 0} -> 455.
        assert_eq!(
            cal.ranges.map(|r| r.dark),
            [BLACK[0] + 5, BLACK[1], BLACK[2]]
        );
    }

    #[test]
    fn armed_on_black_it_never_calibrates_on_the_field_and_fails_in_time() {
        let mut c = ScreenCalibration::new();
        assert_eq!(hold(&mut c, BLACK, 50), Progress::Waiting);
        let periods = usize::from(CALIBRATION_PERIODS);
        assert_eq!(hold(&mut c, FIELD, periods), Progress::Failed);
    }

    #[test]
    fn a_black_screen_no_darker_than_the_span_on_one_sensor_is_not_black() {
        let mut c = ScreenCalibration::new();
        hold(&mut c, WHITE, 10);
        let dim = [BLACK[0], WHITE[1] + CALIBRATION_MIN_SPAN - 1, BLACK[2]];
        assert_eq!(hold(&mut c, dim, 30), Progress::Waiting);
        assert_eq!(hold(&mut c, BLACK, 30), Progress::Done(expected()));
    }

    #[test]
    fn timeouts_on_black_are_a_valid_dark_reading() {
        let timeout = shared::calibration::RC_TIMEOUT_TICKS;
        let mut c = ScreenCalibration::new();
        hold(&mut c, WHITE, 10);
        let Progress::Done(cal) = hold(&mut c, [timeout; 3], 10) else {
            panic!()
        };
        assert!(cal.ranges.iter().all(|r| r.dark == timeout));
        assert_eq!(stable_tolerance(0), 2);
        assert_eq!(stable_tolerance(440), 27);
    }
}
