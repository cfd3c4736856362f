//! Neighbour search: which bodies a contact check or a sensor must test.
//!
//! Both modes are a [`SpatialGrid`]: the grid mode with cells the size of
//! the largest contact reach, the all-pairs mode (`--naive`) with a single
//! cell, so that every query sees every body. Queries answer with
//! supersets of the exact answer and the callers apply the exact test
//! afterwards, in a canonical order, so the mode never changes a result.

use crate::base::vec2::Vec2;
use crate::config::BroadPhase;
use crate::physics::body::Body;
use crate::physics::grid::{Neighbour, SpatialGrid};

/// The neighbour index of a world.
#[derive(Clone, Debug)]
pub(crate) struct NeighbourIndex {
    grid: SpatialGrid,
}

/// Contact candidates of one body, ascending by index (a reused buffer).
#[derive(Clone, Debug, Default)]
pub(crate) struct Candidates {
    /// One slot per body, so that gathering can write before it decides.
    slots: Vec<u32>,
    len: usize,
}

impl Candidates {
    /// A buffer for a world of `bodies` bodies.
    pub fn new(bodies: usize) -> Candidates {
        Candidates {
            slots: vec![0; bodies],
            len: 0,
        }
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
        NeighbourIndex {
            grid: SpatialGrid::new(size, cell, bodies.iter().map(|b| (b.pos, b.radius))),
        }
    }

    /// Records a body's new position.
    #[inline]
    pub fn moved(&mut self, body: usize, p: Vec2) {
        self.grid.moved(body, p);
    }

