//! An experiment's published trials (`trials/<arm>/trial-<NN>.json` in its
//! directory, of any result format), each checked against the plan of the
//! experiment file as it is now: a trial of other settings is stale and left
//! out, with a warning.

use super::plan::plans_of_format;
use super::runner::slug;
use super::spec::ExperimentSpec;
use super::trial::{stored_files, TrialResult};
use anyhow::{Context, Result};
use std::collections::BTreeSet;
use std::path::Path;

/// The trials of an experiment found in a directory.
#[derive(Clone, Debug, Default)]
pub struct Published {
    /// The current trials, in the experiment's arm order, then trial order.
    pub results: Vec<TrialResult>,
    /// Files left out, each with the reason.
    pub stale: Vec<String>,
}

impl Published {
    /// The result formats of the current trials.
    pub fn formats(&self) -> BTreeSet<u32> {
        self.results.iter().map(|r| r.format).collect()
    }
}

/// Reads the trials in `dir/trials` of a run of `spec` at `scale` with
/// `seed`; a missing directory has none. Unreadable files are errors.
pub fn load(spec: &ExperimentSpec, dir: &Path, scale: f64, seed: u64) -> Result<Published> {
    let mut out = Published::default();
    let mut read: Vec<(std::path::PathBuf, String, TrialResult)> = Vec::new();
    for (arm_dir, files) in stored_files(dir)? {
        let name = arm_dir
            .file_name()
            .map(|n| n.to_string_lossy().into_owned())
            .unwrap_or_default();
        if !spec.arms.iter().any(|a| slug(&a.name) == name) {
            out.stale.push(format!(
                "{}: no arm of {} has this directory",
                arm_dir.display(),
                spec.name
            ));
            continue;
        }
        for file in files {
            let bytes =
                std::fs::read(&file).with_context(|| format!("cannot read {}", file.display()))?;
            let r: TrialResult = serde_json::from_slice(&bytes)
                .with_context(|| format!("{} is not a trial result", file.display()))?;
            read.push((file, name.clone(), r));
        }
    }
    // the plans of each format found, as many trials as the files reach
    let trials = read.iter().map(|(_, _, r)| r.trial + 1).max().unwrap_or(0);
    let formats: BTreeSet<u32> = read.iter().map(|(_, _, r)| r.format).collect();
    let plans: Vec<_> = formats
        .iter()
        .flat_map(|&f| plans_of_format(spec, trials, scale, seed, f))
        .collect();
    let mut found: Vec<TrialResult> = Vec::new();
    for (file, name, r) in read {
        let current = plans.iter().any(|p| {
            p.arm == r.arm && p.trial == r.trial && p.hash == r.config_hash && slug(&p.arm) == name
        });
        if current {
            found.push(r);
        } else {
            out.stale.push(format!(
                "{}: of other settings than {}'s arm {:?} now",
                file.display(),
                spec.name,
                r.arm
            ));
        }
    }
    for arm in &spec.arms {
        let mut of_arm: Vec<TrialResult> = found
            .iter()
            .filter(|r| r.arm == arm.name)
            .cloned()
            .collect();
        of_arm.sort_by_key(|r| r.trial);
        out.results.extend(of_arm);
    }
    Ok(out)
}
