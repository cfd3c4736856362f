//! Sine and cosine from IEEE additions and multiplications only, so that
//! a seed gives the same trajectory on every machine.
//!
//! The platform's `sin_cos` comes from its libm, whose last bit may change
//! between versions and even between CPUs of one machine type (glibc picks
//! an FMA variant at run time). A robot's heading that differs in its last
//! bit soon gives a different run. Rust never fuses a multiplication and an
//! addition on its own, so the arithmetic below rounds the same everywhere.
//! It also costs less where it is used: every robot turns every step, and
//! this inlines into the step instead of calling into libm
//! (`docs/performance.md`).

use std::f64::consts::FRAC_2_PI;

/// pi / 2 split in two: the first 33 bits (so that `k * PIO2_HI` is exact
/// for |k| < 2^20) and the rest.
const PIO2_HI: f64 = 1.570_796_326_734_125_6;
const PIO2_LO: f64 = 6.077_100_506_506_192e-11;

/// Adding and subtracting 1.5 x 2^52 rounds a float of magnitude below
/// 2^51 to the nearest integer (the default rounding mode).
const ROUND: f64 = 6_755_399_441_055_744.0;

/// `(sin x, cos x)` within about one unit in the last place for |x| up to
/// a million (headings stay within [-pi, pi], see `Robot::turn`); beyond,
/// the error grows with |x|.
pub fn sin_cos(x: f64) -> (f64, f64) {
    // x = k pi/2 + r with |r| <= pi/4; quadrant k picks the signs.
    let k = (x * FRAC_2_PI + ROUND) - ROUND;
    let r = (x - k * PIO2_HI) - k * PIO2_LO;
    let (s, c) = (sin_poly(r), cos_poly(r));
    match (k as i64) & 3 {
        0 => (s, c),
        1 => (c, -s),
        2 => (-s, -c),
        _ => (-c, s),
    }
}

/// sin r for |r| <= pi/4: Taylor series to r^15 (the next term is below
/// 5e-17).
#[inline]
fn sin_poly(r: f64) -> f64 {
    let z = r * r;
    let p = -1.0 / 1_307_674_368_000.0;
    let p = 1.0 / 6_227_020_800.0 + z * p;
    let p = -1.0 / 39_916_800.0 + z * p;
    let p = 1.0 / 362_880.0 + z * p;
    let p = -1.0 / 5_040.0 + z * p;
    let p = 1.0 / 120.0 + z * p;
    let p = -1.0 / 6.0 + z * p;
    r + r * z * p
}

/// cos r for |r| <= pi/4: Taylor series to r^16 (the next term is below
/// 3e-18).
#[inline]
fn cos_poly(r: f64) -> f64 {
    let z = r * r;
    let p = 1.0 / 20_922_789_888_000.0;
    let p = -1.0 / 87_178_291_200.0 + z * p;
    let p = 1.0 / 479_001_600.0 + z * p;
    let p = -1.0 / 3_628_800.0 + z * p;
    let p = 1.0 / 40_320.0 + z * p;
    let p = -1.0 / 720.0 + z * p;
    let p = 1.0 / 24.0 + z * p;
    1.0 - 0.5 * z + z * z * p
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::{FRAC_PI_2, PI};

    /// Within 2.5e-16 of the platform's (correctly rounded or nearly)
    /// values, over many turns in both directions.
    #[test]
    fn matches_the_platform_within_rounding() {
        let mut worst: f64 = 0.0;
        for i in -200_000..=200_000 {
            let x = i as f64 * 1.0e-4 * PI + (i % 7) as f64 * 1.0e-9;
            let (s, c) = sin_cos(x);
            let (es, ec) = x.sin_cos();
            worst = worst.max((s - es).abs()).max((c - ec).abs());
        }
        assert!(worst < 2.5e-16, "largest error {worst:e}");
    }

    #[test]
    fn exact_at_the_axes_and_unit_length() {
        assert_eq!(sin_cos(0.0), (0.0, 1.0));
        let (s, c) = sin_cos(FRAC_PI_2);
        assert!((s - 1.0).abs() < 1e-16 && c.abs() < 1e-16);
        let (s, c) = sin_cos(-PI);
        assert!(s.abs() < 1e-15 && (c + 1.0).abs() < 1e-16);
        for i in 0..10_000 {
            let (s, c) = sin_cos(i as f64 * 0.000_7 - 3.5);
            assert!((s * s + c * c - 1.0).abs() < 4.5e-16);
        }
    }

    #[test]
    fn large_angles_stay_accurate() {
        for x in [1.0e3, -2.5e4, 1.0e5 + 0.3, 9.9e5] {
            let (s, c) = sin_cos(x);
            let (es, ec) = x.sin_cos();
            assert!((s - es).abs() < 1e-15 && (c - ec).abs() < 1e-15, "{x}");
        }
    }
}
