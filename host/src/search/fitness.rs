//! Scoring tables: the formations a greedy table makes driving fresh worlds
//! of a run's settings, and their mean Eval at the formation checks (which
//! orders tables that form equally many, as on a letter where few form
//! any), one world per seed, every candidate on the same
//! seeds (common random numbers), the (table, world, seed) triples spread
//! over a thread pool and gathered in order, so that the scores do not
//! depend on the number of threads.
//!
//! Several worlds (one per field: a general policy's shapes) are balanced:
//! a table ranks by the sum over the fields of ln(1 + its formations on
//! that field), so that doubling a weak shape's count weighs what doubling
//! a strong one's does. With one field that order is the formations'
//! own.

use crate::experiment::plan::mix;
use crate::train::TrainConfig;
use anyhow::{bail, Context, Result};
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

/// A table's score on a set of worlds: a higher balance is better (more
/// formations, with one field), and of equal balance a higher mean Eval.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Score {
    /// Formations, summed over the worlds of every field.
    pub formations: u64,
    /// Mean Eval at the formation checks, averaged over the worlds.
    pub eval: f64,
    /// The sum over the fields of ln(1 + the field's formations).
    pub balance: f64,
    /// Formations on each field (each field and noise level of the
    /// search, in its order), summed over the worlds.
    #[serde(default)]
    pub fields: Vec<u64>,
}

impl Score {
    /// Whether this score is better than `other`.
    pub fn beats(&self, other: &Score) -> bool {
        Score::best_first(self, other) == std::cmp::Ordering::Less
    }

    /// Best first: by balance, then mean Eval.
    pub fn best_first(a: &Score, b: &Score) -> std::cmp::Ordering {
        (b.balance, b.eval)
            .partial_cmp(&(a.balance, a.eval))
            .unwrap_or(std::cmp::Ordering::Equal)
    }

    /// Whether this score forms at least `share` of `bar`'s count on
    /// every field: always with a share of 0 (as a search before the bar
    /// did, whose logs keep no counts per field), never for a score of
    /// other fields.
    pub fn holds(&self, bar: &Score, share: f64) -> bool {
        share <= 0.0
            || self.fields.len() == bar.fields.len()
                && self
                    .fields
                    .iter()
                    .zip(&bar.fields)
                    .all(|(&mine, &theirs)| mine as f64 >= share * theirs as f64)
    }

    /// The score of per-field scores (formations and mean Eval of each).
    fn of_fields(fields: &[(u64, f64)]) -> Score {
        Score {
            formations: fields.iter().map(|f| f.0).sum(),
            eval: fields.iter().map(|f| f.1).sum::<f64>() / fields.len().max(1) as f64,
            balance: fields.iter().map(|f| (f.0 as f64).ln_1p()).sum(),
            fields: fields.iter().map(|f| f.0).collect(),
        }
    }
}

/// Builds worlds of one run's settings (one per field) and drives them
/// with tables, each world's robots as the table would be flashed: a role
/// table's with the run's innies ([`TrainConfig::role_innies`]), the
/// others' all alike.
pub struct Scorer {
    prepared: Vec<PreparedScenario>,
    role_innies: Vec<usize>,
    actions: ActionTable,
    pool: rayon::ThreadPool,
}

impl Scorer {
    /// A scorer of the worlds of each of `configs` (one per field; the
    /// first one's actions), on `threads` threads (0: one per core).
    pub fn new(configs: &[TrainConfig], threads: usize) -> Result<Scorer> {
        let prepared = configs
            .iter()
            .map(TrainConfig::prepare)
            .collect::<Result<Vec<_>>>()?;
        let role_innies = prepared
            .iter()
            .zip(configs)
            .map(|(p, c)| c.role_innies(p.config().world.robots))
            .collect();
        let (Some(first), Some(config)) = (prepared.first(), configs.first()) else {
            bail!("a search scores on at least one field");
        };
        let forward = first.config().world.forward_speed as f32;
        let actions = ActionTable::new(&config.learn.actions, forward)
            .context("the run's actions are not a valid action table")?;
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .context("cannot start the search's threads")?;
        Ok(Scorer {
            prepared,
            role_innies,
            actions,
            pool,
        })
    }

