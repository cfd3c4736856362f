//! Field calibration: an RC discharge time -> the field value the screen
//! showed there ([`FieldValue`]).
//!
//! The robot's field sensors are photo-transistors read by RC discharge
//! timing. The chain from the field value `v` a pixel shows to the time:
//! the screen's light is `L = v ^ LIGHT_GAMMA` of full white (a display's
//! light curve; the display page pre-compensates a TV whose own gamma
//! differs, so the light curve is this one), the photo-transistor's
//! current is proportional to light plus a dark current, and the capacitor
//! discharges at that current, so `1/t = 1/t_dark + L (1/t_bright -
//! 1/t_dark)`: brighter is faster, `t_bright` on a full-white screen and
//! `t_dark` on a full-black one. A calibration stores, per sensor, exactly
//! those two times ([`SensorRange`]), and the calibrated value inverts the
//! chain: `L = (t_dark - t) t_bright / (t (t_dark - t_bright))`, `v = L ^
//! (1 / LIGHT_GAMMA)`.
//!
//! The firmware runs this on every decision, so it is integer-only with no
//! division or multiplication per reading: [`SensorCurve::calibrate`]
//! computes, once per calibration, the field value at every 8th tick from
//! the bright time on ([`CURVE_STEP_TICKS`]; the light curve inverted
//! through the integer table [`LIGHT_AT`]), and [`SensorCurve::value`]
//! interpolates between the two knots around a reading with a subtraction,
//! shifts and three conditional additions. The knots are exact to the
//! light table, `t_bright` reads exactly 1.0 and `t_dark` (and longer)
//! 0.0; between knots the straight pieces stay within 0.017 of the curve,
//! the most at field values below 0.05 where the light curve is steepest.
//! With whole-tick readings and calibrations the result is within
//! [`CURVE_TOLERANCE`] of the field value for the default responses
//! (`tests` below).
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

/// One sensor's calibration: its discharge times on a full-white screen
/// (field 1.0) and on a full-black one (field 0.0).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub struct SensorRange {
    /// Time on full white, read as 1.0.
    pub bright: u16,
    /// Time on full black, read as 0.0.
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

/// A linear map of a time range onto [0, 1] with its reciprocal
/// precomputed: one piece of a [`SensorCurve`]. The result is the exact
/// quotient rounded down, or at most 2 steps of 1/32768 above it (never
/// below), with both ends exact.
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
        let span = if range.dark > range.bright {
            range.dark - range.bright
        } else {
            1
        };
        let shift = 15 - span.leading_zeros();
        let numerator = 1u32 << (15 + shift);
        let span32 = span as u32;
        let recip = numerator.div_ceil(span32);
        SensorScale {
            dark: range.bright.saturating_add(span),
            span,
            recip: recip as u16,
            shift: shift as u8,
        }
    }

    /// 1.0 at or below `bright`, 0.0 at or above `dark`, linear in between.
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

/// The display's light curve: light is `v ^ LIGHT_GAMMA` of full white.
pub const LIGHT_GAMMA: f32 = 2.2;

/// Ticks between a curve's knots (a power of two).
pub const CURVE_STEP_TICKS: u16 = 8;

/// Knots of a curve: enough for times from `bright` to the RC timeout.
pub const CURVE_KNOTS: usize = 64;

/// The light at field values `k / 32`, `(k / 32) ^ LIGHT_GAMMA` of full
/// white, in units of 2^-14 (rounded): the light curve the calibration inverts.
pub const LIGHT_AT: [u16; 33] = [
    0, 8, 37, 90, 169, 276, 412, 579, 776, 1006, 1268, 1564, 1894, 2258, 2658, 3094, 3566, 4075,
    4621, 5204, 5826, 6486, 7185, 7923, 8701, 9518, 10376, 11274, 12213, 13194, 14215, 15279,
    16384,
];

/// How far a calibrated value may lie from the field value shown, for the
/// simulator's default responses with whole-tick readings and calibrations
/// (0.021 at worst, near black, where the light curve is steepest).
pub const CURVE_TOLERANCE: f32 = 0.025;

