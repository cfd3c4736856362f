//! Scoring tables: the formations a greedy table makes driving fresh worlds
//! of a run's settings, one world per seed, every candidate on the same
//! seeds (common random numbers), the (table, seed) pairs spread over a
//! thread pool and gathered in order, so that the scores do not depend on
//! the number of threads.

use crate::experiment::plan::mix;
use anyhow::{Context, Result};
use rayon::prelude::*;
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

    /// Each table's formations summed over `seeds`, `steps` steps per
    /// world; in the order of `tables`.
    pub fn score(&self, tables: &[PolicyTable], seeds: &[u64], steps: u64) -> Result<Vec<u64>> {
        let jobs: Vec<(usize, u64)> = (0..tables.len())
            .flat_map(|t| seeds.iter().map(move |&s| (t, s)))
            .collect();
        let counts: Vec<u64> = self.pool.install(|| {
            jobs.par_iter()
                .map(|&(t, seed)| self.formations(&tables[t], seed, steps))
                .collect::<Result<Vec<u64>>>()
        })?;
        Ok(counts
            .chunks(seeds.len().max(1))
            .map(|c| c.iter().sum())
            .collect())
    }

    /// Formations of `table` in the world of `seed` after `steps` steps.
    fn formations(&self, table: &PolicyTable, seed: u64, steps: u64) -> Result<u64> {
        let provenance = Provenance::new("search", "candidate", 0, seed)?;
        let blob = PolicyBlob::new(self.actions.clone(), table.clone(), provenance)?;
        let mut sim = self
            .prepared
            .simulation(seed)
            .context("cannot build a search world")?;
        sim.run(&mut GreedyPolicy::new(blob), steps);
        Ok(sim.totals().formations)
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
