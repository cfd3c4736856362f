//! Experiment files: what an experiment compares (its arms), how its table
//! and figures are laid out, and the thesis' figures to show beside ours.
//!
//! An arm is a [`TrainConfig`]: the file's `[defaults]` table with the
//! arm's own keys merged over it (nested tables such as `learn` key by
//! key), plus the arm-only keys `name`, `row`, `column`, `controller`,
//! `pretrain`, `policy`, `thesis`, `author` and `pucks_reason`. On a screen
//! arena an arm's puck count is the puck rule's
//! ([`sim::scenario::puck_rule`]) unless it sets `pucks` and
//! `pucks_reason`. The file's `page` names the results page of its
//! published trials and `trials` the trials per arm of a run that does not
//! say. The built-in experiments are the `*.toml` files directly in
//! `experiments/` ([`BUILT_IN`], listed by `host/build.rs`). See
//! docs/training.md for the format.

use super::metric::Metric;
use crate::train::TrainConfig;
use anyhow::{bail, Context, Result};
use serde::{Deserialize, Serialize};
use sim::base::ranges;
use sim::scenario::puck_rule::rule_pucks;
use sim::scenario::Arena;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

// The experiments shipped in `experiments/`, built into the binary so
// that `host experiment NAME` works from any directory: `BUILT_IN`.
include!(concat!(env!("OUT_DIR"), "/built_in.rs"));

/// A parsed experiment file.
#[derive(Clone, Debug, PartialEq)]
pub struct ExperimentSpec {
    /// Short name (the file stem): names the output directory.
    pub name: String,
    /// Heading of the report.
    pub title: String,
    /// Which thesis table or figures it reproduces.
    pub thesis: String,
    /// The experiment seed every trial seed derives from.
    pub seed: u64,
    /// Trials per arm of a run that does not say (`--trials`): the
    /// published run's.
    pub trials: usize,
    /// The results page (`docs/PAGE.md`, `host experiment report PAGE`)
    /// that shows its published trials, if any.
    pub page: Option<String>,
    /// Points of the formations-over-time curves.
    pub sample_points: usize,
    /// The results table.
    pub table: TableSpec,
    /// The arms, in file order.
    pub arms: Vec<ArmSpec>,
    /// The charts.
    pub figures: Vec<FigureSpec>,
    /// The file's text.
    pub source: String,
}

/// How the markdown table is laid out: one line per distinct `row`, one
/// group of columns per distinct `column`, one column per metric (ours,
/// then the thesis' where it has one).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct TableSpec {
    /// Caption under the table.
    pub caption: String,
    /// Header of the row-label column.
    pub row_header: String,
    /// The metrics shown.
    pub metrics: Vec<Metric>,
    /// The row whose arm in the same column `formations_ratio` divides by
    /// (or, when no arm of the column has that row, the arm of that name).
    pub ratio_to: Option<String>,
}

impl Default for TableSpec {
    fn default() -> TableSpec {
        TableSpec {
            caption: String::new(),
            row_header: "Arm".into(),
            metrics: vec![Metric::Formations, Metric::Stuck],
            ratio_to: None,
        }
    }
}

/// Which controller an arm runs.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum ArmController {
    /// Orbital construction, innies on fields with a cavity.
    Oc,
    /// Q-learning, on-line from the first step.
    Learn,
    /// A policy blob's greedy actions (the arm's `policy` file), as the
    /// robot runs them: no learning.
    Policy,
    /// Each robot's turn drawn uniformly from the learner's actions every
    /// step: the baseline a learned result must beat.
    Random,
}

impl ArmController {
    /// The name in experiment files.
    pub fn name(self) -> &'static str {
        match self {
            ArmController::Oc => "oc",
            ArmController::Learn => "learn",
            ArmController::Policy => "policy",
            ArmController::Random => "random",
        }
    }
}

/// A Q-table trained before the arm's run, which the run starts from.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct PretrainSpec {
    /// Steps of pre-training.
    pub steps: u64,
    /// Robots during pre-training; `None` for the arm's count.
    pub robots: Option<usize>,
}

