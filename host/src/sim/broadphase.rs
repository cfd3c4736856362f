//! Neighbour search behind one interface: the spatial grid or all pairs.
//!
//! Both answer with supersets of the exact answer and the callers apply the
//! exact test afterwards, in a canonical order, so the choice never changes
//! a result.

use super::body::Body;
use super::config::BroadPhase;
use super::grid::SpatialGrid;
use super::vec2::Vec2;

/// The neighbour index of a world.
#[derive(Clone, Debug)]
pub enum NeighbourIndex {
    /// Bodies binned in a [`SpatialGrid`].
    Grid(SpatialGrid),
    /// No index: every body is a candidate.
    Naive {
        /// Number of bodies.
        bodies: usize,
    },
}

impl NeighbourIndex {
    /// An index of the given kind over `positions` in a `size` x `size`
    /// arena. Contact candidates are complete for centre distances up to
    /// `reach` (the largest contact distance plus the candidate margin).
    pub fn new(
        kind: BroadPhase,
        size: f64,
        reach: f64,
        positions: impl ExactSizeIterator<Item = Vec2>,
    ) -> NeighbourIndex {
        match kind {
            BroadPhase::Grid => NeighbourIndex::Grid(SpatialGrid::new(size, reach, positions)),
            BroadPhase::Naive => NeighbourIndex::Naive { bodies: positions.len() },
        }
    }

    /// Records a body's new position.
    #[inline]
    pub fn moved(&mut self, body: usize, p: Vec2) {
        if let NeighbourIndex::Grid(g) = self {
            g.moved(body, p);
        }
    }

    /// Fills `out` with every body `j` (other than `body`, with an index
    /// above `after` if given) whose centre is closer to `body`'s than
    /// `r_body + r_j + margin`, in ascending order. `r_body + r_j + margin`
    /// must not exceed the `reach` the index was built with.
    pub fn contact_candidates(&self, bodies: &[Body], body: usize, after: Option<usize>, margin: f64, out: &mut Vec<u32>) {
        out.clear();
        let first = after.map_or(0, |a| a + 1);
        let b = &bodies[body];
        let consider = |j: usize| {
            if j == body || j < first {
                return;
            }
            let reach = b.radius + bodies[j].radius + margin;
            if (bodies[j].pos - b.pos).length_squared() >= reach * reach {
                return;
            }
            // Insertion keeps the short list sorted without a sort call.
            out.push(j as u32);
            let mut k = out.len() - 1;
            while k > 0 && out[k - 1] as usize > j {
                out[k] = out[k - 1];
                k -= 1;
            }
            out[k] = j as u32;
        };
        match self {
            NeighbourIndex::Grid(g) => g.for_each_near_cell(g.cell_of(body), consider),
            NeighbourIndex::Naive { bodies } => (0..*bodies).for_each(consider),
        }
    }

    /// Whether `pred` holds for some body of a superset of those whose
    /// centres lie in the box `min ..= max`; stops at the first.
    #[inline]
    pub fn any_in_box(&self, min: Vec2, max: Vec2, pred: impl FnMut(usize) -> bool) -> bool {
        match self {
            NeighbourIndex::Grid(g) => g.any_in_box(min, max, pred),
            NeighbourIndex::Naive { bodies } => (0..*bodies).any(pred),
        }
    }
}
