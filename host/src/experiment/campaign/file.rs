//! Campaigns: experiments made of stages, each a search (`host search`), a
//! training run (`host train`), an evaluation of tables on report seeds or
//! the publication of the results, a stage continuing from an earlier
//! stage's table (`from`), so that a shipped table's whole lineage is one
//! file. `host experiment FILE` runs a file with `[[stages]]` ([`run`](super::run)).
//!
//! The file (TOML):
//! ```toml
//! title = "What the campaign measures"
//! [defaults]            # keys every stage starts from (its own win)
//! sensors = "robot"     # a training config's keys (docs/training.md)
//! arena = "tv75"
//! noise = 1.0
//! population = 8        # the search's keys (`host search` flags, snake_case)
//! [[stages]]
//! name = "thesis-V-oc"  # the output files' stem and the policy's name
//! kind = "search"       # search, train, evaluate or publish
//! label = "search from distilled OC"   # how result tables name its table
//! field = "thesis:V"
//! start = "oc"          # a search starts from oc, random or a file ...
//! generations = 5
//! [[stages]]
//! name = "thesis-V-more"
//! kind = "search"
//! from = "thesis-V-oc"  # ... or from an earlier stage's table
//! ships = "policies/robot-search-V.policy"   # the shipped copy of its table
//! ```
//! A search stage's keys are a training config's (the world) and the
//! search's settings; every search setting must be given (in `[defaults]`
//! or the stage), none is taken from `host search`'s defaults. A train
//! stage's are a training config's (`from`: `--init-from` that table). An
//! evaluate stage runs `oc`, the named stages' tables and the named
//! `.policy` files on each of its `fields` for its world's `steps` on each
//! of its `seeds`: a stage searched or trained on one field only on that
//! field; one on several fields (a general table) and a policy file on all.
//! A publish stage copies the tables, logs and evaluations into
//! `dir/runs/` and writes `dir/results.json` ([`publish`](super::publish)).
//!
//! Outputs in the output directory: `<stage>.policy` and
//! `<stage>.search.json` (search), `<stage>.policy` and `<stage>.ckpt`
//! (train), `<stage>.jsonl` (evaluate: one JSON line per field, controller
//! and seed: `field`, `controller`, `seed`, `steps`, `formations`), beside
//! `<stage>.toml` (the world it ran in) and `<stage>.done` (the hash of its
//! settings, written last). A stage whose outputs and `.done` hash are
//! there is skipped, so a killed campaign resumes.

use crate::search::SearchConfig;
use crate::train::TrainConfig;
use anyhow::{bail, Context, Result};
use serde::Deserialize;
use sim::base::ranges;
use sim::fields::source::FieldSource;
use std::path::{Path, PathBuf};

/// A campaign: its stages in the order they run.
#[derive(Clone, Debug, PartialEq)]
pub struct Campaign {
    /// Short name (the file stem): names the default output directory.
    pub name: String,
    /// What it measures.
    pub title: String,
    /// The stages, each after those it continues from.
    pub stages: Vec<Stage>,
}

/// One stage.
#[derive(Clone, Debug, PartialEq)]
pub struct Stage {
    /// The output files' stem and the policy's name.
    pub name: String,
    /// How result tables name its table.
    pub label: String,
    /// The stage whose table it starts from.
    pub from: Option<String>,
    /// The shipped copy of its table, if any.
    pub ships: Option<PathBuf>,
    /// What it does.
    pub work: Work,
}

impl Stage {
    /// The fields its table is made on (none for an evaluation or a
    /// publication).
    pub fn fields(&self) -> Vec<String> {
        match &self.work {
            Work::Search { world, search } => std::iter::once(&world.world.field)
                .chain(&search.also_field)
                .map(|f| f.to_string())
                .collect(),
            Work::Train { world } => vec![world.world.field.to_string()],
            Work::Evaluate(_) | Work::Publish(_) => Vec::new(),
        }
    }
}

