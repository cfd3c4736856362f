//! The cross-entropy method over a policy table: an independent categorical
//! distribution over the actions of every state, sampled into candidate
//! tables and moved towards the actions of the best candidates.
//!
//! No maintained crate fits: the Rust CEM implementations we found
//! (`eqsolver::global_optimisers::CrossEntropy`) sample continuous
//! Gaussians and call the objective one point at a time, where this search
//! needs categorical variables and a whole population scored at once (in
//! parallel, on common seeds); the method itself is a few lines.

use rand::RngExt;
use shared::{ActionId, PolicyTable, State, StateHasher};
use sim::base::rng::SimRng;

/// Each state's action probabilities.
#[derive(Clone, Debug, PartialEq)]
pub struct Categorical {
    hasher: StateHasher,
    actions: usize,
    /// `probs[s * actions + a]`.
    probs: Vec<f64>,
}

impl Categorical {
    /// Centred on `table`: each state's action of the table with
    /// probability `keep`, every other action an equal share of the rest.
    pub fn around(table: &PolicyTable, actions: usize, keep: f64) -> Categorical {
        let hasher = table.hasher();
        let other = (1.0 - keep) / (actions - 1) as f64;
        let mut probs = vec![other; hasher.num_states() * actions];
        for (state, action) in table.entries() {
            probs[state.index() * actions + action.index().min(actions - 1)] = keep;
        }
        Categorical {
            hasher,
            actions,
            probs,
        }
    }

    /// One table: each state's action drawn from its probabilities.
    pub fn sample(&self, rng: &mut SimRng) -> PolicyTable {
        let mut table = PolicyTable::new(self.hasher);
        for (s, row) in self.probs.chunks(self.actions).enumerate() {
            let mut u = rng.random::<f64>();
            let mut pick = self.actions - 1;
            for (a, &p) in row.iter().enumerate() {
                if u < p {
                    pick = a;
                    break;
                }
                u -= p;
            }
            table.set(State(s as u16), ActionId(pick as u8));
        }
        table
    }

    /// Moves every state's probabilities a fraction `rate` towards the
    /// frequencies of its actions among `elites`, then lifts each to at
    /// least `floor` (renormalised), so that no action is ever ruled out.
    pub fn update(&mut self, elites: &[&PolicyTable], rate: f64, floor: f64) {
        if elites.is_empty() {
            return;
        }
        let share = 1.0 / elites.len() as f64;
        for (s, row) in self.probs.chunks_mut(self.actions).enumerate() {
            let mut freq = vec![0.0; row.len()];
            for table in elites {
                freq[table.action(State(s as u16)).index().min(row.len() - 1)] += share;
            }
            for (p, f) in row.iter_mut().zip(&freq) {
                *p = ((1.0 - rate) * *p + rate * f).max(floor);
            }
            let total: f64 = row.iter().sum();
            row.iter_mut().for_each(|p| *p /= total);
        }
    }

    /// The mean over states of each state's entropy, in bits: how far the
    /// search still spreads.
    pub fn mean_entropy(&self) -> f64 {
        let rows = self.probs.chunks(self.actions);
        let n = rows.len() as f64;
        rows.map(|row| {
            row.iter()
                .filter(|&&p| p > 0.0)
                .map(|&p| -p * p.log2())
                .sum::<f64>()
        })
        .sum::<f64>()
            / n
    }

    /// The probability of `action` in `state`.
    pub fn prob(&self, state: State, action: ActionId) -> f64 {
        self.probs[state.index() * self.actions + action.index()]
    }
}

/// A table of uniformly random actions.
pub fn random_table(hasher: StateHasher, actions: usize, rng: &mut SimRng) -> PolicyTable {
    let mut table = PolicyTable::new(hasher);
    for s in 0..hasher.num_states() {
        table.set(
            State(s as u16),
            ActionId(rng.random_range(0..actions) as u8),
        );
    }
    table
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;

    #[test]
    fn a_distribution_around_a_table_samples_mostly_its_actions() {
        let mut rng = SimRng::seed_from_u64(1);
        let start = random_table(StateHasher::Original, 4, &mut rng);
        let c = Categorical::around(&start, 4, 0.7);
        let s = State(17);
        let a = start.action(s);
        assert!((c.prob(s, a) - 0.7).abs() < 1e-12);
        let kept = (0..2000)
            .filter(|_| c.sample(&mut rng).action(s) == a)
            .count();
        assert!((1300..1500).contains(&kept), "{kept}");
        // entropy of (0.7, 0.1, 0.1, 0.1)
        let h = -(0.7f64 * 0.7f64.log2() + 3.0 * 0.1 * 0.1f64.log2());
        assert!((c.mean_entropy() - h).abs() < 1e-9);
    }

    #[test]
    fn an_update_moves_towards_the_elites_and_keeps_the_floor() {
        let mut rng = SimRng::seed_from_u64(2);
        let start = random_table(StateHasher::Bits7, 4, &mut rng);
        let mut c = Categorical::around(&start, 4, 0.25);
        let mut elite = PolicyTable::new(StateHasher::Bits7);
        elite.set(State(3), ActionId(2));
        for _ in 0..50 {
            c.update(&[&elite], 0.5, 0.01);
        }
        let p = c.prob(State(3), ActionId(2));
        assert!(p > 0.96 && p < 0.98, "{p}");
        assert!(c.prob(State(3), ActionId(1)) >= 0.01 / 1.04);
        let row: f64 = (0..4).map(|a| c.prob(State(3), ActionId(a))).sum();
        assert!((row - 1.0).abs() < 1e-12);
    }
}
