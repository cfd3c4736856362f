//! Rounding to whole numbers without libm: on baseline x86-64 (no SSE4.1)
//! `f64::floor` and `f64::round` are calls into libm or compiler-builtins
//! of some 20 to 40 instructions each. These give the same results, bit for
//! bit, from a truncating conversion and an exact fractional part
//! (`t - trunc(t)` is exact for every float), and inline.

/// Beyond this magnitude every float is a whole number.
const WHOLE: f64 = 4_503_599_627_370_496.0; // 2^52

/// `t.floor()`, the sign of a zero, NaN and the infinities included.
#[inline]
pub fn floor(t: f64) -> f64 {
    if t.abs() >= WHOLE || t.is_nan() {
        return t; // whole already, infinite or NaN
    }
    let whole = t as i64 as f64;
    let below = if whole > t { whole - 1.0 } else { whole };
    // -0.0 and (-1, 0) are the only inputs whose truncation has another sign.
    if below == 0.0 {
        0.0f64.copysign(t)
    } else {
        below
    }
}

/// `t.round() as i64`: halves away from zero; NaN gives 0 and magnitudes
/// beyond `i64` saturate, as `as` does. No branch on the fraction, which
/// is as likely to be above one half as below.
#[inline]
pub(crate) fn round_half_away(t: f64) -> i64 {
    let whole = t as i64;
    let frac = t - whole as f64;
    whole
        .saturating_add(i64::from(frac >= 0.5))
        .saturating_sub(i64::from(frac <= -0.5))
}

/// `round_half_away(t).clamp(0, limit)`, rounded after clamping:
/// rounding is monotone and keeps 0 and `limit`, so the order makes no
/// difference, and from 0 up it is a truncation and a comparison (the
/// fraction is exact). NaN gives 0, as there. (A camera block's jittered
/// place: fewer instructions than rounding, then clamping.)
#[inline]
pub(crate) fn round_half_away_within(t: f64, limit: u16) -> u16 {
    let t = t.clamp(0.0, f64::from(limit));
    let whole = t as u16;
    whole + u16::from(t - f64::from(whole) >= 0.5)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Halves, their neighbours, whole numbers, both zeros, the edges of
    /// exactness and the special values.
    fn values() -> Vec<f64> {
        let mut v = vec![
            0.0,
            -0.0,
            0.49999999999999994,
            -0.49999999999999994,
            0.5,
            -0.5,
            1.0 - f64::EPSILON / 2.0,
            -(1.0 - f64::EPSILON / 2.0),
            WHOLE - 0.5,
            -(WHOLE - 0.5),
            WHOLE,
            WHOLE + 2.0,
            9.3e18,
            -9.3e18,
            1e300,
            -1e300,
            f64::MIN_POSITIVE,
            -f64::MIN_POSITIVE,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::NAN,
        ];
        for k in -4000..4000 {
            let t = f64::from(k) * 0.0625;
            v.extend([t, t + 1e-9 * f64::from(k % 3), t.next_up(), t.next_down()]);
        }
        v
    }

    #[test]
    fn floor_is_the_standard_floor_bit_for_bit() {
        for t in values() {
            assert_eq!(floor(t).to_bits(), t.floor().to_bits(), "{t:e}");
        }
    }

    #[test]
    fn rounding_matches_the_standard_round() {
        for t in values() {
            assert_eq!(round_half_away(t), t.round() as i64, "{t:e}");
        }
    }

    #[test]
    fn rounding_within_a_limit_is_rounding_then_clamping() {
        let mut values = values();
        for k in -400..=2_000 {
            let v = f64::from(k) / 4.0;
            values.extend([v, v.next_down(), v.next_up(), v + 0.123]);
        }
        for limit in [0, 1, 207, 208, 315, 316, u16::MAX] {
            for &v in &values {
                let clamped = round_half_away(v).clamp(0, i64::from(limit)) as u16;
                assert_eq!(
                    round_half_away_within(v, limit),
                    clamped,
                    "{v} within {limit}"
                );
            }
        }
    }
}