/// What a stage does.
#[derive(Clone, Debug, PartialEq)]
pub enum Work {
    /// The cross-entropy search in `world` (its output settings the
    /// runner's).
    Search {
        /// The world searched in.
        world: Box<TrainConfig>,
        /// The search's settings (with `from`, its start is that table).
        search: SearchConfig,
    },
    /// Q-learning in `world`.
    Train {
        /// The training run.
        world: Box<TrainConfig>,
    },
    /// Tables on report seeds.
    Evaluate(Evaluation),
    /// The results into the docs.
    Publish(Publication),
}

/// An evaluate stage's runs.
#[derive(Clone, Debug, PartialEq)]
pub struct Evaluation {
    /// The world (its `steps` the length of each run), on each field.
    pub world: Box<TrainConfig>,
    /// The fields.
    pub fields: Vec<FieldSource>,
    /// `oc` or a stage's name.
    pub controllers: Vec<String>,
    /// The report seeds, one run each.
    pub seeds: Vec<u64>,
}

/// Whether an evaluate stage's controller names a policy file (a shipped
/// table, run on every field) rather than a stage.
pub fn is_policy_file(controller: &str) -> bool {
    controller.ends_with(".policy")
}

/// The keys a stage has beside its world's and its search's.
#[derive(Debug, Default, Deserialize)]
#[serde(deny_unknown_fields)]
struct StageKeys {
    name: String,
    kind: String,
    #[serde(default)]
    label: Option<String>,
    #[serde(default)]
    from: Option<String>,
    #[serde(default)]
    ships: Option<PathBuf>,
    #[serde(default)]
    fields: Option<Vec<FieldSource>>,
    #[serde(default)]
    controllers: Option<Vec<String>>,
    #[serde(default)]
    seeds: Option<Vec<u64>>,
    #[serde(default)]
    dir: Option<PathBuf>,
    #[serde(default)]
    evaluations: Option<Vec<String>>,
    #[serde(default)]
    report_fields: Option<Vec<String>>,
    #[serde(default)]
    targets: Option<toml::Value>,
}

/// Keys of [`StageKeys`].
const STAGE_KEYS: [&str; 12] = [
    "name",
    "kind",
    "label",
    "from",
    "ships",
    "fields",
    "controllers",
    "seeds",
    "dir",
    "evaluations",
    "report_fields",
    "targets",
];

/// The keys of the search's settings, as [`SearchConfig`] declares them.
fn search_keys() -> Vec<String> {
    use clap::{Args, FromArgMatches};
    let command = SearchConfig::augment_args(clap::Command::new("search").no_binary_name(true));
    command
        .try_get_matches_from(Vec::<String>::new())
        .ok()
        .and_then(|m| SearchConfig::from_arg_matches(&m).ok())
        .and_then(|c| toml::Table::try_from(c).ok())
        .map(|t| t.keys().cloned().collect())
        .unwrap_or_default()
}

impl Campaign {
    /// Whether `text` is a campaign's (it has `[[stages]]`).
    pub fn is_campaign(text: &str) -> bool {
        toml::from_str::<toml::Table>(text).is_ok_and(|t| t.contains_key("stages"))
    }

    /// The campaign at `name_or_path`, if that is a campaign's file (one
    /// with `[[stages]]`); `None` for anything else (a built-in
    /// experiment's name, an experiment file).
    pub fn at(name_or_path: &str) -> Result<Option<Campaign>> {
        let path = Path::new(name_or_path);
        if !path.is_file() {
            return Ok(None);
        }
        let text = ranges::read_text(path, &ranges::SETTINGS_FILE)
            .with_context(|| format!("cannot read experiment file {}", path.display()))?;
        if !Campaign::is_campaign(&text) {
            return Ok(None);
        }
        Campaign::load(path).map(Some)
    }

    /// Reads a campaign file; errors name the file, the stage and the key.
    pub fn load(path: &Path) -> Result<Campaign> {
        let text = ranges::read_text(path, &ranges::SETTINGS_FILE)
            .with_context(|| format!("cannot read campaign file {}", path.display()))?;
        let stem = path
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_else(|| "campaign".into());
        Campaign::parse(&stem, &text).with_context(|| format!("campaign file {}", path.display()))
    }

