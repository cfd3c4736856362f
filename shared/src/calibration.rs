//! Field calibration: an RC discharge time -> a calibrated [`FieldValue`].
//!
//! The robot's field sensors are photo-transistors read by RC discharge
//! timing: a brighter projection discharges faster, so a *shorter* time
//! means a *higher* field value. A calibration stores, per sensor, the
//! shortest time seen (`bright`, the brightest spot of the field) and the
//! longest (`dark`). A time maps linearly onto [0, 1]:
//!
//! `value = (dark - clamp(t, bright, dark)) / (dark - bright)`
//!
//! The firmware runs this on every decision, so it is integer-only with no
//! division per reading: [`SensorScale::new`] precomputes a 16-bit
//! reciprocal of the span once per calibration (its one 32-bit division is
//! off the decision path), and [`SensorScale::value`] is a subtraction, a
//! 16 x 16 -> 32-bit multiply and a shift. The result is the exact quotient
//! rounded down, or at most 2 steps of 1/32768 above it (never below), with
//! both ends exact: `bright` reads 1.0, `dark` reads 0.0. The simulator
//! models the photo-transistors with this same code.
//!
//! Times are in the robot's timer ticks (`docs/firmware.md` gives the tick
//! length); nothing here depends on the unit.

use crate::field::FieldValue;
use serde::{Deserialize, Serialize};

/// Length of one tick of the robot's RC timer in microseconds (Timer3 at
/// clk/64, 16 MHz): the resolution of a discharge time. The firmware times
/// the sensors in these ticks and the simulator's photo-transistor model
/// quantises to them.
pub const RC_TICK_US: u16 = 4;
/// Discharge timeout, 2000 us as in Pololu's Zumo library: a sensor still
/// high after this many ticks reads exactly this value.
pub const RC_TIMEOUT_TICKS: u16 = 2_000 / RC_TICK_US;

/// Index of each field sensor in the arrays of this module and of log frames.
pub const LEFT: usize = 0;
/// See [`LEFT`].
pub const MID: usize = 1;
/// See [`LEFT`].
pub const RIGHT: usize = 2;

/// One sensor's calibration: the discharge times of the brightest and the
/// darkest field values it saw.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub struct SensorRange {
    /// Shortest time seen, read as 1.0.
    pub bright: u16,
    /// Longest time seen, read as 0.0.
    pub dark: u16,
}

impl SensorRange {
    /// A range, or `None` unless `dark` exceeds `bright` by at least
    /// `min_span` (and by at least 1): a narrower range means the sensor
    /// never saw the field's contrast, and its values would be noise.
    pub const fn new(bright: u16, dark: u16, min_span: u16) -> Option<SensorRange> {
        if dark > bright && dark - bright >= min_span {
            Some(SensorRange { bright, dark })
        } else {
            None
        }
    }

    /// `dark - bright`, saturating at 0 for an invalid range.
    pub const fn span(self) -> u16 {
        self.dark.saturating_sub(self.bright)
    }
}

/// A [`SensorRange`] with its reciprocal precomputed: what the decision
/// path uses.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct SensorScale {
    dark: u16,
    span: u16,
    /// `ceil(2^(15 + shift) / span)`, in `(2^14, 2^15]`.
    recip: u16,
    /// `floor(log2(span))`.
    shift: u8,
}

impl SensorScale {
    /// Precomputes the scale of a range. A range with `dark <= bright`
    /// (which [`SensorRange::new`] never builds) is treated as a span of 1.
    pub const fn new(range: SensorRange) -> SensorScale {
        let span = if range.dark > range.bright { range.dark - range.bright } else { 1 };
        let shift = 15 - span.leading_zeros();
        let numerator = 1u32 << (15 + shift);
        let span32 = span as u32;
        let recip = numerator.div_ceil(span32);
        SensorScale { dark: range.bright.saturating_add(span), span, recip: recip as u16, shift: shift as u8 }
    }

