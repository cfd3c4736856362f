//! A greedy table policy from a policy blob: the robot's behaviour.

use crate::base::rng::SimRng;
use crate::control::{Controller, Perception};
use shared::{ActionId, ChoiceRng, PolicyBlob, State};

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
        let hasher = self.blob.hasher();
        let robots = turns.iter_mut().zip(p.readings).zip(p.robots);
        for (i, ((turn, reading), robot)) in robots.enumerate() {
            let action = self.act(i, hasher.hash_as(reading, robot.kind.role()));
            // A decoded blob names only existing actions, so the lookup
            // cannot miss; 0 keeps the robot straight if it ever did.
            *turn = self.blob.actions().angular(action).unwrap_or(0.0);
        }
    }
}

impl GreedyPolicy {
    /// Robot `robot`'s action in `state`: the state's best action, or the
    /// one robot `robot`'s generator picks among several (one draw). What
    /// [`Controller::decide`] does for each robot; the firmware
    /// equivalence tests follow a robot's decisions with it.
    pub fn act(&mut self, robot: usize, state: State) -> ActionId {
        while self.choices.len() <= robot {
            self.choices
                .push(ChoiceRng::for_robot(self.choices.len() as u8));
        }
        self.choices[robot].pick(self.blob.sets().mask(state))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::control::policy_file;
    use crate::scenario::Scenario;
    use shared::{ActionSets, ActionTable, Provenance, StateHasher};
    use std::path::Path;

    /// The policy controller as it was before blob format version 2: each
    /// state's table action, no generator.
    struct TableOnly(PolicyBlob);

    impl Controller for TableOnly {
        fn decide(&mut self, p: &Perception<'_>, turns: &mut [f32], _rng: &mut SimRng) {
            let (hasher, table, actions) = (self.0.hasher(), self.0.table(), self.0.actions());
            for ((turn, reading), robot) in turns.iter_mut().zip(p.readings).zip(p.robots) {
                let state = hasher.hash_as(reading, robot.kind.role());
                *turn = actions.angular(table.action(state)).unwrap_or(0.0);
            }
        }
    }

    /// The world after `steps` steps of the thesis' standard run, seed 3.
    fn world_after(controller: &mut dyn Controller, steps: u64) -> String {
        let mut sim = Scenario::default()
            .prepare()
            .unwrap()
            .simulation(3)
            .unwrap();
        sim.run(controller, steps);
        format!("{:?}", sim.snapshot())
    }

    #[test]
    fn a_blob_of_one_action_per_state_acts_as_before_and_never_draws() {
        let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../policies/disc-tv75-8bit.policy");
        let blob = policy_file::read(&path).unwrap();
        let mut policy = GreedyPolicy::new(blob.clone());
        assert_eq!(
            world_after(&mut policy, 3000),
            world_after(&mut TableOnly(blob), 3000)
        );
        for robot in 0..8 {
            assert_eq!(policy.choice_rng(robot), ChoiceRng::for_robot(robot as u8));
        }
    }

    #[test]
    fn each_robot_draws_its_firmwares_generator_once_per_tied_decision() {
        // actions 1 and 3 tie in every state: every decision draws
        let mut sets = ActionSets::new(StateHasher::Original);
        for s in 0..256u16 {
            sets.set(State(s), 0b1010);
        }
        let blob =
            PolicyBlob::with_sets(ActionTable::default(), sets, Provenance::default()).unwrap();
        let mut policy = GreedyPolicy::new(blob.clone());
        let steps = 500;
        let tied = world_after(&mut policy, steps);
        for robot in 0..8 {
            let mut expected = ChoiceRng::for_robot(robot as u8);
            for _ in 0..steps {
                expected.next_u16();
            }
            assert_eq!(policy.choice_rng(robot), expected, "robot {robot}");
        }
        // the draws decide: the same world as the table's lowest actions would be a coincidence
        assert_ne!(tied, world_after(&mut TableOnly(blob), steps));
    }
}