/// One arm: a controller on a configuration.
#[derive(Clone, Debug, PartialEq)]
pub struct ArmSpec {
    /// Unique name, used in outputs and seeds.
    pub name: String,
    /// Table row label.
    pub row: String,
    /// Table column group label.
    pub column: String,
    /// The controller.
    pub controller: ArmController,
    /// The run (seed and output keys are set per trial).
    pub config: TrainConfig,
    /// Pre-training (`learn` arms only).
    pub pretrain: Option<PretrainSpec>,
    /// The policy blob a `policy` arm runs (relative to the working
    /// directory: run from the repository root).
    pub policy: Option<PathBuf>,
    /// The thesis' values of this arm, by metric.
    pub thesis: BTreeMap<Metric, f64>,
    /// Per-trial values of the thesis author's own program for this arm
    /// (its published result files), by metric: the side-by-side that
    /// `docs/reproduction.md` tests ours against.
    pub author: BTreeMap<Metric, Vec<f64>>,
    /// Why the arm's puck count is not the puck rule's, if it sets one.
    pub pucks_reason: Option<String>,
}

/// What a chart shows.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum FigureKind {
    /// Formations over time: mean and a band per arm (Figure 15).
    Formations,
    /// Robot-robot collisions per 1000 steps with least-squares lines (Figure 24).
    Collisions,
    /// The scalar field of each distinct field of the arms (Figure 17).
    Fields,
    /// Pictures of the arena during a trial of each arm (Figures 11, 18).
    Snapshots,
}

/// The band around a formations curve.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum BandKind {
    /// The 95 % confidence interval of the mean (the default).
    #[default]
    Ci95,
    /// From the least to the greatest trial (the thesis' Figures 15 and 16:
    /// "the maximum and minimum values of each trial").
    MinMax,
}

/// A moment of a trial that a snapshot shows. The trial is the arm's one
/// with the earliest first formation (the first if none formed), re-run.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Moment {
    /// The random start.
    Start,
    /// Half-way to the first formation (to the end if none).
    Midway,
    /// The formed shape: the world the first formation check tested (the
    /// end of the run if none formed).
    Formed,
}

/// One chart.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FigureSpec {
    /// PNG file name in the output directory.
    pub file: String,
    /// What it shows.
    pub kind: FigureKind,
    /// Title; `None` for a default.
    #[serde(default)]
    pub title: Option<String>,
    /// Arms drawn, by name; empty for all.
    #[serde(default)]
    pub arms: Vec<String>,
    /// Formations: the band around each mean.
    #[serde(default)]
    pub band: BandKind,
    /// Snapshots: the moments shown of each arm's trial.
    #[serde(default = "default_moments")]
    pub moments: Vec<Moment>,
}

fn default_moments() -> Vec<Moment> {
    vec![Moment::Formed]
}

/// The file as written, before arms are merged with the defaults.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ExperimentFile {
    title: String,
    #[serde(default)]
    thesis: String,
    #[serde(default = "default_seed")]
    seed: u64,
    #[serde(default = "default_trials")]
    trials: usize,
    page: Option<String>,
    #[serde(default = "default_sample_points")]
    sample_points: usize,
    #[serde(default)]
    table: TableSpec,
    #[serde(default)]
    defaults: toml::Table,
    arms: Vec<toml::Table>,
    #[serde(default)]
    figures: Vec<FigureSpec>,
}

fn default_seed() -> u64 {
    1
}

fn default_trials() -> usize {
    10
}

fn default_sample_points() -> usize {
    100
}

/// The arm-only keys.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct ArmKeys {
    name: String,
    row: Option<String>,
    #[serde(default)]
    column: String,
    #[serde(default = "default_controller")]
    controller: ArmController,
    pretrain: Option<PretrainSpec>,
    policy: Option<PathBuf>,
    #[serde(default)]
    thesis: BTreeMap<Metric, f64>,
    #[serde(default)]
    author: BTreeMap<Metric, Vec<f64>>,
    pucks_reason: Option<String>,
}

fn default_controller() -> ArmController {
    ArmController::Learn
}

const ARM_KEYS: [&str; 9] = [
    "name",
    "row",
    "column",
    "controller",
    "pretrain",
    "policy",
    "thesis",
    "author",
    "pucks_reason",
];

