//! The tabular action-value function shared by every robot.

use rand::RngExt;
use serde::{Deserialize, Serialize};
use shared::{ActionId, ActionSets, PolicyTable, State, StateHasher};

/// Q(s, a) for every state of one hasher and every action, with visit counts.
///
/// One table is shared by the whole swarm (the thesis' single policy); every
/// robot's experience updates it.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct QTable {
    hasher: StateHasher,
    actions: usize,
    values: Vec<f64>,
    visits: Vec<u64>,
}

/// A learned table at a glance: what the robots did and what the table
/// learned, the figures a side-by-side with the thesis author's program
/// compares (`docs/reproduction.md`).
#[derive(Clone, Debug, PartialEq)]
pub struct TableSummary {
    /// Each action's share of all updates (of the actions taken), by id.
    pub action_shares: Vec<f64>,
    /// The values of every action of the visited states at
    /// [`TableSummary::PERCENTILES`] (the sorted value at index `floor(p (n
    /// - 1))`); none before the first update.
    pub value_percentiles: Option<[f64; 7]>,
    /// Visited states whose greatest value two or more actions share.
    pub tied_states: usize,
}

impl TableSummary {
    /// Minimum, 10th, 25th, 50th, 75th, 90th percentile, maximum.
    pub const PERCENTILES: [f64; 7] = [0.0, 0.1, 0.25, 0.5, 0.75, 0.9, 1.0];
}

/// How much a policy's action is preferred in [`QTable::from_policy`]:
/// enough to win every greedy choice until learning says otherwise.
pub const POLICY_PREFERENCE: f64 = 1.0;

/// Learning-rate and discount of the Q-update.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct QParams {
    /// Learning rate alpha.
    pub alpha: f64,
    /// Discount gamma.
    pub gamma: f64,
}

impl Default for QParams {
    /// The thesis' alpha 0.2, gamma 0.9.
    fn default() -> QParams {
        QParams {
            alpha: 0.2,
            gamma: 0.9,
        }
    }
}

impl QTable {
    /// A table with every value at `initial` (the thesis uses 1.0) and no visits.
    pub fn new(hasher: StateHasher, actions: usize, initial: f64) -> QTable {
        let n = hasher.num_states() * actions;
        QTable {
            hasher,
            actions,
            values: vec![initial; n],
            visits: vec![0; n],
        }
    }

    /// The hasher whose states index the table.
    pub fn hasher(&self) -> StateHasher {
        self.hasher
    }

    /// Number of actions per state.
    pub fn num_actions(&self) -> usize {
        self.actions
    }

    /// The values of one state's actions.
    #[inline]
    pub fn row(&self, state: State) -> &[f64] {
        let start = state.index() * self.actions;
        &self.values[start..start + self.actions]
    }

    /// Q(s, a).
    pub fn value(&self, state: State, action: ActionId) -> f64 {
        self.row(state)[action.index()]
    }

    /// How often (s, a) was updated.
    pub fn visits(&self, state: State, action: ActionId) -> u64 {
        self.visits[state.index() * self.actions + action.index()]
    }

    /// Number of states with at least one update.
    pub fn states_visited(&self) -> usize {
        self.visits
            .chunks(self.actions)
            .filter(|row| row.iter().any(|&v| v > 0))
            .count()
    }

    /// The table at a glance ([`TableSummary`]).
    pub fn summary(&self) -> TableSummary {
        let total: u64 = self.visits.iter().sum();
        let mut taken = vec![0u64; self.actions];
        for row in self.visits.chunks(self.actions) {
            for (sum, &v) in taken.iter_mut().zip(row) {
                *sum += v;
            }
        }
        let visited = || {
            self.values
                .chunks(self.actions)
                .zip(self.visits.chunks(self.actions))
                .filter(|(_, visits)| visits.iter().any(|&v| v > 0))
                .map(|(values, _)| values)
        };
        let mut values: Vec<f64> = visited().flatten().copied().collect();
        values.sort_by(f64::total_cmp);
        let tied_states = visited()
            .filter(|row| {
                let best = row.iter().copied().fold(f64::NEG_INFINITY, f64::max);
                row.iter().filter(|&&v| v == best).count() > 1
            })
            .count();
        TableSummary {
            action_shares: taken
                .iter()
                .map(|&n| {
                    if total > 0 {
                        n as f64 / total as f64
                    } else {
                        0.0
                    }
                })
                .collect(),
            value_percentiles: (!values.is_empty()).then(|| {
                TableSummary::PERCENTILES
                    .map(|p| values[(p * (values.len() - 1) as f64).floor() as usize])
            }),
            tied_states,
        }
    }

