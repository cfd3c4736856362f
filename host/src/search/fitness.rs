//! Scoring tables: the formations a greedy table makes driving fresh worlds
//! of a run's settings, and their mean Eval at the formation checks (which
//! orders tables that form equally many, as on a letter where few form
//! any), one world per seed, every candidate on the same
//! seeds (common random numbers), the (table, seed) pairs spread over a
//! thread pool and gathered in order, so that the scores do not depend on
//! the number of threads.

use crate::experiment::plan::mix;
use anyhow::{Context, Result};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use shared::{ActionTable, PolicyBlob, PolicyTable, Provenance};
use sim::control::greedy::GreedyPolicy;
use sim::scenario::PreparedScenario;

/// Mixed into the search's seed for the fitness worlds' seeds.
const FITNESS_STREAM: u64 = 0xF17E_5500_0000_0001;
/// Mixed into the search's seed for the validation worlds' seeds.
const VALIDATION_STREAM: u64 = 0x7A11_DA7E_0000_0001;

/// The seeds of generation `generation`'s fitness worlds: even, so never a
/// validation seed.
pub fn fitness_seeds(seed: u64, generation: u64, count: usize) -> Vec<u64> {
    (0..count as u64)
        .map(|i| mix(mix(mix(seed ^ FITNESS_STREAM) ^ generation) ^ i) & !1)
        .collect()
}

/// The seeds of the validation worlds, the same every generation: odd, so
/// never a fitness seed.
pub fn validation_seeds(seed: u64, count: usize) -> Vec<u64> {
    (0..count as u64)
        .map(|i| mix(mix(seed ^ VALIDATION_STREAM) ^ i) | 1)
        .collect()
}

/// A table's score on a set of worlds: more formations is better, and of
/// equal formations a higher mean Eval.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct Score {
    /// Formations, summed over the worlds.
    pub formations: u64,
    /// Mean Eval at the formation checks, averaged over the worlds.
    pub eval: f64,
}

impl Score {
    /// Whether this score is better than `other`.
    pub fn beats(&self, other: &Score) -> bool {
        (self.formations, self.eval) > (other.formations, other.eval)
    }

    /// Best first: by formations, then mean Eval.
    pub fn best_first(a: &Score, b: &Score) -> std::cmp::Ordering {
        (b.formations, b.eval)
            .partial_cmp(&(a.formations, a.eval))
            .unwrap_or(std::cmp::Ordering::Equal)
    }
}

/// Builds worlds of one run's settings and drives them with tables.
pub struct Scorer {
    prepared: PreparedScenario,
    actions: ActionTable,
    pool: rayon::ThreadPool,
}

impl Scorer {
    /// A scorer of `prepared`'s worlds with `actions`, on `threads` threads
    /// (0: one per core).
    pub fn new(prepared: PreparedScenario, actions: ActionTable, threads: usize) -> Result<Scorer> {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .context("cannot start the search's threads")?;
        Ok(Scorer {
            prepared,
            actions,
            pool,
        })
    }

    /// Each table's score over `seeds`, `steps` steps per world; in the
    /// order of `tables`.
    pub fn score(&self, tables: &[PolicyTable], seeds: &[u64], steps: u64) -> Result<Vec<Score>> {
        let jobs: Vec<(usize, u64)> = (0..tables.len())
            .flat_map(|t| seeds.iter().map(move |&s| (t, s)))
            .collect();
        let worlds: Vec<Score> = self.pool.install(|| {
            jobs.par_iter()
                .map(|&(t, seed)| self.world(&tables[t], seed, steps))
                .collect::<Result<Vec<Score>>>()
        })?;
        Ok(worlds
            .chunks(seeds.len().max(1))
            .map(|c| Score {
                formations: c.iter().map(|s| s.formations).sum(),
                eval: c.iter().map(|s| s.eval).sum::<f64>() / c.len() as f64,
            })
            .collect())
    }

    /// The score of `table` in the world of `seed` after `steps` steps.
    fn world(&self, table: &PolicyTable, seed: u64, steps: u64) -> Result<Score> {
        let provenance = Provenance::new("search", "candidate", 0, seed)?;
        let blob = PolicyBlob::new(self.actions, table.clone(), provenance)?;
        let mut sim = self
            .prepared
            .simulation(seed)
            .context("cannot build a search world")?;
        sim.run(&mut GreedyPolicy::new(blob), steps);
        Ok(Score {
            formations: sim.totals().formations,
            eval: sim.totals().mean_eval(),
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fitness_and_validation_seeds_never_meet() {
        let v = validation_seeds(5, 50);
        for g in 0..50 {
            assert!(fitness_seeds(5, g, 8).iter().all(|s| !v.contains(s)));
        }
        assert_ne!(fitness_seeds(5, 0, 4), fitness_seeds(5, 1, 4));
        assert_eq!(validation_seeds(5, 3), validation_seeds(5, 3));
    }
}
