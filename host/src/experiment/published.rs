//! An experiment's published trials (`trials/<arm>/trial-<NN>.json` in its
//! directory, of any result format), each checked against the plan of the
//! experiment file as it is now: a trial of other settings is stale and left
//! out, with a warning. Also the figures of the trials published before the
//! clamping border ([`wall_segments`]: `docs/reproduction/wall-segments/trials.tsv`,
//! tab-separated with a header line, columns `experiment`, `arm`, `trial`,
//! `commit`, `format`, `steps`, `formations`, `stuck`, `first_formation`
//! (empty for none) and `collisions_per_1000`).

use super::plan::plans_of_format;
use super::runner::slug;
use super::spec::ExperimentSpec;
use super::trial::{stored_files, TrialResult};
use anyhow::{anyhow, bail, Context, Result};
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
            p.arm == r.arm
                && p.trial == r.trial
                && p.matches(&r.config_hash)
                && slug(&p.arm) == name
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

/// The figures of one trial published with wall segments.
#[derive(Clone, Debug, PartialEq)]
pub struct SegmentTrial {
    /// Its arm.
    pub arm: String,
    /// Its index within the arm.
    pub trial: usize,
    /// Formations.
    pub formations: u64,
    /// Stuck episodes.
    pub stuck: u64,
    /// Step of the first formation, if any.
    pub first_formation: Option<u64>,
    /// Robot-robot collisions per 1000 steps.
    pub collisions_per_1000: f64,
}

/// The wall-segment trials of `experiment` in the file at `path` (its
/// format is in the module's doc); a missing file has none.
pub fn wall_segments(path: &Path, experiment: &str) -> Result<Vec<SegmentTrial>> {
    let text = match std::fs::read_to_string(path) {
        Ok(text) => text,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Ok(Vec::new()),
        Err(e) => return Err(e).with_context(|| format!("cannot read {}", path.display())),
    };
    let mut lines = text.lines().enumerate();
    let header: Vec<&str> = lines
        .next()
        .map(|(_, l)| l.split('\t').collect())
        .unwrap_or_default();
    let column = |name: &str| {
        header
            .iter()
            .position(|h| *h == name)
            .ok_or_else(|| anyhow!("{}: no column {name:?}", path.display()))
    };
    let [exp, arm, trial, formations, stuck, first, collisions] = [
        "experiment",
        "arm",
        "trial",
        "formations",
        "stuck",
        "first_formation",
        "collisions_per_1000",
    ]
    .map(column);
    let (exp, arm, trial) = (exp?, arm?, trial?);
    let (formations, stuck, first, collisions) = (formations?, stuck?, first?, collisions?);
    let mut out = Vec::new();
    for (n, line) in lines.filter(|(_, l)| !l.trim().is_empty()) {
        let at = || format!("{} line {}", path.display(), n + 1);
        let cells: Vec<&str> = line.split('\t').collect();
        if cells.len() != header.len() {
            bail!(
                "{}: {} cells, the header has {}",
                at(),
                cells.len(),
                header.len()
            );
        }
        if cells[exp] != experiment {
            continue;
        }
        fn number<T: std::str::FromStr>(cell: &str, name: &str) -> Result<T> {
            cell.parse()
                .map_err(|_| anyhow!("{name} {cell:?} is not a number"))
        }
        let row = || -> Result<SegmentTrial> {
            Ok(SegmentTrial {
                arm: cells[arm].to_string(),
                trial: number(cells[trial], "trial")?,
                formations: number(cells[formations], "formations")?,
                stuck: number(cells[stuck], "stuck")?,
                first_formation: match cells[first] {
                    "" => None,
                    cell => Some(number(cell, "first_formation")?),
                },
                collisions_per_1000: number(cells[collisions], "collisions_per_1000")?,
            })
        };
        out.push(row().with_context(at)?);
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn wall_segment_trials_are_read_by_column_name_for_one_experiment() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("trials.tsv");
        std::fs::write(
            &path,
            "experiment\tarm\ttrial\tcommit\tformat\tsteps\tformations\tstuck\tfirst_formation\tcollisions_per_1000\n\
             annulus\tRL, author\t0\tabc\t2\t100\t7\t1\t\t3.5\n\
             letters\tT RL\t0\tabc\t2\t100\t9\t0\t40\t1\n",
        )
        .unwrap();
        let rows = wall_segments(&path, "annulus").unwrap();
        assert_eq!(
            rows,
            [SegmentTrial {
                arm: "RL, author".into(),
                trial: 0,
                formations: 7,
                stuck: 1,
                first_formation: None,
                collisions_per_1000: 3.5,
            }]
        );
        assert_eq!(
            wall_segments(&dir.path().join("none"), "annulus").unwrap(),
            []
        );
        std::fs::write(&path, "experiment\tarm\ttrial\tformations\tstuck\tfirst_formation\tcollisions_per_1000\nannulus\tRL\t0\tmany\t0\t\t1\n").unwrap();
        let e = format!("{:#}", wall_segments(&path, "annulus").unwrap_err());
        assert!(
            e.contains("line 2") && e.contains("formations \"many\" is not a number"),
            "{e}"
        );
    }
}
