//! A greedy table policy from a policy blob: the robot's behaviour.

use crate::base::rng::SimRng;
use crate::control::{Controller, Perception};
use shared::PolicyBlob;

/// Hashes each reading with the blob's hasher, looks the state up in its
/// table and turns by the action's angular speed: exactly what the
/// firmware does.
#[derive(Clone, Debug)]
pub struct GreedyPolicy {
    blob: PolicyBlob,
}

impl GreedyPolicy {
    /// The policy of a decoded blob.
    pub fn new(blob: PolicyBlob) -> GreedyPolicy {
        GreedyPolicy { blob }
    }

    /// The blob, for its forward speed and provenance.
    pub fn blob(&self) -> &PolicyBlob {
        &self.blob
    }
}

impl Controller for GreedyPolicy {
    fn decide(&mut self, p: &Perception<'_>, turns: &mut [f32], _rng: &mut SimRng) {
        let (hasher, table, actions) = (self.blob.hasher(), self.blob.table(), self.blob.actions());
        for ((turn, reading), robot) in turns.iter_mut().zip(p.readings).zip(p.robots) {
            // A decoded blob names only existing actions, so the lookup
            // cannot miss; 0 keeps the robot straight if it ever did.
            let state = hasher.hash_as(reading, robot.kind.role());
            *turn = actions.angular(table.action(state)).unwrap_or(0.0);
        }
    }
}
