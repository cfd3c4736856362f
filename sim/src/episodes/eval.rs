//! Evaluation of a world against its target shape.
//!
//! - Eval: per puck, the field value `v` at its centre (truncated cell)
//!   gives a distance `T_o - v` below the outie threshold, `v - T_i` above
//!   the innie threshold, 0 between; Eval = 1 - mean(distance) / max(T_o,
//!   1 - T_i), the original code's normalisation (the 0.94 success
//!   threshold was tuned with it). No pucks: 1.
//! - Eval' (thesis chapter 6), two variants; see [`EvalPrime`].

use crate::base::rounding::round_half_away;
use crate::base::vec2::Vec2;
use crate::config::{SimConfig, Thresholds};
use crate::fields::{FieldLayout, FieldSampling, ScalarField};
use crate::world::World;
use serde::{Deserialize, Serialize};
use std::sync::Arc;

/// Whether a field value lies in the band `[T_o, T_i]` (where Eval wants
/// every puck).
pub fn in_band(value: f64, t: &Thresholds) -> bool {
    band_distance(value, t) == 0.0
}

/// Whether each puck lies in the band, looked up as [`eval`] looks it up.
pub fn pucks_in_band<'a>(
    world: &'a World,
    field: &'a ScalarField,
    t: &'a Thresholds,
) -> impl Iterator<Item = bool> + 'a {
    let layout = world.config().field_layout();
    world
        .pucks()
        .iter()
        .map(move |p| fixed_distance(p.pos, &layout, field, t) == 0)
}

/// How far a field value lies outside the band `[T_o, T_i]`.
pub(crate) fn band_distance(value: f64, t: &Thresholds) -> f64 {
    if value < t.outie {
        t.outie - value
    } else if value > t.innie {
        value - t.innie
    } else {
        0.0
    }
}

/// One unit of band distance in the fixed point Eval sums in: 2^-32.
const DISTANCE_ONE: f64 = 4_294_967_296.0;

/// A puck's band distance in fixed point. Summing integers makes Eval
/// independent of the order of the sum, so [`EvalTracker`]'s running total
/// equals a fresh [`eval`] exactly; the rounding (at most 2^-33 per puck)
/// is far below anything Eval is compared with.
fn fixed_distance(p: Vec2, layout: &FieldLayout, field: &ScalarField, t: &Thresholds) -> u64 {
    fixed_of_value(field.evaluate(p, layout), t)
}

/// The fixed-point band distance of a field value (a distance of at most
/// 1, so the rounded value fits `i64` and is not negative).
fn fixed_of_value(value: f32, t: &Thresholds) -> u64 {
    round_half_away(band_distance(f64::from(value), t) * DISTANCE_ONE) as u64
}

/// Each puck position's fixed-point distance, the way [`fixed_distance`]
/// finds it: with nearest sampling from a table of every cell's distance
/// (a cell index and a load instead of the conversion and rounding of each
/// moved puck: Eval every step is a learner's reward; one table per field
/// and thresholds, shared by the worlds of a batch,
/// [`ScalarField::derived_table`]), with bilinear sampling by the formula.
#[derive(Clone, Debug, PartialEq)]
enum Distances {
    /// Nearest sampling: each cell's distance, and that of the outside.
    ByCell { cells: Arc<[u64]>, outside: u64 },
    /// Bilinear sampling.
    Interpolated,
}

impl Distances {
    fn new(field: &ScalarField, layout: &FieldLayout, t: &Thresholds) -> Distances {
        match layout.sampling {
            FieldSampling::Nearest => Distances::ByCell {
                cells: field.derived_table([t.outie.to_bits(), t.innie.to_bits()], |values| {
                    values.iter().map(|&v| fixed_of_value(v, t)).collect()
                }),
                outside: fixed_of_value(0.0, t),
            },
            FieldSampling::Bilinear => Distances::Interpolated,
        }
    }

    #[inline]
    fn at(&self, p: Vec2, layout: &FieldLayout, field: &ScalarField, t: &Thresholds) -> u64 {
        match self {
            Distances::ByCell { cells, outside } => field
                .truncated_cell(p, &layout.frame)
                .map_or(*outside, |k| cells[k]),
            Distances::Interpolated => fixed_distance(p, layout, field, t),
        }
    }
}

