//! Evaluation of a world against its target shape.
//!
//! - Eval: per puck, the field value `v` at its centre (truncated cell)
//!   gives a distance `T_o - v` below the outie threshold, `v - T_i` above
//!   the innie threshold, 0 between; Eval = 1 - mean(distance) / max(T_o,
//!   1 - T_i), the original code's normalisation (the 0.94 success
//!   threshold was tuned with it). No pucks: 1.
//! - Eval' (thesis chapter 6), two variants; see [`EvalPrime`].

use super::config::Thresholds;
use super::field::ScalarField;
use super::world::World;
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

/// Eval of the pucks' positions, 1 when every puck is in the band.
pub fn eval(world: &World, field: &ScalarField, t: &Thresholds) -> f64 {
    let size = world.config().arena_size;
    let pucks = world.pucks();
    let scale = t.outie.max(1.0 - t.innie);
    if pucks.is_empty() || scale <= 0.0 {
        return 1.0;
    }
    let total: f64 = pucks.iter().map(|p| band_distance(f64::from(field.evaluate(p.pos, size)), t)).sum();
    1.0 - total / pucks.len() as f64 / scale
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
    let size = world.config().arena_size;
    let robot_term = match variant {
        EvalPrime::AsWritten => {
            let value = |b: &super::body::Body| f64::from(field.evaluate(b.pos, size));
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
                total / pairs as f64 / (size * std::f64::consts::SQRT_2)
            }
        }
    };
    phi * eval(world, field, t) + nu * robot_term
}
