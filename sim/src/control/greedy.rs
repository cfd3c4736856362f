//! A greedy table policy from a policy blob: the robot's behaviour.

use crate::base::rng::SimRng;
use crate::control::{Controller, Perception};
use shared::{ChoiceRng, PolicyBlob};

/// Hashes each reading with the blob's hasher, looks the state's best
/// actions up and turns by the action's angular speed: exactly what the
/// firmware does. Where a state has two or more best actions (a blob of
/// format version 2 with ties), robot `i` picks one with its own
/// [`ChoiceRng`], the generator the firmware of robot id `i` starts with;
/// a single best action is taken without drawing, so a blob of version 1
/// acts as its table says and the simulation's generators are never drawn.
#[derive(Clone, Debug)]
pub struct GreedyPolicy {
    blob: PolicyBlob,
    choices: Vec<ChoiceRng>,
}

impl GreedyPolicy {
    /// The policy of a decoded blob.
    pub fn new(blob: PolicyBlob) -> GreedyPolicy {
        GreedyPolicy {
            blob,
            choices: Vec::new(),
        }
    }

    /// The blob, for its forward speed and provenance.
    pub fn blob(&self) -> &PolicyBlob {
        &self.blob
    }

    /// Robot `i`'s choice generator as it is now (robots that have not
    /// decided yet are at their start, [`ChoiceRng::for_robot`]).
    pub fn choice_rng(&self, robot: usize) -> ChoiceRng {
        self.choices
            .get(robot)
            .copied()
            .unwrap_or_else(|| ChoiceRng::for_robot(robot as u8))
    }
}

impl Controller for GreedyPolicy {
    fn decide(&mut self, p: &Perception<'_>, turns: &mut [f32], _rng: &mut SimRng) {
        while self.choices.len() < turns.len() {
            self.choices
                .push(ChoiceRng::for_robot(self.choices.len() as u8));
        }
        let (hasher, sets, actions) = (self.blob.hasher(), self.blob.sets(), self.blob.actions());
        let robots = turns.iter_mut().zip(p.readings).zip(p.robots);
        for (((turn, reading), robot), choice) in robots.zip(&mut self.choices) {
            let state = hasher.hash_as(reading, robot.kind.role());
            // A decoded blob names only existing actions, so the lookup
            // cannot miss; 0 keeps the robot straight if it ever did.
            *turn = actions
                .angular(choice.pick(sets.mask(state)))
                .unwrap_or(0.0);
        }
    }
}