impl ExperimentSpec {
    /// A built-in experiment by name, or a file by path.
    pub fn load(name_or_path: &str) -> Result<ExperimentSpec> {
        if let Some((name, text)) = BUILT_IN.iter().find(|(n, _)| *n == name_or_path) {
            return ExperimentSpec::parse(name, text)
                .with_context(|| format!("built-in experiment {name}"));
        }
        let path = Path::new(name_or_path);
        if !path.exists() && !name_or_path.contains(['/', '.']) {
            let names: Vec<&str> = BUILT_IN.iter().map(|(n, _)| *n).collect();
            bail!(
                "unknown experiment {name_or_path:?}: expected one of {} or a path to a TOML file",
                names.join(", ")
            );
        }
        let text = ranges::read_text(path, &ranges::SETTINGS_FILE)
            .with_context(|| format!("cannot read experiment file {}", path.display()))?;
        let stem = path
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_else(|| "experiment".into());
        ExperimentSpec::parse(&stem, &text)
            .with_context(|| format!("experiment file {}", path.display()))
    }

    /// Parses an experiment's TOML text; errors name the line or the arm.
    pub fn parse(name: &str, text: &str) -> Result<ExperimentSpec> {
        let file: ExperimentFile = toml::from_str(text)?;
        if file.arms.is_empty() {
            bail!("no [[arms]]");
        }
        ranges::TRIALS.check_count("trials", file.trials as u64)?;
        if file.defaults.contains_key("output") {
            bail!("[defaults]: output settings are chosen by the experiment runner");
        }
        let mut arms: Vec<ArmSpec> = Vec::new();
        for (i, table) in file.arms.into_iter().enumerate() {
            let arm = arm(&file.defaults, table).with_context(|| format!("arm {}", i + 1))?;
            if arms.iter().any(|a| a.name == arm.name) {
                bail!("two arms are named {:?}", arm.name);
            }
            if let Some(other) = arms
                .iter()
                .find(|a| a.row == arm.row && a.column == arm.column)
            {
                bail!(
                    "arms {:?} and {:?} share the table cell (row {:?}, column {:?})",
                    other.name,
                    arm.name,
                    arm.row,
                    arm.column
                );
            }
            arms.push(arm);
        }
        let known = |n: &String| arms.iter().any(|a| &a.name == n);
        if let Some(r) = file
            .table
            .ratio_to
            .as_ref()
            .filter(|r| !known(r) && !arms.iter().any(|a| &a.row == *r))
        {
            bail!("[table] ratio_to = {r:?} is neither a row nor an arm");
        }
        for f in &file.figures {
            if let Some(n) = f.arms.iter().find(|n| !known(n)) {
                bail!("figure {}: {n:?} is not an arm", f.file);
            }
            if f.kind == FigureKind::Snapshots {
                if f.arms.is_empty() || f.moments.is_empty() {
                    bail!("figure {}: snapshots need arms and moments", f.file);
                }
                if let Some(a) = arms
                    .iter()
                    .find(|a| f.arms.contains(&a.name) && a.pretrain.is_some())
                {
                    bail!("figure {}: arm {:?} is pre-trained; snapshots re-run trials without pre-training", f.file, a.name);
                }
            }
        }
        let figure = |file: &str, kind| FigureSpec {
            file: file.into(),
            kind,
            title: None,
            arms: vec![],
            band: BandKind::default(),
            moments: default_moments(),
        };
        let figures = if file.figures.is_empty() {
            vec![
                figure("formations.png", FigureKind::Formations),
                figure("collisions.png", FigureKind::Collisions),
            ]
        } else {
            file.figures
        };
        Ok(ExperimentSpec {
            name: name.to_string(),
            title: file.title,
            thesis: file.thesis,
            seed: file.seed,
            trials: file.trials,
            page: file.page,
            sample_points: file.sample_points.max(2),
            table: file.table,
            arms,
            figures,
            source: text.to_string(),
        })
    }

    /// The arm of that name.
    pub fn arm(&self, name: &str) -> Option<&ArmSpec> {
        self.arms.iter().find(|a| a.name == name)
    }

