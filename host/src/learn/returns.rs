//! n-step returns: each robot's recent steps whose update waits for the
//! rewards that follow them.
//!
//! With `n` steps, a robot's (s_t, a_t) is updated once the robot has the
//! rewards r_t .. r_{t+n-1} and the state s_{t+n} after them, towards
//!
//! ```text
//! G = r_t + gamma r_{t+1} + ... + gamma^(n-1) r_{t+n-1} + gamma^n max_a Q(s_{t+n}, a)
//! ```
//!
//! (Sutton and Barto, section 7.1, with Q-learning's max as the
//! bootstrap). When an episode ends, every waiting step is updated with
//! the rewards it has and the last state, oldest first, as the one-step
//! update bootstraps from the state an episode ends in. Between steps a
//! robot holds at most `n - 1` waiting steps: those go into a checkpoint
//! ([`PendingSteps`]), so that a resumed run makes the updates the straight
//! run made.

use super::qtable::QTable;
use serde::{Deserialize, Serialize};
use shared::{ActionId, State};
use std::collections::VecDeque;

/// Longest n-step return a run may ask for.
pub const MAX_N_STEP: u32 = 64;

/// One robot's step waiting for its update.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct WaitingStep {
    /// The state the robot acted in.
    pub state: State,
    /// The action it took.
    pub action: ActionId,
    /// The reward of that step.
    pub reward: f64,
}

/// Every robot's waiting steps, oldest first (robot order as the world's).
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct PendingSteps {
    robots: Vec<VecDeque<WaitingStep>>,
}

impl PendingSteps {
    /// Whether no robot has a waiting step (always so with one-step returns).
    pub fn is_empty(&self) -> bool {
        self.robots.iter().all(VecDeque::is_empty)
    }

    /// Records `robot`'s newest step; the caller completes the due ones
    /// ([`PendingSteps::due`]) with [`PendingSteps::complete_oldest`].
    pub(crate) fn record(&mut self, robot: usize, step: WaitingStep) {
        if self.robots.len() <= robot {
            self.robots.resize_with(robot + 1, VecDeque::new);
        }
        self.robots[robot].push_back(step);
    }

    /// How many of `robot`'s waiting steps are due for their update: the
    /// oldest, once `n` are waiting; all of them when the episode `ended`.
    pub(crate) fn due(&self, robot: usize, n: usize, ended: bool) -> usize {
        let waiting = self.robots.get(robot).map_or(0, VecDeque::len);
        if ended {
            waiting
        } else {
            (waiting + 1).saturating_sub(n)
        }
    }

    /// The n-step return's TD error of `robot`'s oldest waiting step on
    /// `q`, bootstrapped from `next` (the state after the robot's newest
    /// step), and the step, which stops waiting.
    pub(crate) fn complete_oldest(
        &mut self,
        robot: usize,
        next: State,
        gamma: f64,
        q: &QTable,
    ) -> Option<(WaitingStep, f64)> {
        let waiting = self.robots.get_mut(robot)?;
        let oldest = *waiting.front()?;
        let mut target = 0.0;
        let mut discount = 1.0;
        for step in waiting.iter() {
            target += discount * step.reward;
            discount *= gamma;
        }
        target += discount * q.best_value(next);
        waiting.pop_front();
        Some((oldest, target - q.value(oldest.state, oldest.action)))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use shared::StateHasher;

    fn step(state: u16, action: u8, reward: f64) -> WaitingStep {
        WaitingStep {
            state: State(state),
            action: ActionId(action),
            reward,
        }
    }

    #[test]
    fn a_step_is_due_once_n_steps_wait_and_its_target_sums_their_discounted_rewards() {
        let mut q = QTable::new(StateHasher::Bits7, 2, 0.0);
        let next = State(9);
        q.apply(
            next,
            ActionId(1),
            10.0,
            crate::learn::QParams {
                alpha: 1.0,
                gamma: 0.5,
            },
        );
        let mut pending = PendingSteps::default();
        pending.record(0, step(1, 0, 1.0));
        pending.record(0, step(2, 1, 2.0));
        assert_eq!(pending.due(0, 3, false), 0, "two of three steps wait");
        pending.record(0, step(3, 0, 4.0));
        assert_eq!(pending.due(0, 3, false), 1);
        // 1 + 0.5 x 2 + 0.25 x 4 + 0.125 x 10 - Q(1, 0) = 4.25
        let (oldest, error) = pending.complete_oldest(0, next, 0.5, &q).unwrap();
        assert_eq!(oldest, step(1, 0, 1.0));
        assert_eq!(error, 4.25);
        assert_eq!(pending.due(0, 3, false), 0);
    }

    #[test]
    fn at_an_episode_end_every_waiting_step_is_due_with_the_rewards_it_has() {
        let q = QTable::new(StateHasher::Bits7, 2, 2.0);
        let mut pending = PendingSteps::default();
        pending.record(1, step(1, 0, 1.0));
        pending.record(1, step(2, 0, 3.0));
        assert_eq!(pending.due(1, 4, true), 2);
        assert_eq!(pending.due(0, 4, true), 0, "robot 0 has none");
        // 1 + 0.5 x 3 + 0.25 x 2 - 2, then 3 + 0.5 x 2 - 2
        let first = pending.complete_oldest(1, State(5), 0.5, &q).unwrap().1;
        let second = pending.complete_oldest(1, State(5), 0.5, &q).unwrap().1;
        assert_eq!((first, second), (1.0, 2.0));
        assert!(pending.is_empty());
        assert!(pending.complete_oldest(1, State(5), 0.5, &q).is_none());
    }
}
