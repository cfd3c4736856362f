//! Scalar fields: a grid of values in [0, 1] laid over a rectangle of the
//! arena (its [`FieldFrame`]: the whole arena unless an arena places it
//! otherwise), read in one of two ways ([`FieldSampling`]):
//!
//! - `Nearest`, the reference model's: sensors read the nearest cell,
//!   `index = round(cells x (position - origin) / frame size)`, and the
//!   evaluation of pucks truncates instead. Positions whose index falls
//!   outside the grid read 0 (so sensor points in the last half cell along
//!   the right and bottom edges read 0, as in the original).
//! - `Bilinear`, as a TV shows an image scaled to its panel: cell `(i, j)`
//!   is the pixel centred at `((i + 1/2), (j + 1/2))` cell widths from the
//!   frame's origin; a position between centres interpolates the four
//!   around it (past the outermost centres, the edge pixels extend to the
//!   frame's border); outside the frame the screen is black (0). Sensors
//!   and the evaluation of pucks both read this value.
//!
//! Room 2 of the simulator (`lib.rs`): what the robots read and Eval measures, below every stage.

pub mod generated;
pub mod letters;
pub(crate) mod raster;
pub mod source;
pub mod turn;

use crate::base::vec2::Vec2;
use serde::{Deserialize, Serialize};
use shared::FieldValue;
use std::sync::{Arc, Mutex};

/// The rectangle of the arena a field's grid covers, units.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FieldFrame {
    /// Left edge.
    pub x: f64,
    /// Top edge.
    pub y: f64,
    /// Width.
    pub width: f64,
    /// Height.
    pub height: f64,
}

impl FieldFrame {
    /// The whole of a `width` x `height` arena.
    pub const fn whole(width: f64, height: f64) -> FieldFrame {
        FieldFrame {
            x: 0.0,
            y: 0.0,
            width,
            height,
        }
    }
}

/// How a position reads the field.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum FieldSampling {
    /// The reference model's nearest cell (sensors) and truncated cell (Eval).
    #[default]
    Nearest,
    /// Bilinear between pixel centres, as a TV scales an image.
    Bilinear,
}

/// Where a field lies and how it is read: what every reading needs.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FieldLayout {
    /// The rectangle the grid covers.
    pub frame: FieldFrame,
    /// How positions read it.
    pub sampling: FieldSampling,
}

/// A grid of field values, row-major, row 0 at the top (y = 0).
#[derive(Clone, Debug, PartialEq)]
pub struct ScalarField {
    width: usize,
    height: usize,
    values: Vec<f32>,
    fixed: Vec<FieldValue>,
    derived: DerivedTables,
}

/// Tables computed from a field's values, one per key (such as a set of
/// thresholds), made once and then shared by every world that reads this
/// field: a batch of hundreds of worlds keeps one copy, not one a world,
/// in the caches they share. A clone starts without any; equality is the
/// values'.
#[derive(Default)]
struct DerivedTables(Mutex<Vec<DerivedTable>>);

/// A derived table and its key.
type DerivedTable = ([u64; 2], Arc<[u64]>);

impl Clone for DerivedTables {
    fn clone(&self) -> DerivedTables {
        DerivedTables::default()
    }
}

impl PartialEq for DerivedTables {
    fn eq(&self, _: &DerivedTables) -> bool {
        true
    }
}

impl std::fmt::Debug for DerivedTables {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("DerivedTables")
    }
}

impl ScalarField {
    /// A field from `width x height` values (row-major), clamped to [0, 1].
    /// Returns `None` if the sizes do not match or are zero.
    pub fn new(width: usize, height: usize, values: Vec<f32>) -> Option<ScalarField> {
        if width == 0 || height == 0 || values.len() != width * height {
            return None;
        }
        let values: Vec<f32> = values
            .into_iter()
            .map(|v| if v > 0.0 { v.min(1.0) } else { 0.0 })
            .collect();
        let fixed = values.iter().map(|&v| FieldValue::from_f32(v)).collect();
        Some(ScalarField {
            width,
            height,
            values,
            fixed,
            derived: DerivedTables::default(),
        })
    }

    /// The annulus field of the reference model: 64 x 64 cells, value
    /// `1 - distance((i, j), (32, 32)) / (32 sqrt 2)`, so cell (32, 32) is
    /// exactly 1 and the farthest cell (0, 0) is 0.
    pub fn annulus() -> ScalarField {
        ScalarField::annulus_of(64, 64)
    }

