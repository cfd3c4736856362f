//! `host experiment merge`: the shards of one run ([`super::shard`]) joined
//! into the outputs the unsharded run writes. Every shard must have
//! finished its trials; a pre-trained table that several shards ran must be
//! the same in each (byte for byte: same settings, same seed).

use super::outputs;
use super::plan::plans;
use super::runner::{finished, trial_path};
use super::shard::{check_complete, ShardManifest};
use anyhow::{bail, Context, Result};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// What a merge did.
#[derive(Clone, Debug, PartialEq)]
pub struct MergeReport {
    /// The output directory.
    pub dir: PathBuf,
    /// Trials joined.
    pub trials: usize,
    /// Distinct pre-trained tables joined.
    pub pretrained: usize,
    /// The report files written.
    pub outputs: Vec<PathBuf>,
}

/// Joins the shards in `dirs` into `out` (`None`: `out/experiments/<name>`).
pub fn merge(dirs: &[PathBuf], out: Option<&Path>) -> Result<MergeReport> {
    let manifests = dirs
        .iter()
        .map(|d| Ok((d.clone(), ShardManifest::read(d)?)))
        .collect::<Result<Vec<_>>>()?;
    check_complete(&manifests)?;
    let run = &manifests[0].1;
    let spec = run.spec()?;
    let out = out.map_or_else(
        || Path::new("out/experiments").join(&spec.name),
        Path::to_path_buf,
    );
    crate::atomic::create_dirs(&out)?;
    let mut shard_dirs = vec![Path::new(""); run.shard.count];
    for (dir, m) in &manifests {
        shard_dirs[m.shard.index] = dir;
    }

    let plans = plans(&spec, run.trials, run.scale, run.seed);
    let mut results = Vec::with_capacity(plans.len());
    for (i, plan) in plans.iter().enumerate() {
        let dir = shard_dirs[i % run.shard.count];
        let Some(result) = finished(dir, plan) else {
            bail!(
                "shard {}/{} in {} has not finished arm {:?} trial {}: run `host experiment {} --shard {}/{} --out {}` again",
                i % run.shard.count,
                run.shard.count,
                dir.display(),
                plan.arm,
                plan.trial,
                spec.name,
                i % run.shard.count,
                run.shard.count,
                dir.display()
            );
        };
        let from = trial_path(dir, plan);
        let bytes =
            std::fs::read(&from).with_context(|| format!("cannot read {}", from.display()))?;
        let to = trial_path(&out, plan);
        if let Some(arm) = to.parent() {
            crate::atomic::create_dirs(arm)?;
        }
        crate::atomic::write(&to, &bytes)?;
        results.push(result);
    }

    let pretrained = join_pretrained(&shard_dirs, &out)?;
    let outputs = outputs::write(&spec, &out, &results, run.scale, run.seed)?;
    Ok(MergeReport {
        dir: out,
        trials: results.len(),
        pretrained,
        outputs,
    })
}

/// Copies every shard's pre-trained tables into `out/pretrained`, checking
/// that the copies of a table that several shards ran are identical;
/// returns how many distinct tables there are.
fn join_pretrained(shard_dirs: &[&Path], out: &Path) -> Result<usize> {
    let mut tables: BTreeMap<String, (PathBuf, Vec<u8>)> = BTreeMap::new();
    for dir in shard_dirs {
        let Ok(entries) = std::fs::read_dir(dir.join("pretrained")) else {
            continue;
        };
        for entry in entries {
            let path = entry
                .with_context(|| format!("cannot list {}", dir.join("pretrained").display()))?
                .path();
            if path.extension().is_none_or(|e| e != "ckpt") {
                continue;
            }
            let bytes =
                std::fs::read(&path).with_context(|| format!("cannot read {}", path.display()))?;
            let name = path
                .file_name()
                .map(|n| n.to_string_lossy().into_owned())
                .unwrap_or_default();
            match tables.get(&name) {
                Some((first, seen)) if *seen != bytes => bail!(
                    "the pre-trained tables {} and {} differ, though they are of the same settings and seed",
                    first.display(),
                    path.display()
                ),
                Some(_) => {}
                None => {
                    tables.insert(name, (path, bytes));
                }
            }
        }
    }
    if !tables.is_empty() {
        crate::atomic::create_dirs(&out.join("pretrained"))?;
    }
    for (name, (_, bytes)) in &tables {
        crate::atomic::write(&out.join("pretrained").join(name), bytes)?;
    }
    Ok(tables.len())
}