/// Eval from the sum of the pucks' fixed-point distances.
fn eval_of(total: u64, pucks: usize, t: &Thresholds) -> f64 {
    1.0 - eval_loss(total as f64, pucks, t)
}

/// What a fixed-point distance (summed, or one puck's change) takes off
/// Eval.
fn eval_loss(distance: f64, pucks: usize, t: &Thresholds) -> f64 {
    let scale = t.outie.max(1.0 - t.innie);
    if pucks == 0 || scale <= 0.0 {
        return 0.0;
    }
    distance / DISTANCE_ONE / pucks as f64 / scale
}

/// One puck whose band distance changed in the last Eval update, and by
/// how much that changed Eval (the changes of one update sum to Eval's).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PuckChange {
    /// The puck's body index.
    pub body: u32,
    /// Its change of Eval: positive when it moved towards the band.
    pub eval_change: f64,
}

/// Eval of the pucks' positions, 1 when every puck is in the band.
pub fn eval(world: &World, field: &ScalarField, t: &Thresholds) -> f64 {
    let layout = world.config().field_layout();
    let total = world
        .pucks()
        .iter()
        .map(|p| fixed_distance(p.pos, &layout, field, t))
        .sum();
    eval_of(total, world.pucks().len(), t)
}

/// Eval kept current as the world steps: only the pucks that moved since
/// the last update are looked up again, so Eval every step (a learner's
/// reward) costs a few lookups instead of one per puck. Always equal to
/// [`eval`] right after an update. A tracker belongs to one field, one
/// field layout and one set of thresholds: the ones it was made with,
/// which every call must pass again.
#[derive(Clone, Debug, PartialEq)]
pub(crate) struct EvalTracker {
    /// Each body's fixed-point distance (0 for robots).
    distances: Vec<u64>,
    total: u64,
    lookup: Distances,
    /// The pucks whose distance the last update changed.
    changes: Vec<PuckChange>,
}

impl EvalTracker {
    /// A tracker of `world`'s current pucks.
    pub fn new(world: &World, field: &ScalarField, t: &Thresholds) -> EvalTracker {
        let lookup = Distances::new(field, &world.config().field_layout(), t);
        let mut tracker = EvalTracker {
            distances: vec![0; world.bodies().len()],
            total: 0,
            lookup,
            // at most one change per puck: an update never allocates
            changes: Vec::with_capacity(world.pucks().len()),
        };
        tracker.rebuild(world, field, t);
        tracker
    }

    /// Looks every puck up again (after a reset), without allocating.
    pub fn rebuild(&mut self, world: &World, field: &ScalarField, t: &Thresholds) {
        self.distances.fill(0);
        self.changes.clear();
        let layout = world.config().field_layout();
        for i in world.puck_range() {
            self.distances[i] = self.lookup.at(world.bodies()[i].pos, &layout, field, t);
        }
        self.total = self.distances.iter().sum();
    }

    /// Catches up with the world: looks up the pucks that moved since the
    /// last update (the world's moved set, which this empties).
    pub fn update(&mut self, world: &mut World, field: &ScalarField, t: &Thresholds) {
        let (first_puck, layout) = (world.puck_range().start, world.config().field_layout());
        let pucks = world.pucks().len();
        let (lookup, distances, total) = (&self.lookup, &mut self.distances, &mut self.total);
        let changes = &mut self.changes;
        changes.clear();
        world.drain_moved(|i, body| {
            if i >= first_puck {
                let d = lookup.at(body.pos, &layout, field, t);
                if d != distances[i] {
                    let gain = distances[i] as f64 - d as f64;
                    changes.push(PuckChange {
                        body: i as u32,
                        eval_change: eval_loss(gain, pucks, t),
                    });
                }
                *total = *total - distances[i] + d;
                distances[i] = d;
            }
        });
    }

    /// The pucks whose distance to the band the last update changed, in
    /// body order (none after a rebuild).
    pub fn changes(&self) -> &[PuckChange] {
        &self.changes
    }

    /// Eval of the world as of the last update.
    pub fn eval(&self, world: &World, t: &Thresholds) -> f64 {
        eval_of(self.total, world.pucks().len(), t)
    }
}

/// The two readings of the thesis' collision-aware Eval'.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum EvalPrime {
    /// The formula as printed: `phi Eval + nu (1 - mean_j AD_j)`, with
    /// `AD_j` the mean absolute difference between the field value under
    /// robot j and under each robot. It rewards robots for standing on
    /// similar field values.
    AsWritten,
    /// What the text says it should do: `phi Eval + nu (mean distance
    /// between robot pairs / arena diagonal)`, growing as robots spread out.
    /// One robot: 0.
    Spread,
}