/// One sensor's calibrated curve: the field value at every
/// [`CURVE_STEP_TICKS`]th tick from its bright time, up to its dark time
/// (132 bytes, so that the firmware keeps three of them in RAM).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct SensorCurve {
    /// The bright time, ticks: reads 1.0, and so does anything shorter.
    bright: u16,
    /// The dark time, ticks: reads 0.0, and so does anything longer.
    dark: u16,
    /// `knots[j]`: the field value at `bright + 8 j` ticks, raw Q15;
    /// non-increasing; the knot after the last one before `dark` is 0 and
    /// stands for `dark` itself.
    knots: [u16; CURVE_KNOTS],
}

/// `EIGHTHS[m - 1][r]`: `r` ticks into a last piece of `m` ticks, in
/// eighths of it (rounded down), for the piece that ends at the dark time.
const EIGHTHS: [[u8; 8]; 8] = {
    let mut table = [[0u8; 8]; 8];
    let mut m = 1;
    while m <= 8 {
        let mut r = 0;
        while r < m {
            table[m - 1][r] = (r * 8 / m) as u8;
            r += 1;
        }
        m += 1;
    }
    table
};

impl SensorCurve {
    /// A curve that reads every time as 0.0, to be calibrated.
    pub const UNSET: SensorCurve = SensorCurve {
        bright: 0,
        dark: 0,
        knots: [0; CURVE_KNOTS],
    };

    /// The curve of a calibration range (a `bright` of 0 counts as 1 tick,
    /// a `dark` at or below `bright` as one tick above it; times beyond the
    /// RC timeout as the timeout).
    pub fn new(range: SensorRange) -> SensorCurve {
        let mut curve = SensorCurve::UNSET;
        curve.calibrate(range);
        curve
    }

    /// Recomputes this curve for a calibration range, in place (the
    /// firmware has no stack to spare for a copy, nor flash for three
    /// inlined copies of this).
    #[inline(never)]
    pub fn calibrate(&mut self, range: SensorRange) {
        let bright = range.bright.clamp(1, RC_TIMEOUT_TICKS - 1);
        let dark = range.dark.min(RC_TIMEOUT_TICKS).max(bright + 1);
        self.bright = bright;
        self.dark = dark;
        let (bright, dark) = (u32::from(bright), u32::from(dark));
        for (j, knot) in self.knots.iter_mut().enumerate() {
            let t = bright + j as u32 * u32::from(CURVE_STEP_TICKS);
            *knot = if t >= dark {
                0
            } else {
                // The light of time t, 2^-14 of full white: (t_d - t) t_b /
                // (t (t_d - t_b)); t_b t_d < 2^18, so the shifted numerator fits.
                let light = (((dark - t) * bright) << 14) / (t * (dark - bright));
                field_of_light(light.min(16_384) as u16)
            };
        }
    }

    /// The calibrated field value of a discharge time in whole ticks: 1.0
    /// at or below the bright time, 0.0 at or above the dark time.
    #[inline(never)]
    pub fn value(&self, ticks: u16) -> FieldValue {
        if ticks <= self.bright {
            return FieldValue::ONE;
        }
        if ticks >= self.dark {
            return FieldValue::ZERO;
        }
        let past = ticks - self.bright;
        let j = usize::from(past >> 3).min(CURVE_KNOTS - 2);
        // Linear between knots j and j + 1, in eighths of the piece; the
        // last piece ends at the dark time, fewer than 8 ticks on.
        let start = past & !7;
        let left = self.dark - self.bright - start;
        let eighths = if left < CURVE_STEP_TICKS {
            EIGHTHS[usize::from(left - 1) & 7][usize::from(past & 7)]
        } else {
            (past & 7) as u8
        };
        let (upper, lower) = (self.knots[j], self.knots[j + 1]);
        let drop = u32::from(upper.saturating_sub(lower));
        let mut fall = 0u32;
        if eighths & 1 != 0 {
            fall += drop;
        }
        if eighths & 2 != 0 {
            fall += drop << 1;
        }
        if eighths & 4 != 0 {
            fall += drop << 2;
        }
        FieldValue::from_raw(upper - (fall >> 3) as u16)
    }
}

