//! The spatial grid broad phase: cells in row-major order whose
//! bodies are stored cell by cell in one array, so that the cells of a
//! row that a query covers are one contiguous slice.
//!
//! Each slot holds a copy of a body's centre and radius: a query reads
//! nothing else. The grid is updated whenever a body moves, so it always
//! matches the current positions; when a body changes cell, the slots
//! between its old and new place shift by one. Updates and queries
//! allocate nothing.

use crate::base::vec2::Vec2;

/// A body as a neighbour query sees it.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Neighbour {
    /// Centre.
    pub pos: Vec2,
    /// Radius.
    pub radius: f64,
    /// Body index.
    pub body: u32,
}

/// Bodies binned by the cell of their centre. Positions outside the arena
/// fall in the outermost cells of the arena, which keeps every query a
/// superset of the bodies it must find.
///
/// A ring of cells that stay empty surrounds the arena's `cols` x `rows`
/// cells, so that the eight cells around any body's cell exist: the
/// neighbourhood of a body is three runs of three cells, found from its
/// cell index alone ([`SpatialGrid::any_around`]).
#[derive(Clone, Debug)]
pub(crate) struct SpatialGrid {
    /// Columns per unit of x, rows per unit of y.
    cells_per_unit: Vec2,
    /// The smaller of a cell's width and height.
    cell_width: f64,
    /// Cells across the arena.
    cols: usize,
    /// Cells down the arena.
    rows: usize,
    /// Cells across the arena and its empty ring: `cols + 2`.
    stride: usize,
    /// Cell `c` holds the slots `start[c] .. start[c + 1]`.
    start: Vec<u32>,
    /// The bodies, cell by cell.
    slots: Vec<Neighbour>,
    /// Each body's slot.
    slot_of: Vec<u32>,
    /// Each body's cell, `row * stride + col` (the ring counted).
    cell_of: Vec<u32>,
}

impl SpatialGrid {
    /// A grid over an arena of `size` (width, height) with cells of at
    /// least `min_cell` units each way, holding bodies of the given centres
    /// and radii.
    pub fn new(
        size: Vec2,
        min_cell: f64,
        bodies: impl ExactSizeIterator<Item = (Vec2, f64)>,
    ) -> SpatialGrid {
        let count = |side: f64| ((side / min_cell).floor() as usize).clamp(1, u16::MAX as usize);
        let (cols, rows) = (count(size.x), count(size.y));
        let mut grid = SpatialGrid {
            cells_per_unit: Vec2::new(cols as f64 / size.x, rows as f64 / size.y),
            cell_width: 1.0 / (cols as f64 / size.x).max(rows as f64 / size.y),
            cols,
            rows,
            stride: cols + 2,
            start: vec![0; (cols + 2) * (rows + 2) + 1],
            slots: bodies
                .enumerate()
                .map(|(body, (pos, radius))| Neighbour {
                    pos,
                    radius,
                    body: body as u32,
                })
                .collect(),
            slot_of: Vec::new(),
            cell_of: Vec::new(),
        };
        // Slots in cell order (a stable sort: by body within a cell); each
        // cell starts where the counts of the cells before it end.
        grid.cell_of = grid.slots.iter().map(|n| grid.cell(n.pos)).collect();
        grid.slots.sort_by_key(|n| grid.cell_of[n.body as usize]);
        grid.slot_of = vec![0; grid.slots.len()];
        for (slot, n) in grid.slots.iter().enumerate() {
            grid.slot_of[n.body as usize] = slot as u32;
        }
        for &cell in &grid.cell_of {
            grid.start[cell as usize + 1] += 1;
        }
        for c in 1..grid.start.len() {
            grid.start[c] += grid.start[c - 1];
        }
        grid
    }

    /// Column index of an x coordinate, clamped to the arena's cells (the
    /// empty ring excluded: from 1 to `cols`). (`as` truncates, which is
    /// the floor for the non-negative values it sees; `floor` would be a
    /// libm call on baseline x86-64, and a cast to `u32` is cheaper than
    /// one to `usize`.)
    #[inline]
    fn column(&self, x: f64) -> usize {
        ((x * self.cells_per_unit.x) as u32 as usize).min(self.cols - 1) + 1
    }

    /// Row index of a y coordinate, as [`SpatialGrid::column`].
    #[inline]
    fn row(&self, y: f64) -> usize {
        ((y * self.cells_per_unit.y) as u32 as usize).min(self.rows - 1) + 1
    }

    #[inline]
    fn cell(&self, p: Vec2) -> u32 {
        (self.row(p.y) * self.stride + self.column(p.x)) as u32
    }

    /// Records that `body` is now at `p`.
    #[inline]
    pub fn moved(&mut self, body: usize, p: Vec2) {
        let cell = self.cell(p);
        let from = self.cell_of[body];
        if cell != from {
            self.relink(body, from, cell);
        }
        self.slots[self.slot_of[body] as usize].pos = p;
    }