    /// Fills `out` with every body `j` (other than `body`, with an index
    /// above `after` if given) whose centre is closer to `body`'s than
    /// `r_body + r_j + margin`, in ascending order; `max_radius` bounds
    /// every `r_j`, and `out` may hold others. A first gather (`after` is
    /// `None`) leaves `out` empty when nothing can overlap `body` by more
    /// than `threshold` (no centre closer than `r_body + max_radius -
    /// threshold`, which bounds the contact test's `r_body + r_j -
    /// threshold`): then the turn would test them all and change nothing.
    #[allow(
        clippy::too_many_arguments,
        reason = "the hot contact query takes its inputs as plain values; a struct built per call would cost a copy"
    )]
    pub(crate) fn contact_candidates(
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
        // One bound for every body (`r_j <= max_radius`) for being near,
        // and one for overlapping by more than the threshold: supersets,
        // which the turn's own test narrows down. Body `body` is within
        // both (when anything can overlap at all).
        let touch = radius + max_radius - threshold;
        let (len, close) = if half <= self.grid.cell_width() * (1.0 - 1e-9) {
            self.grid
                .gather_around(body, pos, half * half, touch * touch, &mut out.slots)
        } else {
            self.gather_in_box(pos, half, touch, &mut out.slots)
        };
        if after.is_none() && (close < 2 || touch <= 0.0) {
            // Nothing overlaps `body` by more than the threshold.
            out.len = 0;
            return;
        }
        // Insertion sort (the list is short) of what the turn still tests:
        // not the body itself, and after a re-gather in the middle of a
        // turn only bodies above `after`. Each kept body is written at or
        // before the place it was read from.
        let first = after.map_or(0, |a| a + 1);
        let mut kept = 0;
        for k in 0..len {
            let j = out.slots[k];
            if (j as usize == body) | ((j as usize) < first) {
                continue;
            }
            let mut at = kept;
            while at > 0 && out.slots[at - 1] > j {
                out.slots[at] = out.slots[at - 1];
                at -= 1;
            }
            out.slots[at] = j;
            kept += 1;
        }
        out.len = kept;
    }

    /// [`SpatialGrid::gather_around`] for a reach beyond a cell's width:
    /// the bodies in the square of half-side `half` around `pos` closer
    /// than `half`, and how many of them closer than `touch`.
    fn gather_in_box(&self, pos: Vec2, half: f64, touch: f64, out: &mut [u32]) -> (usize, usize) {
        let (reach2, close2) = (half * half, touch * touch);
        let (mut len, mut close) = (0, 0);
        self.grid.any_in_box(
            pos - Vec2::new(half, half),
            pos + Vec2::new(half, half),
            |row| {
                for n in row {
                    let d2 = (n.pos - pos).length_squared();
                    out[len] = n.body;
                    len += usize::from(d2 < reach2);
                    close += usize::from(d2 < close2);
                }
                false
            },
        );
        (len, close)
    }

    /// Whether `pred` holds for some run of bodies among those visited:
    /// runs that together hold a superset of the bodies whose centres are
    /// closer than `reach` to body `body`'s. Stops at the first run for
    /// which it holds. Within a cell's width (less a hair, so that the
    /// rounding of cell indices cannot matter), the body's cell and the
    /// eight around it are searched, with no box to convert to cells.
    #[inline]
    pub(crate) fn any_around(
        &self,
        bodies: &[Body],
        body: usize,
        reach: f64,
        pred: impl FnMut(&[Neighbour]) -> bool,
    ) -> bool {
        if reach <= self.grid.cell_width() * (1.0 - 1e-9) {
            self.grid.any_around(body, pred)
        } else {
            let pos = bodies[body].pos;
            self.grid.any_in_box(
                pos - Vec2::new(reach, reach),
                pos + Vec2::new(reach, reach),
                pred,
            )
        }
    }

    /// Whether `pred` holds for some run of bodies among those visited:
    /// runs that together hold a superset of the bodies whose centres lie
    /// in the box `min ..= max`. Stops at the first run for which it holds.
    #[inline]
    pub(crate) fn any_in_box(
        &self,
        min: Vec2,
        max: Vec2,
        pred: impl FnMut(&[Neighbour]) -> bool,
    ) -> bool {
        self.grid.any_in_box(min, max, pred)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::base::rng::SimRng;
    use rand::{RngExt, SeedableRng};

    /// Contact candidates are what the turn needs, in both broad phases and
    /// with bodies of three sizes: every body closer than `r_i + r_j +
    /// margin` (and above `after`), ascending, never the body itself; a
    /// first gather is empty only when it holds nothing that overlaps by
    /// more than the threshold.
    #[test]
    fn contact_candidates_hold_every_near_body_in_order_and_are_empty_only_when_nothing_overlaps() {
        let mut rng = SimRng::seed_from_u64(5);
        let (size, margin, threshold) = (Vec2::new(300.0, 200.0), 2.5, 0.1);
        let (mut empty, mut turns) = (0, 0);
        for scene in 0..40 {
            let radii = [10.0, 4.0, 7.0];
            let max_radius = 10.0;
            // Dense enough that many bodies touch; some outside the arena.
            let bodies: Vec<Body> = (0..150)
                .map(|k| {
                    let p = Vec2::new(
                        rng.random_range(-5.0..size.x + 5.0),
                        rng.random_range(-5.0..size.y + 5.0),
                    );
                    Body::new(p, radii[k % 3])
                })
                .collect();
            for kind in [BroadPhase::Grid, BroadPhase::Naive] {
                let index = NeighbourIndex::new(kind, size, (2.0 + 0.25) * max_radius, &bodies);
                let mut out = Candidates::new(bodies.len());
                for (i, b) in bodies.iter().enumerate() {
                    let near: Vec<u32> = (0..bodies.len() as u32)
                        .filter(|&j| j as usize != i)
                        .filter(|&j| {
                            let o = &bodies[j as usize];
                            let reach = b.radius + o.radius + margin;
                            (o.pos - b.pos).length_squared() < reach * reach
                        })
                        .collect();
                    let overlapping = near.iter().any(|&j| {
                        let o = &bodies[j as usize];
                        let touch = b.radius + o.radius - threshold;
                        (o.pos - b.pos).length_squared() < touch * touch
                    });
                    index.contact_candidates(
                        &bodies, i, None, max_radius, margin, threshold, &mut out,
                    );
                    let found = out.as_slice().to_vec();
                    assert!(
                        !(overlapping && found.is_empty()),
                        "scene {scene}, {kind:?}, body {i}"
                    );
                    empty += usize::from(found.is_empty());
                    check_candidates(&found, &near, i, 0);
                    turns += 1;
                    let after = i.saturating_sub(3);
                    index.contact_candidates(
                        &bodies,
                        i,
                        Some(after),
                        max_radius,
                        margin,
                        threshold,
                        &mut out,
                    );
                    let later: Vec<u32> = near
                        .iter()
                        .copied()
                        .filter(|&j| j as usize > after)
                        .collect();
                    check_candidates(out.as_slice(), &later, i, after + 1);
                }
            }
        }
        assert!(
            empty > 1_000 && turns - empty > 1_000,
            "both outcomes tested: {empty} empty of {turns}"
        );
    }

    /// `found` holds every body of `near`, ascending, without `body` or any
    /// below `first`.
    fn check_candidates(found: &[u32], near: &[u32], body: usize, first: usize) {
        assert!(
            found.windows(2).all(|w| w[0] < w[1]),
            "ascending: {found:?}"
        );
        assert!(
            found
                .iter()
                .all(|&j| j as usize != body && j as usize >= first),
            "{found:?}"
        );
        if !found.is_empty() {
            assert!(
                near.iter().all(|j| found.contains(j)),
                "{near:?} in {found:?}"
            );
        }
    }
}