/// The field value (raw Q15) whose light is `light` (2^-14 of full white):
/// [`LIGHT_AT`] inverted, linear between its entries.
fn field_of_light(light: u16) -> u16 {
    // The last entry at or below the light (a binary search of 33 entries).
    let mut k = 0;
    let mut step = 16;
    while step > 0 {
        if LIGHT_AT[k + step] <= light {
            k += step;
        }
        step /= 2;
    }
    if k == 32 {
        return FieldValue::ONE.raw();
    }
    let (low, high) = (u32::from(LIGHT_AT[k]), u32::from(LIGHT_AT[k + 1]));
    let within = (u32::from(light) - low) * 1024 / (high - low);
    (k as u32 * 1024 + within) as u16
}

/// Calibration of the three field sensors, indexed by [`LEFT`], [`MID`],
/// [`RIGHT`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub struct FieldCalibration {
    /// One range per sensor.
    pub ranges: [SensorRange; 3],
}

impl FieldCalibration {
    /// The three sensors' curves (computed once per calibration).
    pub fn scales(&self) -> FieldScales {
        let mut scales = FieldScales::UNSET;
        scales.calibrate(self);
        scales
    }
}

/// The curves of a [`FieldCalibration`]: what the decision path uses.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct FieldScales(pub [SensorCurve; 3]);

impl FieldScales {
    /// Curves that read every time as 0.0, to be calibrated.
    pub const UNSET: FieldScales = FieldScales([SensorCurve::UNSET; 3]);

    /// Recomputes the three curves for a calibration, in place.
    pub fn calibrate(&mut self, calibration: &FieldCalibration) {
        for (curve, range) in self.0.iter_mut().zip(calibration.ranges) {
            curve.calibrate(range);
        }
    }

    /// Calibrated values of the three sensors' times.
    pub fn values(&self, times: &[u16; 3]) -> [FieldValue; 3] {
        [
            self.0[LEFT].value(times[LEFT]),
            self.0[MID].value(times[MID]),
            self.0[RIGHT].value(times[RIGHT]),
        ]
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
        for (bright, dark) in [
            (0, 1),
            (5, 7),
            (10, 13),
            (100, 612),
            (0, 500),
            (3, 32771),
            (0, u16::MAX),
        ] {
            let r = SensorRange::new(bright, dark, 1).unwrap();
            let s = SensorScale::new(r);
            for t in bright..=dark {
                let got = u32::from(s.value(t).raw());
                let exact = exact_floor(r, t);
                assert!(
                    got >= exact.min(32768) && got <= exact + 2,
                    "{bright}..{dark} t={t}: {got} vs {exact}"
                );
            }
        }
    }

    extern crate std;

    /// The simulator's default responses (us) and the firmware's polling
    /// latency, as `sim::photo_sensors` models them.
    const RESPONSES: [(f64, f64); 3] = [(150.0, 1700.0), (160.0, 1760.0), (170.0, 1820.0)];
    const LATENCY_US: f64 = 2.8;

    fn ticks(us: f64) -> u16 {
        ((us + LATENCY_US) / f64::from(RC_TICK_US)).floor() as u16
    }

    /// The model's discharge time of field value `v`, us.
    fn discharge_us(v: f64, (bright, dark): (f64, f64)) -> f64 {
        let light = v.powf(f64::from(LIGHT_GAMMA));
        1.0 / (1.0 / dark + light * (1.0 / bright - 1.0 / dark))
    }