/// Eval' of the given variant with a simulation's thresholds and weights
/// (`episode.phi`, `episode.nu`).
pub fn eval_prime_of(
    world: &World,
    field: &ScalarField,
    config: &SimConfig,
    variant: EvalPrime,
) -> f64 {
    eval_prime(
        world,
        field,
        &config.thresholds,
        variant,
        config.episode.phi,
        config.episode.nu,
    )
}

/// Eval' of the given variant with weights `phi` and `nu`.
pub fn eval_prime(
    world: &World,
    field: &ScalarField,
    t: &Thresholds,
    variant: EvalPrime,
    phi: f64,
    nu: f64,
) -> f64 {
    let robots = &world.bodies()[..world.robots().len()];
    let n = robots.len();
    let layout = world.config().field_layout();
    let robot_term = match variant {
        EvalPrime::AsWritten => {
            let value = |b: &crate::physics::body::Body| f64::from(field.evaluate(b.pos, &layout));
            let total_ad: f64 = robots
                .iter()
                .map(|j| {
                    robots
                        .iter()
                        .map(|k| (value(j) - value(k)).abs())
                        .sum::<f64>()
                        / n as f64
                })
                .sum();
            1.0 - total_ad / n as f64
        }
        EvalPrime::Spread => {
            let pairs = n * n.saturating_sub(1) / 2;
            if pairs == 0 {
                0.0
            } else {
                let total: f64 = (0..n)
                    .flat_map(|j| (j + 1..n).map(move |k| (j, k)))
                    .map(|(j, k)| (robots[j].pos - robots[k].pos).length())
                    .sum();
                total / pairs as f64 / diagonal(world.config().arena())
            }
        }
    };
    phi * eval(world, field, t) + nu * robot_term
}

/// The arena's diagonal: side x sqrt 2 for a square (the reference model's
/// expression, so square arenas keep their results bit for bit), the
/// hypotenuse otherwise.
fn diagonal(arena: Vec2) -> f64 {
    if arena.x == arena.y {
        arena.x * std::f64::consts::SQRT_2
    } else {
        arena.x.hypot(arena.y)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fields::FieldFrame;

    /// The per-cell table gives every position the distance of the formula:
    /// on cell edges, between them, outside the grid on every side and at
    /// non-finite coordinates, in a frame that does not start at the origin.
    #[test]
    fn the_cell_table_gives_the_formulas_distance_everywhere() {
        let field = ScalarField::annulus_of(16, 12);
        let layout = FieldLayout {
            frame: FieldFrame {
                x: 30.0,
                y: -12.5,
                width: 160.0,
                height: 90.0,
            },
            sampling: FieldSampling::Nearest,
        };
        for t in [
            Thresholds::default(),
            Thresholds::LETTERS,
            Thresholds {
                outie: 0.2,
                innie: 0.3,
            },
        ] {
            let table = Distances::new(&field, &layout, &t);
            let mut points: Vec<Vec2> = Vec::new();
            for i in -8..=200 {
                for j in -8..=130 {
                    points.push(Vec2::new(
                        20.0 + f64::from(i) * 0.9,
                        -25.0 + f64::from(j) * 0.9,
                    ));
                }
            }
            // exactly on cell edges (10 x 7.5 units each) and a hair off them
            let hair = |v: f64| v.abs().max(1.0) * f64::EPSILON;
            for i in -1..=17 {
                for j in -1..=13 {
                    let edge = Vec2::new(30.0 + f64::from(i) * 10.0, -12.5 + f64::from(j) * 7.5);
                    points.extend([
                        edge,
                        Vec2::new(edge.x - hair(edge.x), edge.y),
                        Vec2::new(edge.x, edge.y + hair(edge.y)),
                    ]);
                }
            }
            points.extend([
                Vec2::new(f64::NAN, 40.0),
                Vec2::new(50.0, f64::INFINITY),
                Vec2::new(-1e300, 1e300),
            ]);
            for p in points {
                assert_eq!(
                    table.at(p, &layout, &field, &t),
                    fixed_distance(p, &layout, &field, &t),
                    "at {p:?}"
                );
            }
        }
    }
}
