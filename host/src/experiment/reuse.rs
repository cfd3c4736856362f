//! Trials that other runs already made, copied instead of run again
//! (`host experiment NAME --reuse DIR`).
//!
//! A trial's config hash covers everything that determines it (controller,
//! every setting, seed, pre-training, result format; `plan`), so a stored
//! result of the same hash in another run's output directory is the result
//! this run would produce, but for its timing fields. The state-bits and
//! obstacle experiments, for one, share the arm "8 bits (Original)" in both
//! columns. A copy takes this run's experiment, arm and trial names; its
//! `seconds` and `steps_per_second` stay those of the run that made it.
//!
//! Layout read: `<DIR>/trials/<arm>/trial-<NN>.json`, as the runner writes
//! them. Files of another result format, and files that are not trial
//! results, are passed over (as a rerun passes over stale trials).

use super::plan::TrialPlan;
use super::trial::{stored_files, TrialResult};
use anyhow::{bail, Result};
use std::collections::HashMap;
use std::path::PathBuf;

/// The stored trials of other runs' output directories, by config hash.
#[derive(Clone, Debug)]
pub struct ReusableTrials {
    by_hash: HashMap<String, TrialResult>,
}

impl ReusableTrials {
    /// Reads every trial result under each directory's `trials/`. A
    /// directory that does not exist is an error (a mistyped path would
    /// otherwise silently run everything); one without trials holds none.
    pub fn load(dirs: &[PathBuf]) -> Result<ReusableTrials> {
        let mut by_hash = HashMap::new();
        for dir in dirs {
            if !dir.is_dir() {
                bail!(
                    "--reuse {}: not a directory (another run's output directory was expected)",
                    dir.display()
                );
            }
            for file in stored_files(dir)?.into_iter().flat_map(|(_, files)| files) {
                if let Some(result) = TrialResult::read_current(&file) {
                    by_hash.entry(result.config_hash.clone()).or_insert(result);
                }
            }
        }
        Ok(ReusableTrials { by_hash })
    }

    /// How many distinct trials were found.
    pub fn stored(&self) -> usize {
        self.by_hash.len()
    }

    /// The stored result of the trial `plan` describes, named as this run's
    /// (`experiment`, the plan's arm and trial), if one has its hash, seed
    /// and step count.
    pub fn result_for(&self, plan: &TrialPlan) -> Option<TrialResult> {
        let stored = std::iter::once(&plan.hash)
            .chain(&plan.alias)
            .find_map(|h| self.by_hash.get(h))?;
        let same = stored.seed == plan.config.world.seed && stored.steps == plan.config.steps;
        same.then(|| TrialResult {
            experiment: plan.experiment.clone(),
            arm: plan.arm.clone(),
            trial: plan.trial,
            ..stored.clone()
        })
    }
}