    #[test]
    fn the_light_table_is_the_light_curve_and_inverts_to_its_field_values() {
        for (k, &l) in LIGHT_AT.iter().enumerate() {
            let exact = (k as f64 / 32.0).powf(f64::from(LIGHT_GAMMA)) * 16_384.0;
            assert_eq!(f64::from(l), exact.round(), "entry {k}");
            assert_eq!(field_of_light(l), (k as u16 * 1024).min(32768), "entry {k}");
        }
        // Linear between entries: within 0.009 below field 1/32 (light 8),
        // where the curve is steepest, 0.0035 up to 1/16, 0.0025 above.
        for l in 0..=16_384u16 {
            let exact = (f64::from(l) / 16_384.0).powf(1.0 / f64::from(LIGHT_GAMMA));
            let got = f64::from(field_of_light(l)) / 32_768.0;
            let tolerance = match l {
                l if l < LIGHT_AT[1] => 0.009,
                l if l < LIGHT_AT[2] => 0.0035,
                _ => 0.0025,
            };
            assert!(
                (got - exact).abs() < tolerance,
                "light {l}: {got} vs {exact}"
            );
        }
    }

    #[test]
    fn white_reads_one_black_reads_zero_and_outside_times_clamp() {
        let curve = SensorCurve::new(SensorRange {
            bright: 38,
            dark: 425,
        });
        assert_eq!(curve.value(38), FieldValue::ONE);
        assert_eq!(curve.value(0), FieldValue::ONE);
        assert_eq!(curve.value(425), FieldValue::ZERO);
        assert_eq!(curve.value(u16::MAX), FieldValue::ZERO);
        // The uncalibrated range and a range without contrast never panic.
        let _ = SensorCurve::new(SensorRange {
            bright: 0,
            dark: RC_TIMEOUT_TICKS,
        })
        .value(100);
        assert_eq!(
            SensorCurve::new(SensorRange {
                bright: 90,
                dark: 90
            })
            .value(95),
            FieldValue::ZERO
        );
    }

    #[test]
    fn the_calibrated_value_is_the_field_value_within_the_tolerance_across_0_to_1() {
        for response in RESPONSES {
            let range = SensorRange {
                bright: ticks(response.0),
                dark: ticks(response.1),
            };
            let curve = SensorCurve::new(range);
            let mut worst = 0.0f64;
            for i in 0..=1000 {
                let v = f64::from(i) / 1000.0;
                let got = f64::from(curve.value(ticks(discharge_us(v, response))).to_f32());
                worst = worst.max((got - v).abs());
            }
            assert!(
                worst <= f64::from(CURVE_TOLERANCE),
                "{response:?}: off by up to {worst:.4}"
            );
        }
        // The old linear map of times was off by 0.2 at 0.6 (a calibrated
        // 0.6 was a field value of about 0.38): now 0.6 reads 0.6.
        let range = SensorRange {
            bright: ticks(160.0),
            dark: ticks(1760.0),
        };
        let at_06 = f64::from(
            SensorCurve::new(range)
                .value(ticks(discharge_us(0.6, (160.0, 1760.0))))
                .to_f32(),
        );
        assert!((at_06 - 0.6).abs() < 0.01, "{at_06}");
    }

    #[test]
    fn the_three_sensors_use_their_own_curves() {
        let cal = FieldCalibration {
            ranges: [
                SensorRange {
                    bright: 50,
                    dark: 450,
                },
                SensorRange {
                    bright: 60,
                    dark: 460,
                },
                SensorRange {
                    bright: 40,
                    dark: 440,
                },
            ],
        };
        let v = cal.scales().values(&[50, 460, 240]);
        assert_eq!((v[0], v[1]), (FieldValue::ONE, FieldValue::ZERO));
        assert_eq!(v[2], SensorCurve::new(cal.ranges[2]).value(240));
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

        #[test]
        fn a_curve_never_reads_a_darker_time_brighter(bright in any::<u16>(), dark in any::<u16>(), t in 0u16..5000) {
            let curve = SensorCurve::new(SensorRange { bright, dark });
            prop_assert!(curve.value(t + 1) <= curve.value(t));
            prop_assert!(curve.value(t) <= FieldValue::ONE);
        }
    }
}
