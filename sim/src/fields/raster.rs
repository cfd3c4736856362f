//! Drawing a shape into a field: the shape's pixels 1.0, every other pixel
//! falling off linearly with its Euclidean distance to the nearest shape
//! pixel (an exact distance transform) down to 0, as the thesis' images do.
//! Shapes are round-capped strokes along segments, filled polygons, or
//! both; a pixel is on the shape if its centre is.

use crate::fields::ScalarField;

/// A point in pixel coordinates (x right, y down).
pub(crate) type Point = (f64, f64);

/// A shape made of strokes and filled polygons, in pixel coordinates.
#[derive(Clone, Debug, Default, PartialEq)]
pub(crate) struct Drawing {
    /// Round-capped strokes: centre line from one point to the other, and
    /// the stroke's width.
    pub(crate) strokes: Vec<([Point; 2], f64)>,
    /// Filled polygons: their corners in order.
    pub(crate) polygons: Vec<Vec<Point>>,
}

impl Drawing {
    /// Whether the pixel centre `p` lies on the shape.
    pub(crate) fn covers(&self, p: Point) -> bool {
        self.strokes
            .iter()
            .any(|&([a, b], width)| segment_distance(p, a, b) <= width / 2.0)
            || self.polygons.iter().any(|poly| inside(p, poly))
    }

    /// Each pixel's Euclidean distance to the nearest shape pixel (0 on the
    /// shape) on a `size` x `size` grid, row-major.
    pub(crate) fn distance_map(&self, size: usize) -> Vec<f64> {
        let mut sq: Vec<f64> = (0..size * size)
            .map(|k| {
                let p = ((k % size) as f64 + 0.5, (k / size) as f64 + 0.5);
                if self.covers(p) {
                    0.0
                } else {
                    f64::INFINITY
                }
            })
            .collect();
        squared_distance_transform(&mut sq, size, size);
        sq.into_iter().map(f64::sqrt).collect()
    }

    /// The shape's field on a `size` x `size` grid: 1 on the shape,
    /// `1 - distance / falloff` off it, at least 0.
    pub(crate) fn field(&self, size: usize, falloff: f64) -> ScalarField {
        let values = self
            .distance_map(size)
            .into_iter()
            .map(|d| (1.0 - d / falloff).max(0.0) as f32)
            .collect();
        ScalarField::new(size, size, values).expect("size x size values")
    }
}

/// Whether `p` lies inside the polygon `poly` (even-odd rule).
fn inside(p: Point, poly: &[Point]) -> bool {
    let mut crossings = false;
    for (i, &a) in poly.iter().enumerate() {
        let b = poly[(i + 1) % poly.len()];
        if (a.1 > p.1) != (b.1 > p.1) && p.0 < a.0 + (p.1 - a.1) * (b.0 - a.0) / (b.1 - a.1) {
            crossings = !crossings;
        }
    }
    crossings
}

/// Distance from `p` to the segment `a`-`b`.
fn segment_distance(p: (f64, f64), a: (f64, f64), b: (f64, f64)) -> f64 {
    let (dx, dy) = (b.0 - a.0, b.1 - a.1);
    let t = (((p.0 - a.0) * dx + (p.1 - a.1) * dy) / (dx * dx + dy * dy)).clamp(0.0, 1.0);
    (p.0 - a.0 - t * dx).hypot(p.1 - a.1 - t * dy)
}

/// Exact squared Euclidean distance transform in place (Felzenszwalb and
/// Huttenlocher): `grid` holds 0 on features and infinity elsewhere; rows
/// then columns.
fn squared_distance_transform(grid: &mut [f64], width: usize, height: usize) {
    let mut line = vec![0.0; width.max(height)];
    let mut out = vec![0.0; width.max(height)];
    for y in 0..height {
        line[..width].copy_from_slice(&grid[y * width..(y + 1) * width]);
        lower_envelope(&line[..width], &mut out[..width]);
        grid[y * width..(y + 1) * width].copy_from_slice(&out[..width]);
    }
    for x in 0..width {
        for y in 0..height {
            line[y] = grid[y * width + x];
        }
        lower_envelope(&line[..height], &mut out[..height]);
        for y in 0..height {
            grid[y * width + x] = out[y];
        }
    }
}

/// One dimension of the transform: `out[q] = min_p (q - p)^2 + f[p]`, over
/// the finite entries of `f` (all infinite gives infinity everywhere).
fn lower_envelope(f: &[f64], out: &mut [f64]) {
    let n = f.len();
    let mut v = vec![0usize; n];
    let mut z = vec![0.0f64; n + 1];
    let mut finite = (0..n).filter(|&q| f[q].is_finite());
    let Some(first) = finite.next() else {
        out.fill(f64::INFINITY);
        return;
    };
    let mut k = 0usize;
    v[0] = first;
    z[0] = f64::NEG_INFINITY;
    z[1] = f64::INFINITY;
    for q in finite {
        // z[0] is minus infinity, so k never drops below 0
        let s = loop {
            let p = v[k];
            let s =
                ((f[q] + (q * q) as f64) - (f[p] + (p * p) as f64)) / (2.0 * (q as f64 - p as f64));
            if s > z[k] {
                break s;
            }
            k -= 1;
        };
        k += 1;
        v[k] = q;
        z[k] = s;
        z[k + 1] = f64::INFINITY;
    }
    let mut k = 0;
    for (q, o) in out.iter_mut().enumerate() {
        while z[k + 1] < q as f64 {
            k += 1;
        }
        let d = q as f64 - v[k] as f64;
        *o = d * d + f[v[k]];
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn distance_transform_is_exact_on_a_small_grid() {
        let (w, h) = (7, 5);
        let features = [(1usize, 1usize), (5, 3)];
        let mut g: Vec<f64> = (0..w * h)
            .map(|k| {
                if features.contains(&(k % w, k / w)) {
                    0.0
                } else {
                    f64::INFINITY
                }
            })
            .collect();
        squared_distance_transform(&mut g, w, h);
        for (k, &got) in g.iter().enumerate() {
            let (x, y) = ((k % w) as f64, (k / w) as f64);
            let brute = features
                .iter()
                .map(|&(fx, fy)| (x - fx as f64).powi(2) + (y - fy as f64).powi(2))
                .fold(f64::INFINITY, f64::min);
            assert_eq!(got, brute, "cell {k}");
        }
    }

    #[test]
    fn a_filled_square_covers_its_inside_and_nothing_outside() {
        let square = Drawing {
            strokes: vec![],
            polygons: vec![vec![(10.0, 10.0), (20.0, 10.0), (20.0, 20.0), (10.0, 20.0)]],
        };
        assert!(square.covers((15.0, 15.0)));
        assert!(square.covers((10.5, 19.5)));
        assert!(!square.covers((9.5, 15.0)));
        assert!(!square.covers((15.0, 20.5)));
    }

    #[test]
    fn a_stroke_covers_half_its_width_around_its_centre_line() {
        let stroke = Drawing {
            strokes: vec![([(10.0, 10.0), (50.0, 10.0)], 8.0)],
            polygons: vec![],
        };
        assert!(stroke.covers((30.0, 13.9)));
        assert!(!stroke.covers((30.0, 14.1)));
        assert!(stroke.covers((6.5, 10.0)), "round cap");
        assert!(!stroke.covers((5.5, 10.0)));
    }
}