    /// Carries a body from cell `from` to cell `to` (the rare case of
    /// [`SpatialGrid::moved`]): the slots in between shift by one towards
    /// the body's old slot, keeping their cells, and every cell boundary in
    /// between moves by one.
    #[cold]
    #[inline(never)]
    fn relink(&mut self, body: usize, from: u32, to: u32) {
        let (from, to, slot) = (from as usize, to as usize, self.slot_of[body] as usize);
        let target = if from < to {
            let target = self.start[to] as usize - 1;
            self.slots[slot..=target].rotate_left(1);
            self.start[from + 1..=to].iter_mut().for_each(|b| *b -= 1);
            target
        } else {
            let target = self.start[to + 1] as usize;
            self.slots[target..=slot].rotate_right(1);
            self.start[to + 1..=from].iter_mut().for_each(|b| *b += 1);
            target
        };
        for k in slot.min(target)..=slot.max(target) {
            self.slot_of[self.slots[k].body as usize] = k as u32;
        }
        self.cell_of[body] = to as u32;
    }

    /// Calls `pred` with the bodies of each row of the cells that overlap
    /// the box `min ..= max` (a superset of the bodies inside the box),
    /// until it returns true; returns whether it did.
    #[inline]
    pub(crate) fn any_in_box(
        &self,
        min: Vec2,
        max: Vec2,
        mut pred: impl FnMut(&[Neighbour]) -> bool,
    ) -> bool {
        let (first_col, last_col) = (self.column(min.x), self.column(max.x));
        for row in self.row(min.y)..self.row(max.y) + 1 {
            let base = row * self.stride;
            let (from, to) = (
                self.start[base + first_col],
                self.start[base + last_col + 1],
            );
            if pred(&self.slots[from as usize..to as usize]) {
                return true;
            }
        }
        false
    }

    /// Calls `pred` with the bodies of body `body`'s cell and the eight
    /// around it, one row of three cells at a time (every body whose
    /// centre is less than a cell's width away from `body`'s, and others),
    /// until it returns true; returns whether it did.
    #[inline]
    pub(crate) fn any_around(
        &self,
        body: usize,
        mut pred: impl FnMut(&[Neighbour]) -> bool,
    ) -> bool {
        let cell = self.cell_of[body] as usize;
        [cell - self.stride, cell, cell + self.stride]
            .into_iter()
            .any(|mid| {
                let (from, to) = (self.start[mid - 1], self.start[mid + 2]);
                pred(&self.slots[from as usize..to as usize])
            })
    }

    /// Writes to the start of `out` the bodies of body `body`'s cell and
    /// the eight around it (those of [`SpatialGrid::any_around`]) whose
    /// centres lie closer to `centre` than `sqrt(reach2)`, `body` itself
    /// among them if it does; returns how many, and how many of those lie
    /// closer than `sqrt(close2)`. `out` needs a slot for every body.
    #[inline]
    pub(crate) fn gather_around(
        &self,
        body: usize,
        centre: Vec2,
        reach2: f64,
        close2: f64,
        out: &mut [u32],
    ) -> (usize, usize) {
        let cell = self.cell_of[body] as usize;
        let (mut len, mut close) = (0, 0);
        for mid in [cell - self.stride, cell, cell + self.stride] {
            // Each body is written to the next free slot and kept only if
            // it is near: no branch to mispredict.
            for n in &self.slots[self.start[mid - 1] as usize..self.start[mid + 2] as usize] {
                let d2 = (n.pos - centre).length_squared();
                out[len] = n.body;
                len += usize::from(d2 < reach2);
                close += usize::from(d2 < close2);
            }
        }
        (len, close)
    }

