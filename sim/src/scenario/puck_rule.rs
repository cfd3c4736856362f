//! The puck rule: how many pucks a shape gets in an arena. The count is
//! the most, up to the arena's own count (12 on the TV, `tv75`), for which
//! a hand placement with every puck's centre on the shape reaches the
//! success Eval; a shape on which fewer than [`LEAST_PUCKS`] do has no
//! count ([`ScenarioError::TooFewPucks`]). Fixed before any training, the same for
//! orbital construction and every policy.
//!
//! The placement: the candidate centres of a grid of [`GRID_STEP`] units
//! over the floor, a puck's radius from the walls, in order of their
//! distance from the shape's band (`thresholds`; on a letter or image
//! `1 - value`, so the brightest first; equal distances in the grid's
//! row-major order), each kept if it does not overlap a puck kept before.
//! "On the shape": inside the band on the annulus, a field value of at
//! least [`ON_A_SHAPE`] on any other field (the letters' fields fall off
//! from 1 on the stroke). `sim/tests/shape_pucks.rs` checks the counts of
//! the shapes the published results use.

use crate::base::vec2::Vec2;
use crate::config::Thresholds;
use crate::episodes::eval::eval;
use crate::fields::source::FieldSource;
use crate::scenario::{Arena, PreparedScenario, Scenario, ScenarioError};
use crate::world::World;
use std::collections::BTreeMap;
use std::sync::Mutex;

pub use crate::scenario::LEAST_PUCKS;

/// The least field value of a shape other than the annulus.
pub const ON_A_SHAPE: f32 = 0.8;

/// The spacing of the candidate centres, in world units.
pub const GRID_STEP: f64 = 0.5;

/// The counts computed in this process, by field and arena.
static COUNTS: Mutex<BTreeMap<String, usize>> = Mutex::new(BTreeMap::new());

/// The puck count of `field` in `arena` by the rule (see the module docs),
/// computed once per field and arena in a process.
pub fn rule_pucks(field: &FieldSource, arena: &Arena) -> Result<usize, ScenarioError> {
    let key = format!("{field} {arena:?}");
    let cached = COUNTS.lock().ok().and_then(|c| c.get(&key).copied());
    if let Some(n) = cached {
        return Ok(n);
    }
    let placement = Placement::new(field, arena)?;
    let most = (1..=placement.cap)
        .rev()
        .find(|&n| placement.reaches_success(n))
        .unwrap_or(0);
    if most < LEAST_PUCKS {
        return Err(ScenarioError::TooFewPucks {
            field: field.clone(),
            most,
        });
    }
    if let Ok(mut counts) = COUNTS.lock() {
        counts.insert(key, most);
    }
    Ok(most)
}

/// The rule's placement of a field in an arena: the pucks kept, in order,
/// up to the arena's own count.
pub struct Placement {
    /// The arena's own puck count: the most the rule gives.
    pub cap: usize,
    /// The centres kept, in order, each with whether it is on the shape.
    pub kept: Vec<(Vec2, bool)>,
    scenario: PreparedScenario,
}

impl Placement {
    /// Places up to the arena's own count of pucks on `field`.
    pub fn new(field: &FieldSource, arena: &Arena) -> Result<Placement, ScenarioError> {
        let scenario = Scenario {
            field: field.clone(),
            arena: arena.clone(),
            ..Scenario::default()
        }
        .prepare()?;
        let c = scenario.config();
        let (layout, shape, t) = (c.world.field_layout(), scenario.field(), &c.thresholds);
        let r = c.world.puck_radius;
        let mut candidates = Vec::new();
        let mut y = r;
        while y <= c.world.arena_height - r {
            let mut x = r;
            while x <= c.world.arena_width - r {
                let p = Vec2::new(x, y);
                candidates.push((shape.evaluate(p, &layout), p));
                x += GRID_STEP;
            }
            y += GRID_STEP;
        }
        // stable: equal distances keep the grid's order
        candidates.sort_by(|a, b| band_distance(a.0, t).total_cmp(&band_distance(b.0, t)));
        let cap = c.world.pucks;
        let mut kept: Vec<(Vec2, bool)> = Vec::new();
        for (v, p) in candidates {
            if kept.len() == cap {
                break;
            }
            if kept.iter().all(|(q, _)| (p - *q).length() >= 2.0 * r) {
                let on_shape = if *field == FieldSource::Annulus {
                    band_distance(v, t) == 0.0
                } else {
                    v >= ON_A_SHAPE
                };
                kept.push((p, on_shape));
            }
        }
        Ok(Placement {
            cap,
            kept,
            scenario,
        })
    }

    /// The Eval of the first `n` pucks kept (`None` if fewer fit) and the
    /// success Eval.
    pub fn eval(&self, n: usize) -> Option<(f64, f64)> {
        let pucks: Vec<Vec2> = self.kept.get(..n)?.iter().map(|&(p, _)| p).collect();
        let c = self.scenario.config();
        let world = World::scene(c, &[], &pucks, 1);
        Some((
            eval(&world, self.scenario.field(), &c.thresholds),
            c.episode.success_eval,
        ))
    }

    /// Whether the first `n` pucks kept are all on the shape and reach the
    /// success Eval.
    pub fn reaches_success(&self, n: usize) -> bool {
        let on_shape = self
            .kept
            .get(..n)
            .is_some_and(|k| k.iter().all(|&(_, on)| on));
        on_shape && self.eval(n).is_some_and(|(e, success)| e > success)
    }
}

/// How far a value lies from the band `[T_o, T_i]`.
fn band_distance(v: f32, t: &Thresholds) -> f64 {
    let v = f64::from(v);
    (t.outie - v).max(v - t.innie).max(0.0)
}