    /// Parses a campaign's TOML text.
    pub fn parse(name: &str, text: &str) -> Result<Campaign> {
        let mut file: toml::Table = toml::from_str(text)?;
        let title = match file.remove("title") {
            Some(toml::Value::String(s)) => s,
            Some(_) => bail!("title: expected a string"),
            None => String::new(),
        };
        let defaults = match file.remove("defaults") {
            Some(toml::Value::Table(t)) => t,
            Some(_) => bail!("defaults: expected a table"),
            None => toml::Table::new(),
        };
        let stages = match file.remove("stages") {
            Some(toml::Value::Array(a)) => a,
            _ => bail!("no [[stages]]"),
        };
        if let Some(key) = file.keys().next() {
            bail!("unknown key {key:?}: expected title, defaults or stages");
        }
        if defaults.contains_key("output") {
            bail!("[defaults]: output settings are chosen by the campaign's runner");
        }
        let search_keys = search_keys();
        let mut out: Vec<Stage> = Vec::new();
        for (i, value) in stages.into_iter().enumerate() {
            let toml::Value::Table(table) = value else {
                bail!("stage {}: expected a table", i + 1);
            };
            let label = table
                .get("name")
                .and_then(|n| n.as_str())
                .map_or_else(|| format!("stage {}", i + 1), |n| format!("stage {n:?}"));
            let stage = stage(&defaults, table, &search_keys, &out).context(label)?;
            out.push(stage);
        }
        Ok(Campaign {
            name: name.to_string(),
            title,
            stages: out,
        })
    }

    /// The stage of this name.
    pub fn stage(&self, name: &str) -> Option<&Stage> {
        self.stages.iter().find(|s| s.name == name)
    }
}

/// One stage from its table over the defaults; `earlier` are the stages
/// before it.
fn stage(
    defaults: &toml::Table,
    mut table: toml::Table,
    search_keys: &[String],
    earlier: &[Stage],
) -> Result<Stage> {
    let mut own = toml::Table::new();
    for key in STAGE_KEYS {
        if let Some(v) = table.remove(key) {
            own.insert(key.to_string(), v);
        }
    }
    let keys: StageKeys = toml::Value::Table(own).try_into()?;
    if table.contains_key("output") {
        bail!("output settings are chosen by the campaign's runner");
    }
    if earlier.iter().any(|s| s.name == keys.name) {
        bail!("two stages are named {:?}", keys.name);
    }
    if let Some(from) = &keys.from {
        if !earlier.iter().any(|s| &s.name == from) {
            bail!("from = {from:?}: no earlier stage has that name");
        }
    }
    let kind = keys.kind.as_str();
    let given = |key: &str, present: bool| -> Result<()> {
        if present {
            bail!("{key}: a {kind} stage takes no {key}");
        }
        Ok(())
    };
    if kind != "evaluate" {
        given("fields", keys.fields.is_some())?;
        given("controllers", keys.controllers.is_some())?;
        given("seeds", keys.seeds.is_some())?;
    }
    if kind != "publish" {
        given("dir", keys.dir.is_some())?;
        given("evaluations", keys.evaluations.is_some())?;
        given("report_fields", keys.report_fields.is_some())?;
        given("targets", keys.targets.is_some())?;
    }
    if !matches!(kind, "search" | "train") {
        given("from", keys.from.is_some())?;
        given("ships", keys.ships.is_some())?;
    }
    // the stage's own keys over the defaults, the search's keys apart
    let mut merged = defaults.clone();
    crate::experiment::spec::merge(&mut merged, table.clone());
    let mut search = toml::Table::new();
    for key in search_keys {
        if let Some(v) = merged.remove(key) {
            search.insert(key.clone(), v);
        }
    }
    if kind != "search" {
        if let Some(key) = search_keys.iter().find(|k| table.contains_key(*k)) {
            bail!("{key}: a search setting, and this is a {kind} stage");
        }
    }
    let mut world = TrainConfig::from_toml_table(merged)?;
    world.output.name = Some(keys.name.clone());
    world.validate()?;
    let world = Box::new(world);
    let work = match kind {
        "search" => {
            if keys.from.is_some() && search.contains_key("start") {
                bail!("start: a stage continuing from another (from) starts from its table");
            }
            if keys.from.is_some() {
                search.insert("start".into(), toml::Value::String("random".into()));
            }
            let search: SearchConfig = toml::Value::Table(search).try_into()?;
            search.validate(world.learn.actions.len())?;
            Work::Search { world, search }
        }
        "train" => Work::Train { world },
        "evaluate" => {
            let evaluation = Evaluation {
                world,
                fields: keys.fields.unwrap_or_default(),
                controllers: keys.controllers.unwrap_or_default(),
                seeds: keys.seeds.unwrap_or_default(),
            };
            if evaluation.fields.is_empty() || evaluation.seeds.is_empty() {
                bail!("an evaluate stage names its fields and seeds");
            }
            for c in &evaluation.controllers {
                if c != "oc" && !is_policy_file(c) && !earlier.iter().any(|s| &s.name == c) {
                    bail!("controllers: {c:?} is neither oc, an earlier stage nor a .policy file");
                }
            }
            Work::Evaluate(evaluation)
        }
        "publish" => Work::Publish(Publication::new(
            keys.dir,
            keys.evaluations.unwrap_or_default(),
            keys.report_fields.unwrap_or_default(),
            keys.targets,
            earlier,
        )?),
        other => bail!("kind = {other:?}: expected search, train, evaluate or publish"),
    };
    Ok(Stage {
        label: keys.label.unwrap_or_else(|| keys.name.clone()),
        name: keys.name,
        from: keys.from,
        ships: keys.ships,
        work,
    })
}