    /// An action with the greatest value; among equal maxima, one chosen
    /// uniformly at random (the generator is drawn only when there is a tie).
    #[inline]
    pub fn greedy(&self, state: State, rng: &mut impl RngExt) -> ActionId {
        let row = self.row(state);
        let best = row.iter().copied().fold(f64::NEG_INFINITY, f64::max);
        let ties = row.iter().filter(|&&v| v == best).count();
        let pick = if ties > 1 {
            rng.random_range(0..ties)
        } else {
            0
        };
        let index = row
            .iter()
            .enumerate()
            .filter(|(_, &v)| v == best)
            .nth(pick)
            .map_or(0, |(i, _)| i);
        ActionId(index as u8)
    }

    /// An action within `tolerance` of the greatest value, chosen uniformly
    /// at random among them (the generator is drawn only when there are two
    /// or more); with `tolerance == 0`, exactly [`QTable::greedy`].
    #[inline]
    pub fn greedy_within(&self, state: State, tolerance: f64, rng: &mut impl RngExt) -> ActionId {
        if tolerance == 0.0 {
            return self.greedy(state, rng);
        }
        let row = self.row(state);
        let floor = row.iter().copied().fold(f64::NEG_INFINITY, f64::max) - tolerance;
        let near = row.iter().filter(|&&v| v >= floor).count();
        let pick = if near > 1 {
            rng.random_range(0..near)
        } else {
            0
        };
        let index = row
            .iter()
            .enumerate()
            .filter(|(_, &v)| v >= floor)
            .nth(pick)
            .map_or(0, |(i, _)| i);
        ActionId(index as u8)
    }

    /// Epsilon-greedy choice: with probability `epsilon` a uniformly random
    /// action, otherwise [`QTable::greedy_within`] `tolerance`. With
    /// `epsilon == 0` the exploration draw is skipped.
    #[inline]
    pub fn select(
        &self,
        state: State,
        epsilon: f64,
        tolerance: f64,
        rng: &mut impl RngExt,
    ) -> ActionId {
        if epsilon > 0.0 && rng.random::<f64>() < epsilon {
            ActionId(rng.random_range(0..self.actions) as u8)
        } else {
            self.greedy_within(state, tolerance, rng)
        }
    }

    /// The Q-learning update Q(s,a) += alpha (r + gamma max_a' Q(s',a') - Q(s,a)).
    #[inline]
    pub fn update(&mut self, s: State, a: ActionId, reward: f64, next: State, params: QParams) {
        let error = self.td_error(s, a, reward, next, params);
        self.apply(s, a, error, params);
    }

    /// The TD error r + gamma max_a' Q(s',a') - Q(s,a), without updating.
    #[inline]
    pub fn td_error(
        &self,
        s: State,
        a: ActionId,
        reward: f64,
        next: State,
        params: QParams,
    ) -> f64 {
        reward + params.gamma * self.best_value(next)
            - self.values[s.index() * self.actions + a.index()]
    }

    /// max_a Q(s, a): the value Q-learning bootstraps from.
    #[inline]
    pub fn best_value(&self, state: State) -> f64 {
        self.row(state)
            .iter()
            .copied()
            .fold(f64::NEG_INFINITY, f64::max)
    }

    /// Q(s,a) += alpha `error`, a TD error computed earlier ([`QTable::td_error`]).
    #[inline]
    pub fn apply(&mut self, s: State, a: ActionId, error: f64, params: QParams) {
        let i = s.index() * self.actions + a.index();
        self.values[i] += params.alpha * error;
        self.visits[i] += 1;
    }

    /// The greedy policy, ties broken towards the lowest action id so that
    /// export is deterministic (unvisited states get action 0).
    pub fn greedy_policy(&self) -> PolicyTable {
        let mut table = PolicyTable::new(self.hasher);
        for s in 0..self.hasher.num_states() as u16 {
            let row = self.row(State(s));
            let mut best = 0;
            for (a, &v) in row.iter().enumerate() {
                if v > row[best] {
                    best = a;
                }
            }
            table.set(State(s), ActionId(best as u8));
        }
        table
    }

