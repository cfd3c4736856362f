//! A learned table frozen: the learner's own greedy choice, ties broken at
//! random as it breaks them, with no updates and no exploration. What the
//! learner would do if it stopped learning (docs/flashed.md, way (b)).

use super::qtable::QTable;
use sim::base::rng::SimRng;
use sim::control::{Controller, Perception};

/// [`QTable::greedy_within`] of a fixed table, drawn from the simulation's
/// generator exactly as the learner with epsilon 0 draws.
#[derive(Clone, Debug)]
pub struct FrozenLearner {
    q: QTable,
    actions: Vec<f32>,
    tolerance: f64,
}

impl FrozenLearner {
    /// The table `q` acting with the angular speeds `actions` and the
    /// learner's tie tolerance.
    pub fn new(q: QTable, actions: Vec<f32>, tolerance: f64) -> FrozenLearner {
        FrozenLearner {
            q,
            actions,
            tolerance,
        }
    }
}

impl Controller for FrozenLearner {
    fn decide(&mut self, p: &Perception<'_>, turns: &mut [f32], rng: &mut SimRng) {
        let hasher = self.q.hasher();
        for ((turn, reading), robot) in turns.iter_mut().zip(p.readings).zip(p.robots) {
            let state = hasher.hash_as(reading, robot.kind.role());
            let action = self.q.greedy_within(state, self.tolerance, rng);
            *turn = self.actions.get(action.index()).copied().unwrap_or(0.0);
        }
    }
}
