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
//! division per reading: [`SensorCurve::new`] computes, once per
//! calibration, the time of each of the 17 field values `k / 16` (in 1/16
//! of a tick, from the integer light table [`LIGHT_AT_KNOT`]) and each
//! piece's reciprocal; [`SensorCurve::value`] finds the piece with four
//! comparisons and interpolates it with a subtraction, a 16 x 16 -> 32-bit
//! multiply and shifts ([`SensorScale`]). The knots are exact, so `t_bright`
//! reads 1.0 and `t_dark` reads 0.0; between knots the straight pieces
//! stay within 0.002 of the curve above field 1/8, 0.005 between 1/16 and
//! 1/8, and 0.018 below 1/16, where the light curve is steepest. With
//! whole-tick readings and calibrations the result is within
//! [`CURVE_TOLERANCE`] of the field value for the default responses
//! (`tests` below). The simulator models the
//! photo-transistors with this same code.
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
        let span = if range.dark > range.bright { range.dark - range.bright } else { 1 };
        let shift = 15 - span.leading_zeros();
        let numerator = 1u32 << (15 + shift);
        let span32 = span as u32;
        let recip = numerator.div_ceil(span32);
        SensorScale { dark: range.bright.saturating_add(span), span, recip: recip as u16, shift: shift as u8 }
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

/// Pieces of a sensor's curve: field values `k / 16` are its knots.
pub const CURVE_SEGMENTS: usize = 16;

/// The light at each knot, `(k / 16) ^ LIGHT_GAMMA` of full white, in
/// units of 2^-14 (rounded).
pub const LIGHT_AT_KNOT: [u16; CURVE_SEGMENTS + 1] =
    [0, 37, 169, 412, 776, 1268, 1894, 2658, 3566, 4621, 5826, 7185, 8701, 10376, 12213, 14215, 16384];

/// The longest calibration time a curve takes, ticks (the RC timeout is 500).
pub const MAX_CURVE_TICKS: u16 = 1023;

/// How far a calibrated value may lie from the field value shown, for the
/// simulator's default responses with whole-tick readings and calibrations
/// (the largest error is near full white, where a tick spans the most field).
pub const CURVE_TOLERANCE: f32 = 0.025;

/// One sensor's calibrated curve: times of the 17 knots and each piece's
/// reciprocal (82 bytes, so that the firmware keeps three of them in RAM).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct SensorCurve {
    /// Time of field value `k / 16`, in 1/16 tick; non-increasing in `k`
    /// (`knots[0]` is the dark time, `knots[16]` the bright one).
    knots: [u16; CURVE_SEGMENTS + 1],
    /// Piece `k`'s `ceil(2^(15 + shift) / span)`, `span = max(1, knots[k] - knots[k + 1])`.
    recips: [u16; CURVE_SEGMENTS],
    /// Piece `k`'s `floor(log2(span))`.
    shifts: [u8; CURVE_SEGMENTS],
}

impl SensorCurve {
    /// A curve that reads every time as 0.0, to be calibrated.
    pub const UNSET: SensorCurve =
        SensorCurve { knots: [0; CURVE_SEGMENTS + 1], recips: [0; CURVE_SEGMENTS], shifts: [0; CURVE_SEGMENTS] };

