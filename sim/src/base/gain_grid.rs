//! A smooth gain over a rectangle: values at the centres of `columns x
//! rows` equal tiles, bilinear between them, the edge values held beyond
//! the outermost centres. The screen's brightness in the robot sensors'
//! noise model is one, drawn per episode; a panel's measured brightness
//! (`host field gain`, [`crate::scenario::flat_field`]) is another.
//!
//! File form (TOML), the points row by row from the rectangle's origin
//! (a panel's top-left):
//!
//! ```toml
//! columns = 4
//! rows = 3
//! gains = [1.02, 0.98, 1.01, 0.97, 1.0, 1.03, 0.99, 1.0, 1.01, 0.98, 1.0, 1.01]
//! ```

use crate::base::ranges::{self, RangeError};
use crate::base::vec2::Vec2;
use serde::{Deserialize, Serialize};
use std::fmt;

/// Gains at the centres of `columns x rows` equal tiles, row by row.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct GainGrid {
    /// Tiles across.
    pub columns: usize,
    /// Tiles down.
    pub rows: usize,
    /// The gain at each tile's centre, row by row.
    pub gains: Vec<f64>,
}

/// Why a gain grid is not usable.
#[derive(Clone, Debug, PartialEq)]
pub enum GainGridError {
    /// A side or a gain outside its range ([`ranges::GAIN_GRID_SIDE`],
    /// [`ranges::PANEL_GAIN`]).
    Range(RangeError),
    /// Not `columns x rows` gains.
    Count {
        /// `columns x rows`.
        expected: usize,
        /// The number given.
        found: usize,
    },
}

impl fmt::Display for GainGridError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            GainGridError::Range(e) => e.fmt(f),
            GainGridError::Count { expected, found } => write!(
                f,
                "{found} gains given, expected columns x rows = {expected}"
            ),
        }
    }
}

impl core::error::Error for GainGridError {}

impl GainGrid {
    /// The same gain `value` everywhere.
    pub fn uniform(columns: usize, rows: usize, value: f64) -> GainGrid {
        GainGrid {
            columns,
            rows,
            gains: vec![value; columns * rows],
        }
    }

    /// Checks the sides, the count and every gain (the error names the
    /// gain by its place, row by row from 1).
    pub fn validate(&self) -> Result<(), GainGridError> {
        for (key, side) in [("gain.columns", self.columns), ("gain.rows", self.rows)] {
            ranges::GAIN_GRID_SIDE
                .check_count(key, side as u64)
                .map_err(GainGridError::Range)?;
        }
        let expected = self.columns * self.rows;
        if self.gains.len() != expected {
            return Err(GainGridError::Count {
                expected,
                found: self.gains.len(),
            });
        }
        for (k, gain) in self.gains.iter().enumerate() {
            ranges::PANEL_GAIN
                .check_as(&format!("gain.gains[{}]", k + 1), *gain)
                .map_err(GainGridError::Range)?;
        }
        Ok(())
    }

    /// Point `k` (row by row) of a rectangle of `size`: its tile's centre.
    pub fn point(&self, k: usize, size: Vec2) -> Vec2 {
        let (i, j) = (k % self.columns, k / self.columns);
        Vec2::new(
            (i as f64 + 0.5) * size.x / self.columns as f64,
            (j as f64 + 0.5) * size.y / self.rows as f64,
        )
    }

    /// The least gain (bilinear values lie between their points').
    pub fn min(&self) -> f64 {
        self.gains.iter().copied().fold(f64::INFINITY, f64::min)
    }

    /// The gain at `p` of a rectangle of `size`.
    pub fn at(&self, p: Vec2, size: Vec2) -> f64 {
        // A side is at most the gains' length, so the conversions through
        // `i64` are exact (one instruction each, where `usize` takes several).
        let split = |t: f64, n: usize| {
            let t = (t * n as i64 as f64 - 0.5).clamp(0.0, (n - 1) as i64 as f64);
            let i = (t as i64 as usize).min(n - 2);
            (i, t - i as i64 as f64)
        };
        let cols = self.columns;
        let (i, tx) = split(p.x / size.x, cols);
        let (j, ty) = split(p.y / size.y, self.rows);
        // The four gains around `p`: the cell's, the next column's, and the
        // two of the next row (`i < cols - 1` and `j < rows - 1`, so the
        // window lies within the gains; one bounds check, not four).
        let cell = &self.gains[j * cols + i..][..cols + 2];
        let (top_left, top_right) = (cell[0], cell[1]);
        let (bottom_left, bottom_right) = (cell[cols], cell[cols + 1]);
        let top = top_left + (top_right - top_left) * tx;
        let bottom = bottom_left + (bottom_right - bottom_left) * tx;
        top + (bottom - top) * ty
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn grid() -> GainGrid {
        GainGrid {
            columns: 4,
            rows: 3,
            gains: (0..12).map(|k| 1.0 + 0.01 * k as f64).collect(),
        }
    }

    #[test]
    fn the_gain_is_its_points_at_the_tile_centres_and_bilinear_between() {
        let (g, size) = (grid(), Vec2::new(400.0, 300.0));
        for k in 0..12 {
            assert!((g.at(g.point(k, size), size) - g.gains[k]).abs() < 1e-12);
        }
        let mid = g.at(Vec2::new(100.0, 50.0), size);
        assert!((mid - (g.gains[0] + g.gains[1]) / 2.0).abs() < 1e-12);
        // past the outermost centres the edge values hold
        assert_eq!(g.at(Vec2::new(0.0, 0.0), size), g.gains[0]);
        assert_eq!(g.at(size, size), g.gains[11]);
        assert_eq!(g.min(), 1.0);
    }

    #[test]
    fn a_grid_of_the_wrong_size_or_with_a_gain_that_is_not_positive_is_refused() {
        assert_eq!(grid().validate(), Ok(()));
        let short = GainGrid {
            gains: vec![1.0; 11],
            ..grid()
        };
        assert!(short
            .validate()
            .unwrap_err()
            .to_string()
            .contains("11 gains"));
        let one_row = GainGrid::uniform(4, 1, 1.0);
        assert!(one_row
            .validate()
            .unwrap_err()
            .to_string()
            .contains("rows = 1"));
        let mut dark = grid();
        dark.gains[5] = 0.0;
        let e = dark.validate().unwrap_err().to_string();
        assert!(e.starts_with("gain.gains[6] = 0: outside"), "{e}");
        dark.gains[5] = f64::NAN;
        assert!(dark.validate().is_err());
    }
}