    /// The smaller of a cell's width and height.
    #[inline]
    pub(crate) fn cell_width(&self) -> f64 {
        self.cell_width
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn grid(size: f64, cell: f64, pts: &[Vec2]) -> SpatialGrid {
        SpatialGrid::new(Vec2::new(size, size), cell, pts.iter().map(|&p| (p, 1.0)))
    }

    fn found(g: &SpatialGrid, min: Vec2, max: Vec2) -> Vec<u32> {
        let mut v = Vec::new();
        g.any_in_box(min, max, |row| {
            v.extend(row.iter().map(|n| n.body));
            false
        });
        v.sort();
        v
    }

    #[test]
    fn moved_bodies_are_found_in_their_new_cell_only() {
        let pts = [
            Vec2::new(5.0, 5.0),
            Vec2::new(100.0, 100.0),
            Vec2::new(-3.0, 900.0),
        ];
        let mut g = grid(800.0, 20.0, &pts);
        assert_eq!(
            found(&g, Vec2::new(0.0, 0.0), Vec2::new(10.0, 10.0)),
            vec![0]
        );
        // clamped into the bottom-left border cell
        assert_eq!(
            found(&g, Vec2::new(0.0, 790.0), Vec2::new(1.0, 799.0)),
            vec![2]
        );
        g.moved(0, Vec2::new(101.0, 99.0));
        assert_eq!(
            found(&g, Vec2::new(0.0, 0.0), Vec2::new(10.0, 10.0)),
            Vec::<u32>::new()
        );
        assert_eq!(
            found(&g, Vec2::new(95.0, 95.0), Vec2::new(105.0, 105.0)),
            vec![0, 1]
        );
        let mut seen = Vec::new();
        g.any_in_box(Vec2::new(95.0, 95.0), Vec2::new(105.0, 105.0), |row| {
            seen.extend(row.iter().map(|n| (n.body, n.pos)));
            false
        });
        seen.sort_by_key(|s| s.0);
        assert_eq!(seen, vec![(0, Vec2::new(101.0, 99.0)), (1, pts[1])]);
    }

    #[test]
    fn queries_in_wide_grids() {
        let pts: Vec<Vec2> = (0..100)
            .map(|i| Vec2::new(i as f64 * 20.0 + 10.0, 30.0))
            .collect();
        let g = grid(2000.0, 20.0, &pts);
        assert_eq!(
            found(&g, Vec2::new(1250.0, 0.0), Vec2::new(1310.0, 40.0)),
            vec![62, 63, 64, 65]
        );
        assert_eq!(
            found(&g, Vec2::new(0.0, 0.0), Vec2::new(2000.0, 2000.0)).len(),
            100
        );
    }

    /// A body's neighbourhood holds every body less than a cell's width
    /// away, also at the arena's edges and for bodies outside it.
    #[test]
    fn the_cells_around_a_body_hold_everything_within_a_cell_width() {
        let pts: Vec<Vec2> = (0..400)
            .map(|i| Vec2::new((i * 37 % 113) as f64 - 6.5, (i * 53 % 109) as f64 - 4.5))
            .collect();
        let g = grid(100.0, 10.0, &pts);
        assert_eq!(g.cell_width(), 10.0);
        for (b, p) in pts.iter().enumerate() {
            let mut seen = Vec::new();
            g.any_around(b, |row| {
                seen.extend(row.iter().map(|n| n.body));
                false
            });
            let mut unique = seen.clone();
            unique.sort();
            unique.dedup();
            assert_eq!(unique.len(), seen.len(), "no body twice");
            for (j, q) in pts.iter().enumerate() {
                if (*q - *p).length() < 10.0 {
                    assert!(seen.contains(&(j as u32)), "body {j} near body {b}");
                }
            }
        }
    }

    #[test]
    fn a_rectangular_arena_has_its_own_rows_and_columns_and_clamps_outside_points_into_them() {
        let pts = [
            Vec2::new(5.0, 5.0),
            Vec2::new(395.0, 95.0),
            Vec2::new(500.0, -20.0),
            Vec2::new(200.0, 150.0),
        ];
        let g = SpatialGrid::new(Vec2::new(400.0, 100.0), 20.0, pts.iter().map(|&p| (p, 1.0)));
        assert_eq!((g.cols, g.rows), (20, 5));
        assert_eq!(
            found(&g, Vec2::new(390.0, 90.0), Vec2::new(399.0, 99.0)),
            vec![1]
        );
        assert_eq!(
            found(&g, Vec2::new(195.0, 95.0), Vec2::new(205.0, 99.0)),
            vec![3],
            "below the arena: last row"
        );
        assert_eq!(
            found(&g, Vec2::new(390.0, 0.0), Vec2::new(399.0, 10.0)),
            vec![2]
        );
        assert_eq!(
            found(&g, Vec2::new(0.0, 0.0), Vec2::new(400.0, 100.0)),
            vec![0, 1, 2, 3]
        );
    }

    /// Many bodies carried across many cells in both directions stay
    /// findable exactly where they are, and every slot stays consistent.
    #[test]
    fn long_moves_keep_every_cell_exact() {
        let n = 60;
        let mut pts: Vec<Vec2> = (0..n)
            .map(|i| Vec2::new((i * 37 % 100) as f64, (i * 53 % 100) as f64))
            .collect();
        let mut g = grid(100.0, 10.0, &pts);
        for step in 0..500 {
            let i = step * 7 % n;
            pts[i] = Vec2::new(
                ((step * 31 + 11) % 100) as f64 + 0.5,
                ((step * 17 + 3) % 100) as f64 + 0.5,
            );
            g.moved(i, pts[i]);
            for (c, w) in g.start.windows(2).enumerate() {
                for s in w[0]..w[1] {
                    let nb = g.slots[s as usize];
                    assert_eq!(g.slot_of[nb.body as usize], s);
                    assert_eq!(g.cell_of[nb.body as usize] as usize, c);
                    assert_eq!(g.cell(pts[nb.body as usize]) as usize, c);
                    assert_eq!(nb.pos, pts[nb.body as usize]);
                }
            }
        }
        for (i, p) in pts.iter().enumerate() {
            assert!(found(&g, *p, *p).contains(&(i as u32)));
        }
    }
}
