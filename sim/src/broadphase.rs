//! Neighbour search: which bodies a contact check or a sensor must test.
//!
//! Both modes are a [`SpatialGrid`]: the grid mode with cells the size of
//! the largest contact reach, the all-pairs mode (`--naive`) with a single
//! cell, so that every query sees every body. Queries answer with
//! supersets of the exact answer and the callers apply the exact test
//! afterwards, in a canonical order, so the mode never changes a result.

use crate::body::Body;
use crate::grid::{Neighbour, SpatialGrid};
use crate::vec2::Vec2;
use serde::{Deserialize, Serialize};

/// How contact candidates and sensor neighbours are found. The choice
/// changes speed only: both resolve contacts in the same canonical order
/// and give bit-identical trajectories.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum BroadPhase {
    /// A uniform spatial grid: a step costs O(bodies).
    #[default]
    Grid,
    /// Every pair of bodies, like the original simulator: O(bodies^2).
    Naive,
}

/// The neighbour index of a world.
#[derive(Clone, Debug)]
pub struct NeighbourIndex {
    grid: SpatialGrid,
}

/// Contact candidates of one body, ascending by index (a reused buffer).
#[derive(Clone, Debug, Default)]
pub struct Candidates {
    /// One slot per body, so that gathering can write before it decides.
    slots: Vec<u32>,
    len: usize,
}

impl Candidates {
    /// A buffer for a world of `bodies` bodies.
    pub fn new(bodies: usize) -> Candidates {
        Candidates { slots: vec![0; bodies], len: 0 }
    }

    /// The candidates, ascending.
    #[inline]
    pub fn as_slice(&self) -> &[u32] {
        &self.slots[..self.len]
    }
}

impl NeighbourIndex {
    /// An index of the given kind over `bodies` in an arena of `size`
    /// (width, height); grid cells are at least `cell` units wide.
    pub fn new(kind: BroadPhase, size: Vec2, cell: f64, bodies: &[Body]) -> NeighbourIndex {
        let cell = match kind {
            BroadPhase::Grid => cell,
            BroadPhase::Naive => size.x.max(size.y),
        };
        NeighbourIndex { grid: SpatialGrid::new(size, cell, bodies.iter().map(|b| (b.pos, b.radius))) }
    }

    /// Records a body's new position.
    #[inline]
    pub fn moved(&mut self, body: usize, p: Vec2) {
        self.grid.moved(body, p);
    }

    /// Fills `out` with every body `j` (other than `body`, with an index
    /// above `after` if given) whose centre is closer to `body`'s than
    /// `r_body + r_j + margin`, in ascending order; `max_radius` bounds
    /// every `r_j`. A first gather (`after` is `None`) leaves `out` empty
    /// when none of them overlaps `body` by more than `threshold` (centres
    /// closer than `r_body + r_j - threshold`, the contact test): then the
    /// turn would test them all and change nothing.
    #[allow(clippy::too_many_arguments)]
    pub fn contact_candidates(
        &self,
        bodies: &[Body],
        body: usize,
        after: Option<usize>,
        max_radius: f64,
        margin: f64,
        threshold: f64,
        out: &mut Candidates,
    ) {
        let (pos, radius) = (bodies[body].pos, bodies[body].radius);
        let half = radius + max_radius + margin;
        let mut len = 0;
        // Every body is written to the next free slot and kept only if it
        // qualifies: no branch to mispredict. A query visits each body at
        // most once, so there is always a free slot.
        let gather = |row: &[Neighbour]| {
            for n in row {
                let reach = radius + n.radius + margin;
                let near = (n.pos - pos).length_squared() < reach * reach;
                out.slots[len] = n.body;
                len += usize::from(near & (n.body as usize != body));
            }
            false
        };
        self.any_around(bodies, body, half, gather);
        // The contact test's own arithmetic, so that it decides exactly as
        // the turn would.
        let overlaps = |j: &u32| {
            let other = &bodies[*j as usize];
            let touch = radius + other.radius - threshold;
            !((touch <= 0.0) | ((other.pos - pos).length_squared() >= touch * touch))
        };
        if after.is_none() && !out.slots[..len].iter().any(overlaps) {
            out.len = 0;
            return;
        }
        // Insertion sort: the list is short.
        let found = &mut out.slots[..len];
        for k in 1..found.len() {
            let j = found[k];
            let mut at = k;
            while at > 0 && found[at - 1] > j {
                found[at] = found[at - 1];
                at -= 1;
            }
            found[at] = j;
        }
        // Only a re-gather in the middle of a turn passes `after`: drop
        // what it has already handled.
        let done = after.map_or(0, |a| found.partition_point(|&j| j as usize <= a));
        if done > 0 {
            found.copy_within(done.., 0);
        }
        out.len = len - done;
    }

    /// Whether `pred` holds for some run of bodies among those visited:
    /// runs that together hold a superset of the bodies whose centres are
    /// closer than `reach` to body `body`'s. Stops at the first run for
    /// which it holds. Within a cell's width (less a hair, so that the
    /// rounding of cell indices cannot matter), the body's cell and the
    /// eight around it are searched, with no box to convert to cells.
    #[inline]
    pub fn any_around(&self, bodies: &[Body], body: usize, reach: f64, pred: impl FnMut(&[Neighbour]) -> bool) -> bool {
        if reach <= self.grid.cell_width() * (1.0 - 1e-9) {
            self.grid.any_around(body, pred)
        } else {
            let pos = bodies[body].pos;
            self.grid.any_in_box(pos - Vec2::new(reach, reach), pos + Vec2::new(reach, reach), pred)
        }
    }

    /// Whether `pred` holds for some run of bodies among those visited:
    /// runs that together hold a superset of the bodies whose centres lie
    /// in the box `min ..= max`. Stops at the first run for which it holds.
    #[inline]
    pub fn any_in_box(&self, min: Vec2, max: Vec2, pred: impl FnMut(&[Neighbour]) -> bool) -> bool {
        self.grid.any_in_box(min, max, pred)
    }
}