    /// Threads the worlds are run on.
    pub fn threads(&self) -> usize {
        self.pool.current_num_threads()
    }

    /// The actions the tables' action ids stand for.
    pub fn actions(&self) -> ActionTable {
        self.actions
    }

    /// Fields each table is scored on.
    pub fn fields(&self) -> usize {
        self.prepared.len()
    }

    /// Each table's score over `seeds` on every field, `steps` steps per
    /// world; in the order of `tables`.
    pub fn score(&self, tables: &[PolicyTable], seeds: &[u64], steps: u64) -> Result<Vec<Score>> {
        let fields = self.prepared.len();
        let jobs: Vec<(usize, usize, u64)> = (0..tables.len())
            .flat_map(|t| (0..fields).flat_map(move |f| seeds.iter().map(move |&s| (t, f, s))))
            .collect();
        let worlds: Vec<(u64, f64)> = self.pool.install(|| {
            jobs.par_iter()
                .map(|&(t, f, seed)| self.world(&tables[t], f, seed, steps))
                .collect::<Result<Vec<_>>>()
        })?;
        let per_field: Vec<(u64, f64)> = worlds
            .chunks(seeds.len().max(1))
            .map(|c| {
                (
                    c.iter().map(|w| w.0).sum(),
                    c.iter().map(|w| w.1).sum::<f64>() / c.len() as f64,
                )
            })
            .collect();
        Ok(per_field
            .chunks(fields.max(1))
            .map(Score::of_fields)
            .collect())
    }

    /// The formations and mean Eval of `table` in field `field`'s world of
    /// `seed` after `steps` steps.
    fn world(
        &self,
        table: &PolicyTable,
        field: usize,
        seed: u64,
        steps: u64,
    ) -> Result<(u64, f64)> {
        let provenance = Provenance::new("search", "candidate", 0, seed)?;
        let blob = PolicyBlob::new(self.actions, table.clone(), provenance)?;
        let mut sim = if table.hasher().has_role_bit() {
            let mut prepared = self.prepared[field].clone();
            prepared.config_mut().world.innies = self.role_innies[field];
            prepared.simulation(seed)
        } else {
            self.prepared[field].simulation(seed)
        }
        .context("cannot build a search world")?;
        sim.run(&mut GreedyPolicy::new(blob), steps);
        Ok((sim.totals().formations, sim.totals().mean_eval()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn one_field_ranks_by_formations_and_several_balance_them() {
        let one = |f: u64, e: f64| Score::of_fields(&[(f, e)]);
        assert!(one(5, 0.1).beats(&one(4, 0.9)));
        assert!(one(4, 0.9).beats(&one(4, 0.8)));
        // doubling a weak shape's count outweighs adding as many to a strong one's
        let weak_doubled = Score::of_fields(&[(1000, 0.5), (20, 0.5)]);
        let strong_plus = Score::of_fields(&[(1010, 0.5), (10, 0.5)]);
        assert!(weak_doubled.beats(&strong_plus));
        assert_eq!(weak_doubled.formations, 1020);
    }

    #[test]
    fn a_score_holds_a_share_of_another_only_on_every_field() {
        let bar = Score::of_fields(&[(100, 0.5), (10, 0.5)]);
        let gains_one_loses_one = Score::of_fields(&[(300, 0.5), (8, 0.5)]);
        assert!(gains_one_loses_one.beats(&bar));
        assert!(!gains_one_loses_one.holds(&bar, 1.0));
        assert!(gains_one_loses_one.holds(&bar, 0.8));
        assert!(
            gains_one_loses_one.holds(&bar, 0.0),
            "a share of 0 holds anything"
        );
        let other_fields = Score::of_fields(&[(300, 0.5)]);
        assert!(
            !other_fields.holds(&bar, 0.5),
            "scores of other worlds never hold"
        );
    }

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