    /// The annulus on `width` x `height` square cells: value `1 -
    /// distance((i, j), (width / 2, height / 2))` over the distance from the
    /// centre to cell (0, 0), so contours are circles and the corner cell
    /// (0, 0) is 0. (The 64 x 64 one is the reference model's.)
    pub fn annulus_of(width: usize, height: usize) -> ScalarField {
        let centre = ((width / 2) as f64, (height / 2) as f64);
        let farthest = centre.0.hypot(centre.1);
        let values = (0..width * height)
            .map(|k| {
                let (x, y) = ((k % width) as f64, (k / width) as f64);
                (1.0 - (x - centre.0).hypot(y - centre.1) / farthest) as f32
            })
            .collect();
        ScalarField::new(width, height, values).expect("width x height values")
    }

    /// The table `make` computes from the values, for `key`: made on the
    /// first call with that key, the same shared table afterwards.
    pub fn derived_table(
        &self,
        key: [u64; 2],
        make: impl FnOnce(&[f32]) -> Vec<u64>,
    ) -> Arc<[u64]> {
        // a panic while holding the lock left at most a table unmade
        let mut tables = self
            .derived
            .0
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner);
        if let Some((_, table)) = tables.iter().find(|(k, _)| *k == key) {
            return table.clone();
        }
        let table: Arc<[u64]> = make(&self.values).into();
        tables.push((key, table.clone()));
        table
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

    /// The cell a sensor at `p` reads with [`FieldSampling::Nearest`]:
    /// nearest cell by rounding.
    #[cfg(test)]
    pub(crate) fn nearest_cell(&self, p: Vec2, frame: &FieldFrame) -> (i64, i64) {
        let x = crate::base::rounding::round_half_away(
            self.width as f64 * (p.x - frame.x) / frame.width,
        );
        let y = crate::base::rounding::round_half_away(
            self.height as f64 * (p.y - frame.y) / frame.height,
        );
        (x, y)
    }

    /// A sensor's reading at `p`, in fixed point.
    #[inline]
    pub fn sense(&self, p: Vec2, layout: &FieldLayout) -> FieldValue {
        match layout.sampling {
            FieldSampling::Nearest => {
                // The cell of [`ScalarField::nearest_cell`], decided without
                // its integer conversions (a sensor reads three per step).
                let f = &layout.frame;
                let x = nearest_index(self.width as f64 * (p.x - f.x) / f.width, self.width);
                let y = nearest_index(self.height as f64 * (p.y - f.y) / f.height, self.height);
                match (x, y) {
                    (Some(x), Some(y)) => self.fixed[y * self.width + x],
                    _ => FieldValue::ZERO,
                }
            }
            FieldSampling::Bilinear => FieldValue::from_f32(self.bilinear(p, &layout.frame) as f32),
        }
    }

    /// The field value the screen shows at `p` (what a photo-transistor
    /// there sees): the sensor reading's value with nearest sampling, the
    /// exact interpolation with bilinear.
    pub fn shown(&self, p: Vec2, layout: &FieldLayout) -> f64 {
        match layout.sampling {
            FieldSampling::Nearest => f64::from(self.sense(p, layout).to_f32()),
            FieldSampling::Bilinear => self.bilinear(p, &layout.frame),
        }
    }

    /// The value used to evaluate a puck at `p`: with nearest sampling the
    /// cell found by truncation (0 outside), with bilinear the interpolation.
    pub fn evaluate(&self, p: Vec2, layout: &FieldLayout) -> f32 {
        match layout.sampling {
            FieldSampling::Nearest => self
                .truncated_cell(p, &layout.frame)
                .map_or(0.0, |k| self.values[k]),
            FieldSampling::Bilinear => self.bilinear(p, &layout.frame) as f32,
        }
    }

    /// The row-major index of the cell [`ScalarField::evaluate`] reads at
    /// `p` with nearest sampling (the cell found by truncation), or `None`
    /// outside the grid.
    #[inline]
    pub(crate) fn truncated_cell(&self, p: Vec2, frame: &FieldFrame) -> Option<usize> {
        let x = (self.width as f64 * (p.x - frame.x) / frame.width) as i64;
        let y = (self.height as f64 * (p.y - frame.y) / frame.height) as i64;
        self.cell_index(x, y)
    }

    /// Every cell's value, row-major.
    pub fn values(&self) -> &[f32] {
        &self.values
    }

    /// The bilinear interpolation at `p` between pixel centres (0 outside
    /// the frame; the edge pixels extend to its border).
    pub fn bilinear(&self, p: Vec2, frame: &FieldFrame) -> f64 {
        // A side is at most the values' length, so it converts through
        // `i64` exactly (one instruction, where `usize` takes several).
        let (width, height) = (self.width as i64 as f64, self.height as i64 as f64);
        let u = width * (p.x - frame.x) / frame.width;
        let v = height * (p.y - frame.y) / frame.height;
        if !((0.0..=width).contains(&u) && (0.0..=height).contains(&v)) {
            return 0.0;
        }
        let (i0, i1, tx) = split(u - 0.5, self.width);
        let (j0, j1, ty) = split(v - 0.5, self.height);
        let at = |i: usize, j: usize| f64::from(self.values[j * self.width + i]);
        let top = at(i0, j0) + (at(i1, j0) - at(i0, j0)) * tx;
        let bottom = at(i0, j1) + (at(i1, j1) - at(i0, j1)) * tx;
        top + (bottom - top) * ty
    }
}

