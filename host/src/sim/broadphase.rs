//! Neighbour search behind one interface: the spatial grid or all pairs.
//!
//! Both answer with supersets of the exact answer and the callers apply the
//! exact test afterwards, in a canonical order, so the choice never changes
//! a result.

use super::body::Body;
use super::config::BroadPhase;
use super::grid::{Neighbour, SpatialGrid};
use super::vec2::Vec2;

/// The neighbour index of a world.
#[derive(Clone, Debug)]
pub enum NeighbourIndex {
    /// Bodies binned in a [`SpatialGrid`].
    Grid(SpatialGrid),
    /// No index: every body is a candidate.
    Naive,
}

impl NeighbourIndex {
    /// An index of the given kind over `bodies` in a `size` x `size`
    /// arena, with grid cells of at least `cell` units.
    pub fn new(kind: BroadPhase, size: f64, cell: f64, bodies: &[Body]) -> NeighbourIndex {
        match kind {
            BroadPhase::Grid => NeighbourIndex::Grid(SpatialGrid::new(size, cell, cell, bodies.iter().map(|b| (b.pos, b.radius)))),
            BroadPhase::Naive => NeighbourIndex::Naive,
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
    /// `r_body + r_j + margin`, in ascending order; `max_radius` bounds
    /// every `r_j`.
    pub fn contact_candidates(
        &self,
        bodies: &[Body],
        body: usize,
        after: Option<usize>,
        max_radius: f64,
        margin: f64,
        out: &mut Vec<u32>,
    ) {
        out.clear();
        let first = after.map_or(0, |a| a as u32 + 1);
        let (pos, radius) = (bodies[body].pos, bodies[body].radius);
        let half = radius + max_radius + margin;
        self.any_in_box(bodies, pos - Vec2::new(half, half), pos + Vec2::new(half, half), |n| {
            let j = n.body;
            let reach = radius + n.radius + margin;
            if j as usize == body || j < first || (n.pos - pos).length_squared() >= reach * reach {
                return false;
            }
            // Insertion keeps the short list sorted without a sort call.
            out.push(j);
            let mut k = out.len() - 1;
            while k > 0 && out[k - 1] > j {
                out[k] = out[k - 1];
                k -= 1;
            }
            out[k] = j;
            false
        });
    }

    /// Whether `pred` holds for some body of a superset of those whose
    /// centres lie in the box `min ..= max`; stops at the first.
    #[inline]
    pub fn any_in_box(&self, bodies: &[Body], min: Vec2, max: Vec2, mut pred: impl FnMut(&Neighbour) -> bool) -> bool {
        match self {
            NeighbourIndex::Grid(g) => g.any_in_box(min, max, pred),
            NeighbourIndex::Naive => bodies
                .iter()
                .enumerate()
                .any(|(j, b)| pred(&Neighbour { pos: b.pos, radius: b.radius, body: j as u32 })),
        }
    }
}
