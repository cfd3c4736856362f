//! Sharding an experiment over machines: shard K of N runs the trials at
//! positions K, K + N, K + 2N, ... of the whole run's plan (every arm's
//! trials in order), with the seeds of the whole run, so that the shards'
//! trials together are exactly the unsharded run's. Each shard records what
//! it ran in `shard.json`, from which `merge` checks and joins the shards.

use super::plan::TrialPlan;
use super::spec::ExperimentSpec;
use anyhow::{bail, Context, Result};
use serde::{Deserialize, Serialize};
use std::fmt;
use std::path::{Path, PathBuf};
use std::str::FromStr;

/// Shard `index` of `count` (`K/N` on the command line; K from 0, as
/// Slurm's `SLURM_ARRAY_TASK_ID` counts with `--array=0-(N-1)`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Shard {
    /// K, from 0.
    pub index: usize,
    /// N, at least 1.
    pub count: usize,
}

impl FromStr for Shard {
    type Err = String;

    /// `K/N` with `0 <= K < N`.
    fn from_str(s: &str) -> Result<Shard, String> {
        let bad = || format!("--shard {s:?}: expected K/N with 0 <= K < N, e.g. 0/4");
        let (k, n) = s.split_once('/').ok_or_else(bad)?;
        let (index, count) = (
            k.trim().parse().map_err(|_| bad())?,
            n.trim().parse().map_err(|_| bad())?,
        );
        if index >= count {
            return Err(bad());
        }
        Ok(Shard { index, count })
    }
}

impl fmt::Display for Shard {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}/{}", self.index, self.count)
    }
}

impl Shard {
    /// This shard's plans of the whole run's `plans`.
    pub fn share(self, plans: Vec<TrialPlan>) -> Vec<TrialPlan> {
        plans
            .into_iter()
            .enumerate()
            .filter(|(i, _)| i % self.count == self.index)
            .map(|(_, p)| p)
            .collect()
    }

    /// The default output directory's name: `shard-K-of-N`.
    pub fn dir_name(self) -> String {
        format!("shard-{}-of-{}", self.index, self.count)
    }
}

/// What a shard ran (`shard.json`): the experiment file's text and the run's
/// options, so that `merge` needs nothing else.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct ShardManifest {
    /// The experiment's name.
    pub experiment: String,
    /// The experiment file's text.
    pub source: String,
    /// The shard.
    pub shard: Shard,
    /// Trials per arm of the whole run.
    pub trials: usize,
    /// Scale of the step counts.
    pub scale: f64,
    /// Experiment seed.
    pub seed: u64,
}

/// The manifest's file name in a shard's directory.
pub const MANIFEST: &str = "shard.json";

impl ShardManifest {
    /// The manifest of shard `shard` of a run of `spec`.
    pub fn new(
        spec: &ExperimentSpec,
        shard: Shard,
        trials: usize,
        scale: f64,
        seed: u64,
    ) -> ShardManifest {
        ShardManifest {
            experiment: spec.name.clone(),
            source: spec.source.clone(),
            shard,
            trials,
            scale,
            seed,
        }
    }

    /// Writes it into `dir` atomically; returns its path.
    pub fn write(&self, dir: &Path) -> Result<PathBuf> {
        let path = dir.join(MANIFEST);
        crate::atomic::write(
            &path,
            &serde_json::to_vec_pretty(self).context("cannot encode the shard manifest")?,
        )?;
        Ok(path)
    }

    /// Reads the manifest of the shard in `dir`.
    pub fn read(dir: &Path) -> Result<ShardManifest> {
        let path = dir.join(MANIFEST);
        let bytes = std::fs::read(&path).with_context(|| {
            format!(
                "{} is not a shard's directory: cannot read {}",
                dir.display(),
                path.display()
            )
        })?;
        serde_json::from_slice(&bytes)
            .with_context(|| format!("{} is not a valid shard manifest", path.display()))
    }

    /// The experiment it ran.
    pub fn spec(&self) -> Result<ExperimentSpec> {
        ExperimentSpec::parse(&self.experiment, &self.source)
            .with_context(|| format!("experiment {}", self.experiment))
    }

    /// Whether another shard's manifest is of the same run.
    pub fn same_run(&self, other: &ShardManifest) -> bool {
        fn run(m: &ShardManifest) -> (&str, &str, usize, usize, u64, u64) {
            (
                &m.experiment,
                &m.source,
                m.shard.count,
                m.trials,
                m.scale.to_bits(),
                m.seed,
            )
        }
        run(self) == run(other)
    }
}

/// Checks that the manifests are the shards 0 to N-1 of one run, each once.
pub fn check_complete(manifests: &[(PathBuf, ShardManifest)]) -> Result<()> {
    let Some((first_dir, first)) = manifests.first() else {
        bail!("no shard directories given");
    };
    for (dir, m) in manifests {
        if !m.same_run(first) {
            bail!(
                "{} and {} are shards of different runs (experiment, its file, trials, scale, seed or shard count differ)",
                first_dir.display(),
                dir.display()
            );
        }
    }
    let n = first.shard.count;
    for k in 0..n {
        let dirs: Vec<String> = manifests
            .iter()
            .filter(|(_, m)| m.shard.index == k)
            .map(|(d, _)| d.display().to_string())
            .collect();
        match dirs.len() {
            1 => {}
            0 => bail!("shard {k}/{n} is missing: run `host experiment {} --shard {k}/{n}` and give its directory", first.experiment),
            _ => bail!("shard {k}/{n} is given twice: {}", dirs.join(", ")),
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shards_parse_and_bad_ones_are_named() {
        assert_eq!("2/5".parse::<Shard>(), Ok(Shard { index: 2, count: 5 }));
        assert_eq!("0/1".parse::<Shard>().unwrap().to_string(), "0/1");
        for bad in ["5/5", "1", "a/3", "1/0", "-1/3"] {
            let e = bad.parse::<Shard>().unwrap_err();
            assert!(e.contains(bad), "{e}");
        }
    }
}
