//! Scalar fields: a grid of values in [0, 1] stretched over the arena.
//!
//! Sensors read the nearest cell, `index = round(cells x position /
//! arena_size)`; the evaluation of pucks truncates instead. Positions whose
//! index falls outside the grid read 0 (so sensor points in the last half
//! cell along the right and bottom edges read 0, as in the original).

use crate::vec2::Vec2;
use shared::FieldValue;

/// A grid of field values, row-major, row 0 at the top (y = 0).
#[derive(Clone, Debug, PartialEq)]
pub struct ScalarField {
    width: usize,
    height: usize,
    values: Vec<f32>,
    fixed: Vec<FieldValue>,
}

impl ScalarField {
    /// A field from `width x height` values (row-major), clamped to [0, 1].
    /// Returns `None` if the sizes do not match or are zero.
    pub fn new(width: usize, height: usize, values: Vec<f32>) -> Option<ScalarField> {
        if width == 0 || height == 0 || values.len() != width * height {
            return None;
        }
        let values: Vec<f32> = values.into_iter().map(|v| if v > 0.0 { v.min(1.0) } else { 0.0 }).collect();
        let fixed = values.iter().map(|&v| FieldValue::from_f32(v)).collect();
        Some(ScalarField { width, height, values, fixed })
    }

    /// The annulus field of the reference model: 64 x 64 cells, value
    /// `1 - distance((i, j), (32, 32)) / (32 sqrt 2)`, so cell (32, 32) is
    /// exactly 1 and the farthest cell (0, 0) is 0.
    pub fn annulus() -> ScalarField {
        const N: usize = 64;
        let centre = (N / 2) as f64;
        let farthest = centre.hypot(centre);
        let values = (0..N * N)
            .map(|k| {
                let (x, y) = ((k % N) as f64, (k / N) as f64);
                (1.0 - (x - centre).hypot(y - centre) / farthest) as f32
            })
            .collect();
        ScalarField::new(N, N, values).expect("64 x 64 values")
    }

    /// Grid width (columns).
    pub fn width(&self) -> usize {
        self.width
    }

    /// Grid height (rows).
    pub fn height(&self) -> usize {
        self.height
    }

    /// The value of cell (`x`, `y`), or 0 outside the grid.
    pub fn cell(&self, x: i64, y: i64) -> f32 {
        self.cell_index(x, y).map_or(0.0, |k| self.values[k])
    }

    fn cell_index(&self, x: i64, y: i64) -> Option<usize> {
        let inside = (0..self.width as i64).contains(&x) && (0..self.height as i64).contains(&y);
        inside.then(|| y as usize * self.width + x as usize)
    }

    /// The cell a sensor at `p` reads: nearest cell by rounding.
    pub fn nearest_cell(&self, p: Vec2, arena_size: f64) -> (i64, i64) {
        let x = round_half_away(self.width as f64 * p.x / arena_size);
        let y = round_half_away(self.height as f64 * p.y / arena_size);
        (x, y)
    }

    /// The sensor reading at `p`, in fixed point (nearest cell; 0 outside).
    pub fn sense(&self, p: Vec2, arena_size: f64) -> FieldValue {
        let (x, y) = self.nearest_cell(p, arena_size);
        self.cell_index(x, y).map_or(FieldValue::ZERO, |k| self.fixed[k])
    }

    /// The value used to evaluate a puck at `p`: the cell found by
    /// truncation (0 outside).
    pub fn evaluate(&self, p: Vec2, arena_size: f64) -> f32 {
        let x = (self.width as f64 * p.x / arena_size) as i64;
        let y = (self.height as f64 * p.y / arena_size) as i64;
        self.cell(x, y)
    }
}

/// `t.round() as i64` without the libm call `round` compiles to on
/// baseline x86-64: the fractional part `t - trunc(t)` is exact, so the
/// result is identical. No branch on the fraction, which is as likely to
/// be above one half as below. (Indices beyond `i64` saturate, as `as`
/// does.)
fn round_half_away(t: f64) -> i64 {
    let whole = t as i64;
    let frac = t - whole as f64;
    whole.saturating_add(i64::from(frac >= 0.5)).saturating_sub(i64::from(frac <= -0.5))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn annulus_centre_is_exactly_one_and_far_corner_zero() {
        let f = ScalarField::annulus();
        assert_eq!(f.cell(32, 32), 1.0);
        assert_eq!(f.cell(0, 0), 0.0);
        assert!(f.cell(63, 63) > 0.0);
        assert_eq!(f.sense(Vec2::new(400.0, 400.0), 800.0), FieldValue::ONE);
    }

    #[test]
    fn sensors_round_and_read_zero_past_the_last_half_cell() {
        let f = ScalarField::annulus();
        // 64 cells over 800 units: 12.5 units per cell.
        assert_eq!(f.nearest_cell(Vec2::new(6.0, 6.0), 800.0), (0, 0));
        assert_eq!(f.nearest_cell(Vec2::new(6.25, 18.7), 800.0), (1, 1));
        assert_eq!(f.nearest_cell(Vec2::new(793.0, 400.0), 800.0), (63, 32));
        assert_eq!(f.nearest_cell(Vec2::new(793.75, 400.0), 800.0), (64, 32));
        assert_eq!(f.sense(Vec2::new(793.75, 400.0), 800.0), FieldValue::ZERO);
        assert_eq!(f.sense(Vec2::new(400.0, 795.0), 800.0), FieldValue::ZERO);
        assert_eq!(f.sense(Vec2::new(793.0, 400.0), 800.0), FieldValue::from_f32(f.cell(63, 32)));
        assert_eq!(f.sense(Vec2::new(-7.0, 400.0), 800.0), FieldValue::ZERO);
        // evaluation truncates: 799 -> cell 63
        assert_eq!(f.evaluate(Vec2::new(799.0, 400.0), 800.0), f.cell(63, 32));
        assert_eq!(f.evaluate(Vec2::new(12.4, 12.4), 800.0), f.cell(0, 0));
    }

    #[test]
    fn rounding_matches_the_standard_round() {
        let mut values = vec![0.0, 0.49999999999999994, 0.5, 1.5, 2.4999, 63.5, -0.2, -0.5, -0.50001, -1.5, 1e300, f64::NAN];
        values.extend((-4000..4000).map(|k| f64::from(k) * 0.0625 + 1e-9 * f64::from(k % 3)));
        for t in values {
            assert_eq!(round_half_away(t), t.round() as i64, "{t}");
        }
    }
}
