//! Fixed-point scalar-field values.

use serde::{Deserialize, Serialize};

/// A scalar-field value in [0, 1], stored as an unsigned Q1.15 fixed-point
/// number: `raw / 32768`, so 0.0 is `0` and 1.0 is exactly `32768`.
///
/// Why Q1.15: 1.0 is representable (the annulus centre and letter strokes
/// are exactly 1.0), a state hash's field bin is a right shift (no division
/// on the AVR), and the resolution (1/32768) is far finer than either the
/// robot's photo-transistors or the 64 x 64 field grid.
///
/// Real numbers convert with [`FieldValue::from_f32`]: clamp to [0, 1], then
/// round to the nearest step, ties upwards. Hashing is defined on the fixed-
/// point value, so the simulator converts once and then hashes exactly what
/// the firmware would hash.
#[derive(
    Clone, Copy, Debug, Default, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize,
)]
pub struct FieldValue(u16);

impl FieldValue {
    /// Number of fractional bits.
    pub const FRACTION_BITS: u32 = 15;
    /// The value 0.0.
    pub const ZERO: FieldValue = FieldValue(0);
    /// The value 1.0 (`32768`), the largest valid value.
    pub const ONE: FieldValue = FieldValue(1 << Self::FRACTION_BITS);

    /// Wraps a raw Q1.15 number, saturating at [`FieldValue::ONE`].
    pub const fn from_raw(raw: u16) -> FieldValue {
        if raw > Self::ONE.0 {
            Self::ONE
        } else {
            FieldValue(raw)
        }
    }

    /// The raw Q1.15 number, `0..=32768`.
    pub const fn raw(self) -> u16 {
        self.0
    }

    /// Converts a real number: clamped to [0, 1] (NaN reads as 0), then
    /// rounded to the nearest 1/32768, ties upwards.
    pub fn from_f32(value: f32) -> FieldValue {
        #[allow(
            clippy::neg_cmp_op_on_partial_ord,
            reason = "`!(value > 0.0)` also catches NaN, in one comparison (the AVR's flash is tight)"
        )]
        if !(value > 0.0) {
            return Self::ZERO;
        }
        if value >= 1.0 {
            return Self::ONE;
        }
        // Scaling by a power of two is exact; `as` truncates, so +0.5
        // rounds to nearest with ties up for the non-negative values here.
        FieldValue((value * 32768.0 + 0.5) as u16)
    }

    /// The value as a real number (exact: every Q1.15 value is an `f32`).
    pub fn to_f32(self) -> f32 {
        f32::from(self.0) / 32768.0
    }

    /// `floor(value x 2^bits)`, clamped to `2^bits - 1` so that 1.0 falls
    /// in the top bin. `bits` is at most 15.
    pub const fn bin(self, bits: u32) -> u16 {
        let bin = self.0 >> (Self::FRACTION_BITS - bits);
        let top = (1u16 << bits) - 1;
        if bin > top {
            top
        } else {
            bin
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn conversion_rounds_to_nearest_and_clamps() {
        assert_eq!(FieldValue::from_f32(0.0).raw(), 0);
        assert_eq!(FieldValue::from_f32(1.0), FieldValue::ONE);
        assert_eq!(FieldValue::from_f32(1.5), FieldValue::ONE);
        assert_eq!(FieldValue::from_f32(-0.2), FieldValue::ZERO);
        assert_eq!(FieldValue::from_f32(f32::NAN), FieldValue::ZERO);
        assert_eq!(FieldValue::from_f32(0.5).raw(), 16384);
        // 0.4 x 32768 = 13107.2 -> 13107
        assert_eq!(FieldValue::from_f32(0.4).raw(), 13107);
        // a tie rounds up: (2.5 / 32768) -> 3
        assert_eq!(FieldValue::from_f32(2.5 / 32768.0).raw(), 3);
        assert_eq!(FieldValue::from_raw(40000), FieldValue::ONE);
    }

    #[test]
    fn every_raw_value_round_trips_through_f32() {
        for raw in 0..=FieldValue::ONE.raw() {
            let v = FieldValue::from_raw(raw);
            assert_eq!(FieldValue::from_f32(v.to_f32()), v);
        }
    }

    #[test]
    fn bins_floor_and_clamp_the_top() {
        assert_eq!(FieldValue::from_f32(0.4).bin(4), 6);
        assert_eq!(FieldValue::ONE.bin(3), 7);
        assert_eq!(FieldValue::ONE.bin(4), 15);
        assert_eq!(FieldValue::ONE.bin(5), 31);
        assert_eq!(FieldValue::from_f32(0.5).bin(4), 8);
        assert_eq!(FieldValue::from_raw(16383).bin(4), 7);
    }
}