    /// The arm `formations_ratio` divides `arm`'s formations by: the one of
    /// the `ratio_to` row in `arm`'s column, else the arm named `ratio_to`.
    pub fn ratio_reference(&self, arm: &ArmSpec) -> Option<&ArmSpec> {
        let r = self.table.ratio_to.as_deref()?;
        self.arms
            .iter()
            .find(|a| a.row == r && a.column == arm.column)
            .or_else(|| self.arm(r))
    }
}

/// One arm: its own keys, and the rest merged over the defaults.
fn arm(defaults: &toml::Table, mut table: toml::Table) -> Result<ArmSpec> {
    let mut own = toml::Table::new();
    for key in ARM_KEYS {
        if let Some(v) = table.remove(key) {
            own.insert(key.to_string(), v);
        }
    }
    let keys: ArmKeys = toml::Value::Table(own).try_into()?;
    let context = || format!("arm {:?}", keys.name);
    if table.contains_key("output") {
        bail!(
            "{}: output settings are chosen by the experiment runner",
            context()
        );
    }
    let mut merged = defaults.clone();
    merge(&mut merged, table);
    let mut config = TrainConfig::from_toml_table(merged).with_context(context)?;
    config.validate().with_context(context)?;
    config.world.pucks =
        effective_pucks(&config, keys.pucks_reason.as_deref()).with_context(context)?;
    if keys.pretrain.is_some() && keys.controller != ArmController::Learn {
        bail!("{}: only learning arms can be pre-trained", context());
    }
    if (keys.controller == ArmController::Policy) != keys.policy.is_some() {
        bail!("{}: a policy arm (controller = \"policy\") names its policy file (policy = \"FILE\"), and only a policy arm does", context());
    }
    let roles = keys.controller == ArmController::Oc || config.learn.hasher.0.has_role_bit();
    if let Some(n) = config.innies.filter(|_| !roles) {
        bail!(
            "{}: innies = {n}: only orbital construction and the role hasher have innies",
            context()
        );
    }
    Ok(ArmSpec {
        row: keys.row.unwrap_or_else(|| keys.name.clone()),
        name: keys.name,
        column: keys.column,
        controller: keys.controller,
        config,
        pretrain: keys.pretrain,
        policy: keys.policy,
        thesis: keys.thesis,
        author: keys.author,
        pucks_reason: keys.pucks_reason,
    })
}

/// The arm's puck count: on a screen arena the puck rule's
/// ([`sim::scenario::puck_rule`]) unless the arm sets another and says why
/// (`pucks_reason`); elsewhere the count set, if any. An arena file that
/// cannot be read leaves the count as set: the run fails naming the file.
fn effective_pucks(config: &TrainConfig, reason: Option<&str>) -> Result<Option<usize>> {
    let rule = match config.arena_choice().arena() {
        Ok(arena @ Arena::Screen(_)) => Some(rule_pucks(&config.world.field, &arena)?),
        Ok(Arena::Square(_)) => None,
        Err(_) => return Ok(config.world.pucks),
    };
    match (config.world.pucks, rule, reason) {
        (Some(n), Some(r), None) if n != r => bail!(
            "pucks = {n}: the puck rule gives {} {r}; give the reason for another count as pucks_reason",
            config.world.field
        ),
        (None, _, Some(_)) => bail!("pucks_reason without pucks: the count is the puck rule's"),
        (pucks, rule, _) => Ok(pucks.or(rule)),
    }
}

