//! Plane-to-plane perspective maps (homographies): how a camera sees the
//! flat screen. Four point pairs, no three on a line, define one.

/// A homography: `(x, y) -> ((a x + b y + c) / (g x + h y + 1), (d x + e y + f) / (g x + h y + 1))`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Homography {
    /// The 3 x 3 matrix, row-major, the last entry 1.
    m: [f64; 9],
}

impl Homography {
    /// The map taking each of `from` to the same entry of `to`, or `None`
    /// if the points are degenerate (three on a line, or repeated).
    pub fn from_points(from: &[[f64; 2]; 4], to: &[[f64; 2]; 4]) -> Option<Homography> {
        // Eight equations in a..h: for each pair, a x + b y + c - g x X - h y X = X and likewise for Y.
        let mut rows = [[0.0; 9]; 8];
        for (k, (p, q)) in from.iter().zip(to).enumerate() {
            let ([x, y], [u, v]) = (*p, *q);
            rows[2 * k] = [x, y, 1.0, 0.0, 0.0, 0.0, -x * u, -y * u, u];
            rows[2 * k + 1] = [0.0, 0.0, 0.0, x, y, 1.0, -x * v, -y * v, v];
        }
        let h = solve(rows)?;
        let m = [h[0], h[1], h[2], h[3], h[4], h[5], h[6], h[7], 1.0];
        let map = Homography { m };
        // A degenerate quadrilateral solves numerically but maps a corner to infinity.
        from.iter()
            .zip(to)
            .all(|(p, q)| map.apply(*p).is_some_and(|r| close(r, *q)))
            .then_some(map)
    }

    /// Where `p` goes, or `None` if it maps to infinity (the horizon).
    pub fn apply(&self, [x, y]: [f64; 2]) -> Option<[f64; 2]> {
        let m = &self.m;
        let w = m[6] * x + m[7] * y + m[8];
        if w.abs() < 1e-12 {
            return None;
        }
        Some([
            (m[0] * x + m[1] * y + m[2]) / w,
            (m[3] * x + m[4] * y + m[5]) / w,
        ])
    }
}

/// Whether `r` is `q` to the solver's rounding.
fn close(r: [f64; 2], q: [f64; 2]) -> bool {
    let scale = 1.0 + q[0].abs().max(q[1].abs());
    (r[0] - q[0]).abs() <= 1e-6 * scale && (r[1] - q[1]).abs() <= 1e-6 * scale
}

/// Solves 8 linear equations (each row: 8 coefficients, then the right
/// side) by Gaussian elimination with partial pivoting; `None` if singular.
fn solve(mut rows: [[f64; 9]; 8]) -> Option<[f64; 8]> {
    for col in 0..8 {
        let pivot = (col..8).max_by(|&a, &b| rows[a][col].abs().total_cmp(&rows[b][col].abs()))?;
        if rows[pivot][col].abs() < 1e-12 {
            return None;
        }
        rows.swap(col, pivot);
        let pivot_row = rows[col];
        for (r, row) in rows.iter_mut().enumerate() {
            if r != col {
                let factor = row[col] / pivot_row[col];
                for (v, p) in row.iter_mut().zip(pivot_row).skip(col) {
                    *v -= factor * p;
                }
            }
        }
    }
    let mut x = [0.0; 8];
    for (i, row) in rows.iter().enumerate() {
        x[i] = row[8] / row[i];
    }
    Some(x)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn four_corners_map_exactly_and_lines_stay_lines() {
        let square = [[0.0, 0.0], [254.0, 0.0], [254.0, 142.8], [0.0, 142.8]];
        let photo = [
            [210.0, 180.0],
            [1420.0, 140.0],
            [1500.0, 1010.0],
            [120.0, 1060.0],
        ];
        let h = Homography::from_points(&square, &photo).unwrap();
        for (s, p) in square.iter().zip(&photo) {
            let q = h.apply(*s).unwrap();
            assert!(
                (q[0] - p[0]).abs() < 1e-6 && (q[1] - p[1]).abs() < 1e-6,
                "{q:?} {p:?}"
            );
        }
        let back = Homography::from_points(&photo, &square).unwrap();
        let mid = back.apply(h.apply([100.0, 50.0]).unwrap()).unwrap();
        assert!(
            (mid[0] - 100.0).abs() < 1e-6 && (mid[1] - 50.0).abs() < 1e-6,
            "{mid:?}"
        );
        // The middle of the top edge lies on the photo's top edge.
        let top = h.apply([127.0, 0.0]).unwrap();
        let (edge, to_top) = (
            [photo[1][0] - photo[0][0], photo[1][1] - photo[0][1]],
            [top[0] - photo[0][0], top[1] - photo[0][1]],
        );
        let cross = edge[0] * to_top[1] - edge[1] * to_top[0];
        assert!(cross.abs() < 1e-6, "{cross}");
    }

    #[test]
    fn three_corners_on_a_line_are_refused() {
        let square = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]];
        let line = [[0.0, 0.0], [1.0, 1.0], [2.0, 2.0], [0.0, 5.0]];
        assert_eq!(Homography::from_points(&square, &line), None);
        assert_eq!(Homography::from_points(&square, &[[3.0, 3.0]; 4]), None);
    }
}
