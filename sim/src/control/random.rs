//! Uniformly random actions: the baseline that forms nothing.

use crate::base::rng::SimRng;
use crate::control::{Controller, Perception};
use rand::RngExt;
use shared::ActionTable;

/// Each robot, each step, turns by an action drawn uniformly from a table.
#[derive(Clone, Debug, PartialEq)]
pub struct RandomTurns {
    actions: ActionTable,
}

impl RandomTurns {
    /// Random choices among `actions`.
    pub fn new(actions: ActionTable) -> RandomTurns {
        RandomTurns { actions }
    }
}

impl Controller for RandomTurns {
    fn decide(&mut self, _p: &Perception<'_>, turns: &mut [f32], rng: &mut SimRng) {
        let speeds = self.actions.angular_speeds();
        for turn in turns.iter_mut() {
            *turn = speeds[rng.random_range(0..speeds.len())];
        }
    }
}
