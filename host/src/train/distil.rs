//! Distilling orbital construction (`distil_oc = STEPS`): before learning,
//! orbital construction drives a world of the run's own settings for STEPS
//! steps while every robot's hashed state and the run's action nearest to
//! orbital construction's turn are counted; each state's most frequent
//! action becomes the policy the run starts from (its Q-values preferring
//! those actions, as `--init-from` does with a policy blob).
//!
//! With a role hasher (`original-role`, `bits9-role`) the world has the
//! flashed swarm's innies on every field, the robots of odd id
//! ([`TrainConfig::prepare`]), and the table holds both behaviours; with
//! the others every robot is an outie. A state orbital construction never
//! reached takes the action of the same state of the other role if that
//! one was reached, else the most frequent action overall. The world is seeded with the run's seed mixed with
//! [`DISTIL_STREAM`], apart from the training world.

use super::config::TrainConfig;
use anyhow::{Context, Result};
use shared::{ActionId, PolicyTable, State};
use sim::control::orbital::{OrbitalConfig, OrbitalConstruction};
use sim::{base::rng::SimRng, control::Controller, control::Perception};

/// Mixed into the run's seed for the distillation world.
pub const DISTIL_STREAM: u64 = 0xD157_11ED_0000_0001;

/// Orbital construction, counting each state's actions.
struct Counting {
    orbital: OrbitalConstruction,
    speeds: Vec<f32>,
    hasher: shared::StateHasher,
    counts: Vec<u64>,
}

impl Controller for Counting {
    fn decide(&mut self, p: &Perception<'_>, turns: &mut [f32], rng: &mut SimRng) {
        self.orbital.decide(p, turns, rng);
        let n = self.speeds.len();
        for ((reading, &turn), robot) in p.readings.iter().zip(turns.iter()).zip(p.robots) {
            let state = self.hasher.hash_as(reading, robot.kind.role());
            self.counts[state.index() * n + nearest(&self.speeds, turn)] += 1;
        }
    }
}

/// Index of the speed nearest `turn` (the first of equals).
fn nearest(speeds: &[f32], turn: f32) -> usize {
    let mut best = 0;
    for (i, s) in speeds.iter().enumerate() {
        if (s - turn).abs() < (speeds[best] - turn).abs() {
            best = i;
        }
    }
    best
}

/// Index of the largest count (the first of equals), `None` if all are 0.
fn most(counts: &[u64]) -> Option<usize> {
    let best = (0..counts.len()).rev().max_by_key(|&i| counts[i])?;
    (counts[best] > 0).then_some(best)
}

/// Orbital construction as a policy table of the run's hasher and actions.
pub fn distil_orbital(config: &TrainConfig, steps: u64) -> Result<PolicyTable> {
    let prepared = config.prepare()?;
    let mut sim = prepared
        .simulation(config.world.seed ^ DISTIL_STREAM)
        .context("cannot build the distillation world")?;
    let hasher = config.learn.hasher.0;
    let speeds = config.learn.actions.clone();
    let n = speeds.len();
    let orbital = OrbitalConstruction::new(OrbitalConfig::default(), &sim.config().thresholds);
    let mut counting = Counting {
        orbital,
        speeds,
        hasher,
        counts: vec![0; hasher.num_states() * n],
    };
    sim.run(&mut counting, steps);
    let counts = |s: usize| &counting.counts[s * n..(s + 1) * n];
    let mut overall = vec![0u64; n];
    for s in 0..hasher.num_states() {
        for (o, c) in overall.iter_mut().zip(counts(s)) {
            *o += c;
        }
    }
    let fallback = most(&overall).unwrap_or(0);
    let mut table = PolicyTable::new(hasher);
    for s in 0..hasher.num_states() {
        let other_role = hasher
            .has_role_bit()
            .then(|| s ^ usize::from(hasher.role_mask()));
        let action = most(counts(s))
            .or_else(|| other_role.and_then(|o| most(counts(o))))
            .unwrap_or(fallback);
        table.set(State(s as u16), ActionId(action as u8));
    }
    Ok(table)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn turns_map_to_the_nearest_action_and_ties_to_the_first() {
        let speeds = [0.3, 0.15, -0.15, -0.3];
        assert_eq!(nearest(&speeds, 0.09), 1);
        assert_eq!(nearest(&speeds, -0.3), 3);
        assert_eq!(
            nearest(&speeds, 0.0),
            1,
            "0 is as near 0.15 as -0.15: the first"
        );
        assert_eq!(most(&[0, 3, 3, 1]), Some(1));
        assert_eq!(most(&[0, 0]), None);
    }

    #[test]
    fn a_distilled_role_table_acts_as_orbital_construction_for_both_roles() {
        let config = TrainConfig {
            world: sim::scenario::choices::WorldChoices {
                robots: Some(4),
                pucks: Some(60),
                ..Default::default()
            },
            learn: crate::learn::LearnConfig {
                hasher: crate::learn::StateHasherName(shared::StateHasher::OriginalRole),
                ..Default::default()
            },
            ..TrainConfig::default()
        };
        let table = distil_orbital(&config, 3000).unwrap();
        assert_eq!(table.hasher(), shared::StateHasher::OriginalRole);
        // outies and innies turn opposite ways somewhere: the table holds both
        let differs = (0..256u16).any(|s| table.action(State(s)) != table.action(State(s + 256)));
        assert!(differs);
        let again = distil_orbital(&config, 3000).unwrap();
        assert!(table == again, "seeded");
    }
}