/// Writes `over` into `base`, merging nested tables key by key.
pub(crate) fn merge(base: &mut toml::Table, over: toml::Table) {
    for (key, value) in over {
        match (base.get_mut(&key), value) {
            (Some(toml::Value::Table(b)), toml::Value::Table(o)) => merge(b, o),
            (_, value) => {
                base.insert(key, value);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const FILE: &str = r#"
title = "t"
[table]
metrics = ["formations", "formations_ratio"]
ratio_to = "A"
[defaults]
robots = 4
[defaults.learn]
alpha = 0.3
gamma = 0.5
[[arms]]
name = "A"
controller = "oc"
thesis = { formations = 12.5 }
[[arms]]
name = "B"
row = "b"
robots = 2
pretrain = { steps = 100, robots = 1 }
[arms.learn]
alpha = 0.1
"#;

    #[test]
    fn arms_merge_over_the_defaults_key_by_key() {
        let spec = ExperimentSpec::parse("x", FILE).unwrap();
        let (a, b) = (&spec.arms[0], &spec.arms[1]);
        assert_eq!(
            (a.controller, a.config.world.robots, a.row.as_str()),
            (ArmController::Oc, Some(4), "A")
        );
        assert_eq!(a.thesis[&Metric::Formations], 12.5);
        assert_eq!(
            (
                b.config.world.robots,
                b.config.learn.alpha,
                b.config.learn.gamma
            ),
            (Some(2), 0.1, 0.5)
        );
        assert_eq!(
            b.pretrain,
            Some(PretrainSpec {
                steps: 100,
                robots: Some(1)
            })
        );
        assert_eq!(spec.figures.len(), 2, "default figures");
    }

    #[test]
    fn mistakes_are_named() {
        let e = |text: &str| format!("{:#}", ExperimentSpec::parse("x", text).unwrap_err());
        let typo = FILE.replace("robots = 2", "robts = 2");
        assert!(
            e(&typo).contains("arm \"B\"") && e(&typo).contains("robts"),
            "{}",
            e(&typo)
        );
        let bad = FILE.replace("ratio_to = \"A\"", "ratio_to = \"Z\"");
        assert!(
            e(&bad).contains("\"Z\" is neither a row nor an arm"),
            "{}",
            e(&bad)
        );
        let innies = FILE.replace("row = \"b\"", "row = \"b\"\ninnies = 1");
        assert!(
            e(&innies).contains("only orbital construction and the role hasher have innies"),
            "{}",
            e(&innies)
        );
        let syntax = FILE.replace("[table]", "[table");
        assert!(e(&syntax).contains("line 3"), "{}", e(&syntax));
        let metric = FILE.replace("\"formations_ratio\"", "\"speed\"");
        assert!(e(&metric).contains("speed"), "{}", e(&metric));
        let range = FILE.replace("alpha = 0.1", "alpha = 3.0");
        assert!(e(&range).contains("learn.alpha = 3"), "{}", e(&range));
        let no_file = FILE.replace("controller = \"oc\"", "controller = \"policy\"");
        assert!(
            e(&no_file).contains("names its policy file"),
            "{}",
            e(&no_file)
        );
        let stray = FILE.replace(
            "controller = \"oc\"",
            "controller = \"oc\"\npolicy = \"p.policy\"",
        );
        assert!(
            e(&stray).contains("only a policy arm does"),
            "{}",
            e(&stray)
        );
    }

    #[test]
    fn a_policy_arm_runs_its_file_and_its_trials_hash_the_file_contents() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("p.policy");
        let text = format!(
            "title = \"t\"\n[[arms]]\nname = \"P\"\ncontroller = \"policy\"\npolicy = {:?}\nsteps = 300\nrobots = 3\npucks = 20\n",
            path.display().to_string()
        );
        let spec = ExperimentSpec::parse("x", &text).unwrap();
        assert_eq!(spec.arms[0].policy.as_deref(), Some(path.as_path()));
        let heuristic =
            Path::new(env!("CARGO_MANIFEST_DIR")).join("../policies/oc-heuristic.policy");
        std::fs::copy(&heuristic, &path).unwrap();
        let plan = &super::super::plan::plans(&spec, 1, 1.0, 1)[0];
        let result = super::super::trial::run(plan, None).unwrap();
        assert_eq!((result.steps, result.states_visited), (300, None));
        // another policy under the same name is another trial
        let mut bytes = std::fs::read(&path).unwrap();
        let last = bytes.len() - 5;
        bytes[last] ^= 1;
        std::fs::write(&path, &bytes).unwrap();
        assert_ne!(
            super::super::plan::plans(&spec, 1, 1.0, 1)[0].hash,
            plan.hash
        );
    }

    #[test]
    fn every_built_in_experiment_parses() {
        for (name, text) in BUILT_IN {
            let spec =
                ExperimentSpec::parse(name, text).unwrap_or_else(|e| panic!("{name}: {e:#}"));
            assert!(!spec.arms.is_empty());
        }
    }
}