    /// The curve of a calibration range (a `bright` of 0 counts as 1 tick,
    /// a `dark` at or below `bright` as one tick above it; times beyond
    /// [`MAX_CURVE_TICKS`], twice the RC timeout and more, as that).
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
        let bright = u32::from(range.bright.clamp(1, MAX_CURVE_TICKS - 1));
        let dark = u32::from(range.dark.min(MAX_CURVE_TICKS)).max(bright + 1);
        let product = bright * dark;
        for k in 0..=CURVE_SEGMENTS {
            // t = t_b t_d / (t_b + L (t_d - t_b)), L in 2^-14, t in 1/16 tick,
            // rounded: 2^18 t_b t_d / den in two 32-bit divisions (the AVR
            // has no cheap 64-bit one; t_b t_d < 2^20, so every step fits).
            let light = u32::from(LIGHT_AT_KNOT[k]);
            let den = bright * 16_384 + light * (dark - bright);
            let high = (product << 12) / den;
            let rest = (product << 12) % den;
            let t16 = high * 64 + (rest * 64 + den / 2) / den;
            self.knots[k] = u16::try_from(t16).unwrap_or(u16::MAX);
        }
        for k in 0..CURVE_SEGMENTS {
            let scale = SensorScale::new(SensorRange { bright: self.knots[k + 1], dark: self.knots[k] });
            self.recips[k] = scale.recip;
            self.shifts[k] = scale.shift;
        }
    }

    /// The calibrated field value of a discharge time in whole ticks: 1.0
    /// at or below the bright time, 0.0 at or above the dark time. (One
    /// copy for the three sensors: the robot's flash is nearly full.)
    #[inline(never)]
    pub fn value(&self, ticks: u16) -> FieldValue {
        let t = ticks.saturating_mul(16);
        let kn = &self.knots;
        // The last piece whose darker knot is at or above t (piece 0 if t
        // is darker than every knot, piece 15 if brighter): a binary search
        // written out, the masks telling the compiler every index is in range.
        let mut k = if kn[8] >= t { 8 } else { 0 };
        if kn[(k + 4) & 15] >= t {
            k += 4;
        }
        if kn[(k + 2) & 15] >= t {
            k += 2;
        }
        if kn[(k + 1) & 15] >= t {
            k += 1;
        }
        let k = k & 15;
        let (dark, bright) = (kn[k], kn[k + 1]);
        let span = if dark > bright { dark - bright } else { 1 };
        let within = SensorScale { dark, span, recip: self.recips[k], shift: self.shifts[k] }.value(t).raw();
        FieldValue::from_raw(((k as u16) << 11) + (within >> 4))
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
    fn the_light_table_is_the_light_curve_at_the_knots() {
        for (k, &l) in LIGHT_AT_KNOT.iter().enumerate() {
            let exact = (k as f64 / CURVE_SEGMENTS as f64).powf(f64::from(LIGHT_GAMMA)) * 16_384.0;
            assert_eq!(f64::from(l), exact.round(), "knot {k}");
        }
    }

    #[test]
    fn white_reads_one_black_reads_zero_and_outside_times_clamp() {
        let curve = SensorCurve::new(SensorRange { bright: 38, dark: 425 });
        assert_eq!(curve.value(38), FieldValue::ONE);
        assert_eq!(curve.value(0), FieldValue::ONE);
        assert_eq!(curve.value(425), FieldValue::ZERO);
        assert_eq!(curve.value(u16::MAX), FieldValue::ZERO);
        // The uncalibrated range and a range without contrast never panic.
        let _ = SensorCurve::new(SensorRange { bright: 0, dark: RC_TIMEOUT_TICKS }).value(100);
        assert_eq!(SensorCurve::new(SensorRange { bright: 90, dark: 90 }).value(95), FieldValue::ZERO);
    }

    #[test]
    fn the_calibrated_value_is_the_field_value_within_the_tolerance_across_0_to_1() {
        for response in RESPONSES {
            let range = SensorRange { bright: ticks(response.0), dark: ticks(response.1) };
            let curve = SensorCurve::new(range);
            let mut worst = 0.0f64;
            for i in 0..=1000 {
                let v = f64::from(i) / 1000.0;
                let got = f64::from(curve.value(ticks(discharge_us(v, response))).to_f32());
                worst = worst.max((got - v).abs());
            }
            assert!(worst <= f64::from(CURVE_TOLERANCE), "{response:?}: off by up to {worst:.4}");
        }
        // The old linear map of times was off by 0.2 at 0.6 (a calibrated
        // 0.6 was a field value of about 0.38): now 0.6 reads 0.6.
        let range = SensorRange { bright: ticks(160.0), dark: ticks(1760.0) };
        let at_06 = f64::from(SensorCurve::new(range).value(ticks(discharge_us(0.6, (160.0, 1760.0)))).to_f32());
        assert!((at_06 - 0.6).abs() < 0.01, "{at_06}");
    }

    #[test]
    fn the_three_sensors_use_their_own_curves() {
        let cal = FieldCalibration {
            ranges: [SensorRange { bright: 50, dark: 450 }, SensorRange { bright: 60, dark: 460 }, SensorRange { bright: 40, dark: 440 }],
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