/// The pixel at or left of coordinate `t` (in pixel widths from the first
/// centre), the next one (the last pixel's is itself) and the fraction
/// towards it, clamped to the `n` pixels.
fn split(t: f64, n: usize) -> (usize, usize, f64) {
    if t <= 0.0 {
        return (0, 1.min(n - 1), 0.0);
    }
    // `t` is positive and below `n` here (no NaN): its truncation is its
    // floor, exactly.
    let i = t as i64 as usize;
    if i >= n - 1 {
        return (n - 1, n - 1, 0.0);
    }
    (i, i + 1, t - i as i64 as f64)
}

/// `round_half_away(t)` if it lies in `0..n`, else `None`. It is at least 0
/// exactly when `t > -0.5` (-0.5 rounds away to -1) and below `n` exactly
/// when `t < n - 0.5` (which rounds up to `n`). Inside, `t as u32`
/// truncates (to 0 for `t` in (-0.5, 0)) and the fraction is exact, as in
/// [`crate::base::rounding::round_half_away`]; NaN passes both tests and reads cell 0, as there.
#[inline]
fn nearest_index(t: f64, n: usize) -> Option<usize> {
    if (t <= -0.5) | (t >= n as f64 - 0.5) {
        return None;
    }
    let whole = t as u32;
    Some(whole as usize + usize::from(t - f64::from(whole) >= 0.5))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_derived_table_is_made_once_per_key_and_shared() {
        let f = ScalarField::annulus();
        let made = std::cell::Cell::new(0);
        let make = |values: &[f32]| {
            made.set(made.get() + 1);
            values.iter().map(|&v| u64::from(v > 0.5)).collect()
        };
        let a = f.derived_table([1, 2], make);
        let b = f.derived_table([1, 2], make);
        assert!(Arc::ptr_eq(&a, &b));
        assert_eq!(a.len(), 64 * 64);
        let c = f.derived_table([1, 3], make);
        assert!(!Arc::ptr_eq(&a, &c));
        assert_eq!(made.get(), 2);
        // a clone is the same field and makes its own
        let g = f.clone();
        assert_eq!(g, f);
        assert!(!Arc::ptr_eq(&g.derived_table([1, 2], make), &a));
    }

    #[test]
    fn annulus_centre_is_exactly_one_and_far_corner_zero() {
        let f = ScalarField::annulus();
        assert_eq!(f.cell(32, 32), 1.0);
        assert_eq!(f.cell(0, 0), 0.0);
        assert!(f.cell(63, 63) > 0.0);
        assert_eq!(f.sense(Vec2::new(400.0, 400.0), &THESIS), FieldValue::ONE);
    }

    /// The reference model's layout: the 800 x 800 arena, nearest cell.
    const THESIS: FieldLayout = FieldLayout {
        frame: FieldFrame::whole(800.0, 800.0),
        sampling: FieldSampling::Nearest,
    };

    #[test]
    fn sensors_round_and_read_zero_past_the_last_half_cell() {
        let f = ScalarField::annulus();
        let frame = THESIS.frame;
        // 64 cells over 800 units: 12.5 units per cell.
        assert_eq!(f.nearest_cell(Vec2::new(6.0, 6.0), &frame), (0, 0));
        assert_eq!(f.nearest_cell(Vec2::new(6.25, 18.7), &frame), (1, 1));
        assert_eq!(f.nearest_cell(Vec2::new(793.0, 400.0), &frame), (63, 32));
        assert_eq!(f.nearest_cell(Vec2::new(793.75, 400.0), &frame), (64, 32));
        assert_eq!(f.sense(Vec2::new(793.75, 400.0), &THESIS), FieldValue::ZERO);
        assert_eq!(f.sense(Vec2::new(400.0, 795.0), &THESIS), FieldValue::ZERO);
        assert_eq!(
            f.sense(Vec2::new(793.0, 400.0), &THESIS),
            FieldValue::from_f32(f.cell(63, 32))
        );
        assert_eq!(f.sense(Vec2::new(-7.0, 400.0), &THESIS), FieldValue::ZERO);
        // evaluation truncates: 799 -> cell 63
        assert_eq!(f.evaluate(Vec2::new(799.0, 400.0), &THESIS), f.cell(63, 32));
        assert_eq!(f.evaluate(Vec2::new(12.4, 12.4), &THESIS), f.cell(0, 0));
    }

    #[test]
    fn bilinear_sampling_matches_hand_computed_values_and_is_black_outside_the_frame() {
        // 2 x 2 pixels over a 20 x 10 frame at (100, 50): centres at x 105
        // and 115, y 52.5 and 57.5.
        let f = ScalarField::new(2, 2, vec![0.0, 1.0, 0.5, 0.25]).unwrap();
        let layout = FieldLayout {
            frame: FieldFrame {
                x: 100.0,
                y: 50.0,
                width: 20.0,
                height: 10.0,
            },
            sampling: FieldSampling::Bilinear,
        };
        let at = |x, y| f.shown(Vec2::new(x, y), &layout);
        assert_eq!(at(105.0, 52.5), 0.0);
        assert_eq!(at(115.0, 52.5), 1.0);
        assert_eq!(at(110.0, 52.5), 0.5);
        // Halfway down between the rows: top 0.5, bottom (0.5 + 0.25) / 2.
        assert!((at(110.0, 55.0) - (0.5 + 0.375) / 2.0).abs() < 1e-12);
        // A quarter of the way from the left centre, three quarters down.
        let (tx, ty) = (0.25, 0.75);
        let (top, bottom) = (0.0 + (1.0 - 0.0) * tx, 0.5 + (0.25 - 0.5) * tx);
        assert!((at(107.5, 52.5 + 5.0 * ty) - (top + (bottom - top) * ty)).abs() < 1e-12);
        // Past the outermost centres the edge pixels extend to the border.
        assert_eq!(at(100.0, 50.0), 0.0);
        assert_eq!(at(120.0, 50.0), 1.0);
        assert_eq!(at(119.0, 60.0), 0.25);
        // Outside the frame: black.
        assert_eq!(at(99.9, 55.0), 0.0);
        assert_eq!(at(121.0, 55.0), 0.0);
        assert_eq!(f.sense(Vec2::new(115.0, 52.5), &layout), FieldValue::ONE);
        assert_eq!(f.evaluate(Vec2::new(110.0, 52.5), &layout), 0.5);
    }

    #[test]
    fn two_sensors_37_mm_apart_on_a_gradient_read_different_values_bilinear_but_often_one_cell_nearest(
    ) {
        // The annulus over the thesis' arena: cells of 12.5 units (62.5 mm
        // at 5 mm per unit); sensors 37 mm = 7.4 units apart across a radius.
        let f = ScalarField::annulus();
        let bilinear = FieldLayout {
            sampling: FieldSampling::Bilinear,
            ..THESIS
        };
        let (mut same_cell, mut differ) = (0, 0);
        for k in 0..100 {
            let x = 420.0 + 2.0 * f64::from(k);
            let (a, b) = (Vec2::new(x, 400.0), Vec2::new(x + 7.4, 400.0));
            same_cell += usize::from(f.sense(a, &THESIS) == f.sense(b, &THESIS));
            differ += usize::from(f.sense(a, &bilinear) > f.sense(b, &bilinear));
        }
        assert_eq!(differ, 100, "bilinear: the inner sensor always reads more");
        assert!(
            same_cell >= 30,
            "nearest: {same_cell} of 100 pairs read one cell"
        );
    }

    #[test]
    fn nearest_sensing_reads_the_cell_that_rounding_picks_also_at_half_cells_and_outside() {
        let f = ScalarField::annulus_of(64, 36);
        let layout = FieldLayout {
            frame: FieldFrame {
                x: -3.5,
                y: 10.0,
                width: 800.0,
                height: 450.0,
            },
            sampling: FieldSampling::Nearest,
        };
        let cell = 800.0 / 64.0;
        let mut points = vec![
            Vec2::new(f64::NAN, 100.0),
            Vec2::new(1e300, 100.0),
            Vec2::new(-1e300, -1e300),
        ];
        for k in -40..1700 {
            let t = f64::from(k) * 0.5 * cell - 3.5;
            for d in [0.0, 1e-9, -1e-9, 0.3, 4.0, 6.25, -6.25] {
                points.push(Vec2::new(t + d, 10.0 + (t + d) * 0.5625));
                points.push(Vec2::new(400.0, t + d));
                points.push(Vec2::new(t + d, 200.0));
            }
        }
        for p in points {
            let (x, y) = f.nearest_cell(p, &layout.frame);
            let expected = f.cell_index(x, y).map_or(FieldValue::ZERO, |k| f.fixed[k]);
            assert_eq!(f.sense(p, &layout), expected, "{p:?}");
        }
    }
}
