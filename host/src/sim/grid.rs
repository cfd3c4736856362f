//! The spatial grid broad phase: square cells, each an intrusive doubly
//! linked list of the bodies whose centres lie in it.
//!
//! The grid is updated whenever a body moves, so it always matches the
//! current positions. With a cell side of at least the largest contact
//! distance (twice the largest radius), every body that can overlap a body
//! in cell C lies in the 3 x 3 cells around C. Updates and queries allocate
//! nothing.

use super::vec2::Vec2;

const NONE: u32 = u32::MAX;

/// Bodies binned by the cell of their centre. Positions outside the arena
/// fall in the border cells, which keeps every query a superset of the
/// bodies it must find.
#[derive(Clone, Debug)]
pub struct SpatialGrid {
    cells_per_unit: f64,
    cols: usize,
    head: Vec<u32>,
    next: Vec<u32>,
    prev: Vec<u32>,
    /// Each body's cell as `row << 16 | col`.
    cell_of: Vec<u32>,
}

impl SpatialGrid {
    /// A grid over a `size` x `size` arena with cells of at least
    /// `min_cell` units, holding `positions`.
    pub fn new(size: f64, min_cell: f64, positions: impl ExactSizeIterator<Item = Vec2>) -> SpatialGrid {
        let cols = ((size / min_cell).floor() as usize).clamp(1, u16::MAX as usize);
        let n = positions.len();
        let mut grid = SpatialGrid {
            cells_per_unit: cols as f64 / size,
            cols,
            head: vec![NONE; cols * cols],
            next: vec![NONE; n],
            prev: vec![NONE; n],
            cell_of: vec![NONE; n],
        };
        for (body, p) in positions.enumerate() {
            grid.insert(body as u32, grid.cell(p));
        }
        grid
    }

    /// Column or row index of a coordinate, clamped to the grid. (`as`
    /// truncates, which is the floor for the non-negative values it sees;
    /// `floor` would be a libm call on baseline x86-64, and a cast to `u32`
    /// is cheaper than one to `usize`.)
    #[inline]
    fn axis(&self, v: f64) -> usize {
        ((v * self.cells_per_unit) as u32 as usize).min(self.cols - 1)
    }

    #[inline]
    fn cell(&self, p: Vec2) -> u32 {
        ((self.axis(p.y) as u32) << 16) | self.axis(p.x) as u32
    }

    #[inline]
    fn unpack(&self, cell: u32) -> (usize, usize) {
        ((cell >> 16) as usize, (cell & 0xFFFF) as usize)
    }

    fn insert(&mut self, body: u32, cell: u32) {
        let (row, col) = self.unpack(cell);
        let slot = row * self.cols + col;
        let b = body as usize;
        let old_head = self.head[slot];
        self.next[b] = old_head;
        self.prev[b] = NONE;
        if old_head != NONE {
            self.prev[old_head as usize] = body;
        }
        self.head[slot] = body;
        self.cell_of[b] = cell;
    }

    fn remove(&mut self, body: u32) {
        let b = body as usize;
        let (prev, next) = (self.prev[b], self.next[b]);
        if prev == NONE {
            let (row, col) = self.unpack(self.cell_of[b]);
            self.head[row * self.cols + col] = next;
        } else {
            self.next[prev as usize] = next;
        }
        if next != NONE {
            self.prev[next as usize] = prev;
        }
    }

    /// Records that `body` is now at `p`.
    #[inline]
    pub fn moved(&mut self, body: usize, p: Vec2) {
        let cell = self.cell(p);
        if cell != self.cell_of[body] {
            self.relink(body as u32, cell);
        }
    }

    /// Moves a body to another cell (the rare case of [`SpatialGrid::moved`]).
    #[cold]
    #[inline(never)]
    fn relink(&mut self, body: u32, cell: u32) {
        self.remove(body);
        self.insert(body, cell);
    }

    /// The cell a body is registered in.
    #[inline]
    pub fn cell_of(&self, body: usize) -> u32 {
        self.cell_of[body]
    }

    /// Calls `visit` for every body in the cells of rows `rows` and columns
    /// `cols` (half-open ranges) until it returns true; returns whether it did.
    #[inline]
    fn visit(&self, rows: (usize, usize), cols: (usize, usize), mut visit: impl FnMut(usize) -> bool) -> bool {
        for row in rows.0..rows.1 {
            let start = row * self.cols;
            for &first in &self.head[start + cols.0..start + cols.1] {
                let mut b = first;
                while b != NONE {
                    if visit(b as usize) {
                        return true;
                    }
                    b = self.next[b as usize];
                }
            }
        }
        false
    }

    /// Whether `pred` holds for some body whose centre lies in a cell that
    /// overlaps the box `min ..= max` (a superset of the bodies inside the
    /// box); stops at the first.
    #[inline]
    pub fn any_in_box(&self, min: Vec2, max: Vec2, pred: impl FnMut(usize) -> bool) -> bool {
        self.visit((self.axis(min.y), self.axis(max.y) + 1), (self.axis(min.x), self.axis(max.x) + 1), pred)
    }

    /// Calls `f` for every body in the 3 x 3 cells around `cell`.
    #[inline]
    pub fn for_each_near_cell(&self, cell: u32, mut f: impl FnMut(usize)) {
        let (row, col) = self.unpack(cell);
        let end = self.cols;
        self.visit((row.saturating_sub(1), (row + 2).min(end)), (col.saturating_sub(1), (col + 2).min(end)), |b| {
            f(b);
            false
        });
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn found(g: &SpatialGrid, min: Vec2, max: Vec2) -> Vec<usize> {
        let mut v = Vec::new();
        g.any_in_box(min, max, |b| {
            v.push(b);
            false
        });
        v.sort();
        v
    }

    #[test]
    fn moved_bodies_are_found_in_their_new_cell_only() {
        let pts = [Vec2::new(5.0, 5.0), Vec2::new(100.0, 100.0), Vec2::new(-3.0, 900.0)];
        let mut g = SpatialGrid::new(800.0, 20.0, pts.iter().copied());
        assert_eq!(found(&g, Vec2::new(0.0, 0.0), Vec2::new(10.0, 10.0)), vec![0]);
        // clamped into the bottom-left border cell
        assert_eq!(found(&g, Vec2::new(0.0, 790.0), Vec2::new(1.0, 799.0)), vec![2]);
        g.moved(0, Vec2::new(101.0, 99.0));
        assert_eq!(found(&g, Vec2::new(0.0, 0.0), Vec2::new(10.0, 10.0)), Vec::<usize>::new());
        assert_eq!(found(&g, Vec2::new(95.0, 95.0), Vec2::new(105.0, 105.0)), vec![0, 1]);
        let mut near = Vec::new();
        g.for_each_near_cell(g.cell_of(1), |b| near.push(b));
        near.sort();
        assert_eq!(near, vec![0, 1]);
    }

    #[test]
    fn queries_in_wide_grids() {
        let pts: Vec<Vec2> = (0..100).map(|i| Vec2::new(i as f64 * 20.0 + 10.0, 30.0)).collect();
        let g = SpatialGrid::new(2000.0, 20.0, pts.iter().copied());
        assert_eq!(found(&g, Vec2::new(1250.0, 0.0), Vec2::new(1310.0, 40.0)), vec![62, 63, 64, 65]);
        assert_eq!(found(&g, Vec2::new(0.0, 0.0), Vec2::new(2000.0, 2000.0)).len(), 100);
        let mut near = Vec::new();
        g.for_each_near_cell(g.cell_of(63), |b| near.push(b));
        near.sort();
        assert_eq!(near, vec![62, 63, 64]);
    }
}