    /// Each state's best actions: exactly the set [`QTable::greedy_within`]
    /// `tolerance` picks from uniformly (the actions within `tolerance` of
    /// the greatest value; with 0 the equal maxima of [`QTable::greedy`]).
    /// Unvisited states have every action.
    pub fn best_sets(&self, tolerance: f64) -> ActionSets {
        let mut sets = ActionSets::new(self.hasher);
        for s in 0..self.hasher.num_states() as u16 {
            let row = self.row(State(s));
            let best = row.iter().copied().fold(f64::NEG_INFINITY, f64::max);
            let floor = if tolerance == 0.0 {
                best
            } else {
                best - tolerance
            };
            let mask = row
                .iter()
                .enumerate()
                .filter(|(_, &v)| v >= floor)
                .fold(0u8, |m, (a, _)| m | 1 << a);
            sets.set(State(s), mask);
        }
        sets
    }

    /// A table that acts like a greedy policy: every value `initial`, plus
    /// [`POLICY_PREFERENCE`] on each state's policy action, no visits. Used
    /// to start learning from a policy blob, which carries no Q-values.
    pub fn from_policy(policy: &PolicyTable, actions: usize, initial: f64) -> QTable {
        let mut q = QTable::new(policy.hasher(), actions, initial);
        for (state, action) in policy.entries() {
            if action.index() < actions {
                q.values[state.index() * actions + action.index()] += POLICY_PREFERENCE;
            }
        }
        q
    }

