//! Evaluation of a world against its target shape.
//!
//! - Eval: per puck, the field value `v` at its centre (truncated cell)
//!   gives a distance `T_o - v` below the outie threshold, `v - T_i` above
//!   the innie threshold, 0 between; Eval = 1 - mean(distance) / max(T_o,
//!   1 - T_i), the original code's normalisation (the 0.94 success
//!   threshold was tuned with it). No pucks: 1.
//! - Eval' (thesis chapter 6), two variants; see [`EvalPrime`].

use crate::config::Thresholds;
use crate::field::{FieldLayout, ScalarField};
use crate::vec2::Vec2;
use crate::world::World;
use serde::{Deserialize, Serialize};

/// How far a field value lies outside the band `[T_o, T_i]`.
pub fn band_distance(value: f64, t: &Thresholds) -> f64 {
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
    let d = band_distance(f64::from(field.evaluate(p, layout)), t);
    (d * DISTANCE_ONE).round() as u64
}

/// Eval from the sum of the pucks' fixed-point distances.
fn eval_of(total: u64, pucks: usize, t: &Thresholds) -> f64 {
    let scale = t.outie.max(1.0 - t.innie);
    if pucks == 0 || scale <= 0.0 {
        return 1.0;
    }
    1.0 - total as f64 / DISTANCE_ONE / pucks as f64 / scale
}

/// Eval of the pucks' positions, 1 when every puck is in the band.
pub fn eval(world: &World, field: &ScalarField, t: &Thresholds) -> f64 {
    let layout = world.config().field_layout();
    let total = world.pucks().iter().map(|p| fixed_distance(p.pos, &layout, field, t)).sum();
    eval_of(total, world.pucks().len(), t)
}

/// Eval kept current as the world steps: only the pucks that moved since
/// the last update are looked up again, so Eval every step (a learner's
/// reward) costs a few lookups instead of one per puck. Always equal to
/// [`eval`] right after an update.
#[derive(Clone, Debug, PartialEq)]
pub struct EvalTracker {
    /// Each body's fixed-point distance (0 for robots).
    distances: Vec<u64>,
    total: u64,
}

impl EvalTracker {
    /// A tracker of `world`'s current pucks.
    pub fn new(world: &World, field: &ScalarField, t: &Thresholds) -> EvalTracker {
        let mut tracker = EvalTracker { distances: vec![0; world.bodies().len()], total: 0 };
        tracker.rebuild(world, field, t);
        tracker
    }

    /// Looks every puck up again (after a reset), without allocating.
    pub fn rebuild(&mut self, world: &World, field: &ScalarField, t: &Thresholds) {
        self.distances.fill(0);
        let layout = world.config().field_layout();
        for i in world.puck_range() {
            self.distances[i] = fixed_distance(world.bodies()[i].pos, &layout, field, t);
        }
        self.total = self.distances.iter().sum();
    }

    /// Catches up with the world: looks up the pucks that moved since the
    /// last update (the world's moved set, which this empties).
    pub fn update(&mut self, world: &mut World, field: &ScalarField, t: &Thresholds) {
        let (first_puck, layout) = (world.puck_range().start, world.config().field_layout());
        world.drain_moved(|i, body| {
            if i >= first_puck {
                let d = fixed_distance(body.pos, &layout, field, t);
                self.total = self.total - self.distances[i] + d;
                self.distances[i] = d;
            }
        });
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

/// Eval' of the given variant with weights `phi` and `nu`.
pub fn eval_prime(world: &World, field: &ScalarField, t: &Thresholds, variant: EvalPrime, phi: f64, nu: f64) -> f64 {
    let robots = &world.bodies()[..world.robots().len()];
    let n = robots.len();
    let layout = world.config().field_layout();
    let robot_term = match variant {
        EvalPrime::AsWritten => {
            let value = |b: &crate::body::Body| f64::from(field.evaluate(b.pos, &layout));
            let total_ad: f64 = robots
                .iter()
                .map(|j| robots.iter().map(|k| (value(j) - value(k)).abs()).sum::<f64>() / n as f64)
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