/// What a publish stage writes and how its targets are judged.
#[derive(Clone, Debug, PartialEq)]
pub struct Publication {
    /// Under the docs directory: `<dir>/runs/`, `<dir>/results.json`, and
    /// the page `<dir>.md`.
    pub dir: PathBuf,
    /// The evaluate stages: at the default noise, then at twice it.
    pub evaluations: Vec<String>,
    /// The fields the report judges, in its order.
    pub report_fields: Vec<String>,
    /// The general tables: the stages searched on several fields.
    pub general: Vec<String>,
    /// The targets.
    pub targets: Targets,
}

/// The targets table's rules (a publish stage's `targets`).
#[derive(Clone, Debug, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Targets {
    /// The field whose best learned table is judged as a multiple of OC's.
    pub ratio_field: String,
    /// That multiple.
    pub ratio: f64,
    /// Any other report field's best own table: at least this many per
    /// million steps ...
    pub least: f64,
    /// ... and OC's count where OC forms at least this many ...
    pub oc_at_least: f64,
    /// ... and these multiples of OC's count, by field.
    #[serde(default)]
    pub times_oc: std::collections::BTreeMap<String, f64>,
}

impl Publication {
    /// A publish stage's settings; `earlier` are the stages before it.
    pub fn new(
        dir: Option<PathBuf>,
        evaluations: Vec<String>,
        report_fields: Vec<String>,
        targets: Option<toml::Value>,
        earlier: &[Stage],
    ) -> Result<Publication> {
        let dir = dir.context("dir: a publish stage names its directory under the docs")?;
        if evaluations.is_empty() || evaluations.len() > 2 {
            bail!("evaluations: one or two evaluate stages (the default noise, then twice it)");
        }
        for e in &evaluations {
            if !earlier
                .iter()
                .any(|s| &s.name == e && matches!(s.work, Work::Evaluate(_)))
            {
                bail!("evaluations: {e:?} is no earlier evaluate stage");
            }
        }
        let targets: Targets = targets
            .context("targets: a publish stage states its targets")?
            .try_into()
            .context("targets")?;
        let general = earlier
            .iter()
            .filter(|s| s.fields().len() > 1)
            .map(|s| s.name.clone())
            .collect();
        Ok(Publication {
            dir,
            evaluations,
            report_fields,
            general,
            targets,
        })
    }
}