    /// The calibrated field value of a discharge time: 1.0 at or below
    /// `bright`, 0.0 at or above `dark`, linear in between.
    pub const fn value(&self, time: u16) -> FieldValue {
        // Distance from the dark end, clamped to 0..=span.
        let d = if time >= self.dark {
            0
        } else {
            let d = self.dark - time;
            if d > self.span {
                self.span
            } else {
                d
            }
        };
        // floor(d x recip / 2^shift), computed as (d << (15 - shift)) x recip
        // / 2^15: d < 2^(shift+1), so the shifted d fits in 16 bits, and the
        // AVR shifts a 16-bit value by a variable amount and a 32-bit one by
        // a constant, both cheaper than a variable 32-bit shift. Same result.
        let aligned = d << (15 - self.shift);
        let scaled = (aligned as u32 * self.recip as u32) >> 15;
        if scaled >= FieldValue::ONE.raw() as u32 {
            FieldValue::ONE
        } else {
            FieldValue::from_raw(scaled as u16)
        }
    }
}

/// Calibration of the three field sensors, indexed by [`LEFT`], [`MID`],
/// [`RIGHT`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub struct FieldCalibration {
    /// One range per sensor.
    pub ranges: [SensorRange; 3],
}

impl FieldCalibration {
    /// Precomputes the three scales.
    pub const fn scales(&self) -> FieldScales {
        FieldScales([
            SensorScale::new(self.ranges[LEFT]),
            SensorScale::new(self.ranges[MID]),
            SensorScale::new(self.ranges[RIGHT]),
        ])
    }
}

/// The precomputed scales of a [`FieldCalibration`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct FieldScales(pub [SensorScale; 3]);

impl FieldScales {
    /// Calibrated values of the three sensors' times.
    pub fn values(&self, times: &[u16; 3]) -> [FieldValue; 3] {
        [self.0[LEFT].value(times[LEFT]), self.0[MID].value(times[MID]), self.0[RIGHT].value(times[RIGHT])]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn exact_floor(range: SensorRange, t: u16) -> u32 {
        let t = t.clamp(range.bright, range.dark);
        (u32::from(range.dark - t) << 15) / u32::from(range.span())
    }

    #[test]
    fn ends_are_exact_and_outside_times_clamp() {
        let r = SensorRange::new(120, 480, 1).unwrap();
        let s = SensorScale::new(r);
        assert_eq!(s.value(120), FieldValue::ONE);
        assert_eq!(s.value(0), FieldValue::ONE);
        assert_eq!(s.value(480), FieldValue::ZERO);
        assert_eq!(s.value(u16::MAX), FieldValue::ZERO);
        // midpoint: 180 / 360 = 0.5
        assert_eq!(s.value(300).raw(), 16384);
    }

    #[test]
    fn ranges_need_contrast() {
        assert_eq!(SensorRange::new(100, 100, 1), None);
        assert_eq!(SensorRange::new(100, 90, 1), None);
        assert_eq!(SensorRange::new(100, 120, 25), None);
        assert!(SensorRange::new(100, 125, 25).is_some());
        assert!(SensorRange::new(0, u16::MAX, 1).is_some());
    }

    #[test]
    fn every_time_of_some_spans_is_within_two_steps_above_exact() {
        for (bright, dark) in [(0, 1), (5, 7), (10, 13), (100, 612), (0, 500), (3, 32771), (0, u16::MAX)] {
            let r = SensorRange::new(bright, dark, 1).unwrap();
            let s = SensorScale::new(r);
            for t in bright..=dark {
                let got = u32::from(s.value(t).raw());
                let exact = exact_floor(r, t);
                assert!(got >= exact.min(32768) && got <= exact + 2, "{bright}..{dark} t={t}: {got} vs {exact}");
            }
        }
    }

    #[test]
    fn thesis_example_values_round_trip_through_the_three_scales() {
        let cal = FieldCalibration {
            ranges: [SensorRange { bright: 50, dark: 450 }, SensorRange { bright: 60, dark: 460 }, SensorRange { bright: 40, dark: 440 }],
        };
        let v = cal.scales().values(&[50, 460, 240]);
        assert_eq!(v, [FieldValue::ONE, FieldValue::ZERO, FieldValue::from_raw(16384)]);
    }

    proptest! {
        #[test]
        fn close_to_exact_and_monotone(bright in 0u16..60000, span in 1u16..5000, t in any::<u16>()) {
            let dark = bright.saturating_add(span);
            prop_assume!(dark > bright);
            let r = SensorRange::new(bright, dark, 1).unwrap();
            let s = SensorScale::new(r);
            let got = u32::from(s.value(t).raw());
            let exact = exact_floor(r, t);
            prop_assert!(got >= exact && got <= (exact + 2).min(32768));
            // Darker never reads brighter.
            prop_assert!(s.value(t.saturating_add(1)) <= s.value(t));
        }
    }
}