    /// Whether another table has the same shape (hasher and action count),
    /// so that its values can seed this run.
    pub fn same_shape(&self, other: &QTable) -> bool {
        self.hasher == other.hasher && self.actions == other.actions
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;
    use rand_pcg::Pcg64Mcg;

    #[test]
    fn a_tie_tolerance_picks_uniformly_among_near_ties_and_never_outside() {
        let mut q = QTable::new(StateHasher::Bits7, 4, 0.0);
        let s = State(3);
        // values 1.0, 0.9995, 0.5, 0.9991: within 0.001 of the best are 0, 1, 3
        for (a, v) in [1.0, 0.9995, 0.5, 0.9991].into_iter().enumerate() {
            q.values[s.index() * 4 + a] = v;
        }
        let mut rng = Pcg64Mcg::seed_from_u64(7);
        let mut counts = [0u32; 4];
        let draws = 30_000;
        for _ in 0..draws {
            counts[q.greedy_within(s, 0.001, &mut rng).index()] += 1;
        }
        assert_eq!(counts[2], 0, "{counts:?}");
        for a in [0, 1, 3] {
            let share = f64::from(counts[a]) / f64::from(draws);
            assert!((share - 1.0 / 3.0).abs() < 0.015, "{counts:?}");
        }
        // no tolerance: the exact maximum only, and the same draws as greedy
        let (mut a, mut b) = (Pcg64Mcg::seed_from_u64(3), Pcg64Mcg::seed_from_u64(3));
        for state in 0..q.hasher().num_states() as u16 {
            assert_eq!(
                q.greedy_within(State(state), 0.0, &mut a),
                q.greedy(State(state), &mut b)
            );
        }
    }

    #[test]
    fn update_matches_a_hand_computed_example() {
        let mut q = QTable::new(StateHasher::Original, 4, 1.0);
        let p = QParams {
            alpha: 0.2,
            gamma: 0.9,
        };
        // Q(5,1) = 1 + 0.2 (0.5 + 0.9 x 1 - 1) = 1.08
        q.update(State(5), ActionId(1), 0.5, State(7), p);
        assert!((q.value(State(5), ActionId(1)) - 1.08).abs() < 1e-12);
        // next state 5 now has max 1.08: Q(9,0) = 1 + 0.2 (-1 + 0.9 x 1.08 - 1) = 0.7944
        q.update(State(9), ActionId(0), -1.0, State(5), p);
        assert!((q.value(State(9), ActionId(0)) - 0.7944).abs() < 1e-12);
        assert_eq!(q.visits(State(5), ActionId(1)), 1);
        assert_eq!(q.states_visited(), 2);
    }

    #[test]
    fn the_summary_counts_actions_taken_and_the_values_and_ties_of_visited_states() {
        let mut q = QTable::new(StateHasher::Original, 4, 1.0);
        assert_eq!(q.summary().value_percentiles, None);
        let p = QParams {
            alpha: 0.5,
            gamma: 0.0,
        };
        // state 5: action 1 once, action 2 three times; state 9: action 0 once.
        q.update(State(5), ActionId(1), 3.0, State(0), p); // Q(5,1) = 2
        for _ in 0..3 {
            q.update(State(5), ActionId(2), 1.0, State(0), p); // Q(5,2) stays 1
        }
        q.update(State(9), ActionId(0), -1.0, State(0), p); // Q(9,0) = 0
        let summary = q.summary();
        assert_eq!(summary.action_shares, vec![0.2, 0.2, 0.6, 0.0]);
        // state 9's actions 1 to 3 keep 1.0, its best, three times: a tie;
        // state 5's best (2.0) is alone.
        assert_eq!(summary.tied_states, 1);
        // the 8 values of states 5 and 9, sorted: 0, 1 x 6, 2
        assert_eq!(
            summary.value_percentiles,
            Some([0.0, 0.0, 1.0, 1.0, 1.0, 1.0, 2.0])
        );
    }

    #[test]
    fn greedy_picks_the_maximum() {
        let mut q = QTable::new(StateHasher::Bits7, 4, 0.0);
        q.update(State(3), ActionId(2), 1.0, State(0), QParams::default());
        let mut rng = Pcg64Mcg::seed_from_u64(1);
        for _ in 0..100 {
            assert_eq!(q.greedy(State(3), &mut rng), ActionId(2));
        }
        assert_eq!(q.greedy_policy().action(State(3)), ActionId(2));
        assert_eq!(q.greedy_policy().action(State(4)), ActionId(0));
    }

    #[test]
    fn best_sets_are_exactly_the_actions_the_learner_picks_among() {
        let mut q = QTable::new(StateHasher::Bits7, 4, 1.0);
        let rows: [[f64; 4]; 5] = [
            [1.0, 1.0, 0.5, 1.0],
            [0.2, 0.9, 0.9, 0.1],
            [0.3, 0.3005, 0.1, 0.2996],
            [-1.0, -2.0, -3.0, -4.0],
            [1.0, 1.0, 1.0, 1.0],
        ];
        for (s, row) in rows.iter().enumerate() {
            q.values[s * 4..s * 4 + 4].copy_from_slice(row);
        }
        let mut rng = Pcg64Mcg::seed_from_u64(11);
        for tolerance in [0.0, 0.001] {
            let sets = q.best_sets(tolerance);
            for s in 0..q.hasher().num_states() as u16 {
                let mut seen = 0u8;
                for _ in 0..400 {
                    seen |= 1 << q.greedy_within(State(s), tolerance, &mut rng).0;
                }
                assert_eq!(
                    sets.mask(State(s)),
                    seen,
                    "state {s}, tolerance {tolerance}"
                );
            }
        }
        assert_eq!(q.best_sets(0.0).mask(State(2)), 0b0010);
        assert_eq!(q.best_sets(0.001).mask(State(2)), 0b1011);
        // without ties the lowest of each set is the old export
        assert_eq!(q.best_sets(0.0).lowest(), q.greedy_policy());
    }

    #[test]
    fn ties_are_broken_uniformly() {
        let q = QTable::new(StateHasher::Original, 4, 1.0);
        let mut rng = Pcg64Mcg::seed_from_u64(7);
        let mut counts = [0u32; 4];
        let n = 40_000;
        for _ in 0..n {
            counts[q.greedy(State(0), &mut rng).index()] += 1;
        }
        // Each count ~ Binomial(40000, 1/4): sd ~ 87; allow 5 sd.
        for c in counts {
            assert!((c as i64 - 10_000).abs() < 435, "{counts:?}");
        }
    }

    #[test]
    fn a_table_from_a_policy_acts_like_it() {
        let mut policy = PolicyTable::new(StateHasher::Bits7);
        policy.set(State(5), ActionId(3));
        let q = QTable::from_policy(&policy, 4, 1.0);
        let mut rng = Pcg64Mcg::seed_from_u64(1);
        assert_eq!(q.greedy(State(5), &mut rng), ActionId(3));
        assert_eq!(q.greedy(State(6), &mut rng), ActionId(0));
        assert_eq!(q.greedy_policy(), policy);
        assert_eq!(q.states_visited(), 0);
    }

    #[test]
    fn epsilon_one_explores_every_action() {
        let mut q = QTable::new(StateHasher::Original, 3, 0.0);
        q.update(State(0), ActionId(0), 10.0, State(1), QParams::default());
        let mut rng = Pcg64Mcg::seed_from_u64(3);
        let mut seen = [false; 3];
        for _ in 0..200 {
            seen[q.select(State(0), 1.0, 0.0, &mut rng).index()] = true;
        }
        assert_eq!(seen, [true; 3]);
    }
}
