//! Running a campaign: its stages in order, each skipped when its outputs
//! and its settings' hash (`<stage>.done`) are there, so that a killed run
//! resumes at the stage it was in.

use super::file::{is_policy_file, Campaign, Evaluation, Stage, Work};
use crate::experiment::plan::hash;
use crate::search::{SearchConfig, SearchRequest, Start};
use crate::train::{TrainConfig, TrainFlags, TrainRequest};
use anyhow::{bail, Context, Result};
use rayon::prelude::*;
use serde::Serialize;
use sim::scenario::ControllerChoice;
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::time::Instant;

/// How a campaign is run.
#[derive(Clone, Debug, PartialEq)]
pub struct CampaignOptions {
    /// The output directory of every stage's files.
    pub out: PathBuf,
    /// Fraction of every step count and generation count (1: the file's).
    pub scale: f64,
    /// Only these stages, with the stages they need that are not finished
    /// (every stage when empty).
    pub stages: Vec<String>,
}

/// What a campaign run did.
#[derive(Clone, Debug, PartialEq)]
pub struct CampaignReport {
    /// The stages run.
    pub run: Vec<String>,
    /// The stages found finished and skipped.
    pub skipped: Vec<String>,
    /// Wall time.
    pub seconds: f64,
}

/// What a stage's hash covers: its kind, its settings as run (scaled, the
/// output directory left out) and the hashes of the stages it uses.
#[derive(Serialize)]
struct Hashed<'a> {
    kind: &'static str,
    world: Option<TrainConfig>,
    search: Option<SearchConfig>,
    fields: Vec<String>,
    seeds: &'a [u64],
    uses: Vec<(&'a str, String)>,
}

/// Runs `campaign`'s stages (or those `options` names), writing each
/// stage's outputs into `options.out`; `progress` gets a line per stage.
pub fn run(
    campaign: &Campaign,
    options: &CampaignOptions,
    progress: &dyn Fn(&str),
) -> Result<CampaignReport> {
    sim::base::ranges::SCALE.check(options.scale)?;
    let started = Instant::now();
    let selected = selection(campaign, &options.stages)?;
    crate::atomic::check_writable(&options.out)?;
    let mut hashes: BTreeMap<&str, String> = BTreeMap::new();
    let mut report = CampaignReport {
        run: Vec::new(),
        skipped: Vec::new(),
        seconds: 0.0,
    };
    for stage in &campaign.stages {
        let stage_hash = stage_hash(stage, options.scale, &hashes)?;
        hashes.insert(&stage.name, stage_hash.clone());
        if !selected.contains(&stage.name.as_str()) {
            continue;
        }
        let done = options.out.join(format!("{}.done", stage.name));
        let finished = std::fs::read_to_string(&done).is_ok_and(|h| h.trim() == stage_hash)
            && outputs(stage, &options.out).iter().all(|p| p.exists());
        if finished {
            progress(&format!("stage {}: finished, skipped", stage.name));
            report.skipped.push(stage.name.clone());
            continue;
        }
        if let Work::Publish(_) = stage.work {
            if options.scale != 1.0 {
                progress(&format!(
                    "stage {}: not published at scale {}",
                    stage.name, options.scale
                ));
                report.skipped.push(stage.name.clone());
                continue;
            }
        }
        progress(&format!("stage {}: running", stage.name));
        let t = Instant::now();
        run_stage(campaign, stage, options, progress)
            .with_context(|| format!("stage {:?}", stage.name))?;
        if !matches!(stage.work, Work::Publish(_)) {
            crate::atomic::write(&done, format!("{stage_hash}\n").as_bytes())?;
        }
        progress(&format!(
            "stage {}: done in {:.0} s",
            stage.name,
            t.elapsed().as_secs_f64()
        ));
        report.run.push(stage.name.clone());
    }
    report.seconds = started.elapsed().as_secs_f64();
    Ok(report)
}

/// The stages to run: those named and the stages they use, or all.
fn selection<'a>(campaign: &'a Campaign, names: &[String]) -> Result<Vec<&'a str>> {
    if names.is_empty() {
        return Ok(campaign.stages.iter().map(|s| s.name.as_str()).collect());
    }
    let mut wanted: Vec<&str> = Vec::new();
    let mut todo: Vec<&str> = Vec::new();
    for n in names {
        match campaign.stage(n) {
            Some(s) => todo.push(&s.name),
            None => {
                let known: Vec<&str> = campaign.stages.iter().map(|s| s.name.as_str()).collect();
                bail!(
                    "--stages: no stage {n:?} in campaign {}: expected some of {}",
                    campaign.name,
                    known.join(", ")
                );
            }
        }
    }
    while let Some(name) = todo.pop() {
        if wanted.contains(&name) {
            continue;
        }
        wanted.push(name);
        if let Some(stage) = campaign.stage(name) {
            todo.extend(uses(stage));
        }
    }
    Ok(wanted)
}

/// The stages a stage uses the outputs of.
fn uses(stage: &Stage) -> Vec<&str> {
    match &stage.work {
        Work::Search { .. } | Work::Train { .. } => stage.from.as_deref().into_iter().collect(),
        Work::Evaluate(e) => e
            .controllers
            .iter()
            .map(String::as_str)
            .filter(|c| *c != "oc" && !is_policy_file(c))
            .collect(),
        Work::Publish(p) => p.evaluations.iter().map(String::as_str).collect(),
    }
}

/// The files a finished stage has written.
fn outputs(stage: &Stage, out: &Path) -> Vec<PathBuf> {
    let file = |suffix: &str| out.join(format!("{}{suffix}", stage.name));
    match stage.work {
        Work::Search { .. } => vec![file(".policy"), file(".search.json")],
        Work::Train { .. } => vec![file(".policy"), file(".ckpt")],
        Work::Evaluate(_) => vec![file(".jsonl")],
        // a publish stage writes no hash, so it always runs
        Work::Publish(_) => Vec::new(),
    }
}

/// `n` steps at `scale`, at least 1.
fn scaled(n: u64, scale: f64) -> u64 {
    ((n as f64 * scale).round() as u64).max(1)
}

/// A world's step counts at `scale`, its output the campaign's.
fn world_at(world: &TrainConfig, scale: f64, out: &Path) -> TrainConfig {
    let mut w = world.clone();
    w.steps = scaled(w.steps, scale);
    w.distil_oc = w.distil_oc.map(|n| scaled(n, scale));
    w.epsilon_decay = w.epsilon_decay.map(|n| scaled(n, scale));
    if let Some(select) = &mut w.select {
        select.every = scaled(select.every, scale);
        select.steps = scaled(select.steps, scale);
    }
    w.output.dir = out.to_path_buf();
    w
}

/// A search's settings at `scale`: its worlds' steps and its generations.
fn search_at(search: &SearchConfig, scale: f64) -> SearchConfig {
    SearchConfig {
        generations: (search.generations as f64 * scale).ceil().max(1.0) as u64,
        fitness_steps: scaled(search.fitness_steps, scale),
        validation_steps: scaled(search.validation_steps, scale),
        ..search.clone()
    }
}

/// The hash of a stage's settings at `scale`, given the hashes of the
/// stages before it.
fn stage_hash(stage: &Stage, scale: f64, hashes: &BTreeMap<&str, String>) -> Result<String> {
    let uses = uses(stage)
        .into_iter()
        .map(|n| {
            let h = hashes.get(n).cloned().unwrap_or_default();
            (n, h)
        })
        .collect();
    let none = Path::new("");
    let hashed = match &stage.work {
        Work::Search { world, search } => Hashed {
            kind: "search",
            world: Some(world_at(world, scale, none)),
            search: Some(search_at(search, scale)),
            fields: Vec::new(),
            seeds: &[],
            uses,
        },
        Work::Train { world } => Hashed {
            kind: "train",
            world: Some(world_at(world, scale, none)),
            search: None,
            fields: Vec::new(),
            seeds: &[],
            uses,
        },
        Work::Evaluate(e) => Hashed {
            kind: "evaluate",
            world: Some(world_at(&e.world, scale, none)),
            search: None,
            fields: e.fields.iter().map(|f| f.to_string()).collect(),
            seeds: &e.seeds,
            uses,
        },
        Work::Publish(_) => Hashed {
            kind: "publish",
            world: None,
            search: None,
            fields: Vec::new(),
            seeds: &[],
            uses,
        },
    };
    Ok(hash(&hashed))
}

/// Runs one stage.
fn run_stage(
    campaign: &Campaign,
    stage: &Stage,
    options: &CampaignOptions,
    progress: &dyn Fn(&str),
) -> Result<()> {
    let out = &options.out;
    let from = stage.from.as_ref().map(|f| out.join(format!("{f}.policy")));
    match &stage.work {
        Work::Search { world, search } => {
            let config = write_world(stage, &world_at(world, options.scale, out), out)?;
            let mut search = search_at(search, options.scale);
            if let Some(from) = from {
                search.start = Start::File(from);
            }
            let request = SearchRequest {
                config: Some(config),
                flags: no_flags()?,
                search,
            };
            let report = crate::search::search(&request, &mut |g| {
                progress(&format!(
                    "stage {}: generation {} of {}, {} formations on the validation worlds",
                    stage.name,
                    g.generation + 1,
                    request.search.generations,
                    g.result_validation.formations
                ));
                Ok(())
            })?;
            progress(&report.to_string());
        }
        Work::Train { world } => {
            let config = write_world(stage, &world_at(world, options.scale, out), out)?;
            // an interrupted run's files are replaced, not kept
            for suffix in [".policy", ".ckpt"] {
                let path = out.join(format!("{}{suffix}", stage.name));
                if path.exists() {
                    std::fs::remove_file(&path)
                        .with_context(|| format!("cannot remove {}", path.display()))?;
                }
            }
            let request = TrainRequest {
                config: Some(config),
                flags: no_flags()?,
                init_from: from,
                ..TrainRequest::default()
            };
            crate::train::train(&request, |report| {
                progress(&report.to_string());
                Ok(())
            })?;
        }
        Work::Evaluate(e) => {
            let lines = evaluate(campaign, e, options)?;
            let path = out.join(format!("{}.jsonl", stage.name));
            crate::atomic::write(&path, lines.concat().as_bytes())?;
        }
        Work::Publish(p) => {
            for line in p.publish(campaign, out)? {
                progress(&format!("stage {}: wrote {}", stage.name, line.display()));
            }
        }
    }
    Ok(())
}

/// No settings flags: a stage's world is its file.
fn no_flags() -> Result<TrainFlags> {
    TrainFlags::parse(Vec::<String>::new())
}

/// Writes the world a stage runs in as `<out>/<stage>.toml`; returns it.
fn write_world(stage: &Stage, world: &TrainConfig, out: &Path) -> Result<PathBuf> {
    let path = out.join(format!("{}.toml", stage.name));
    let text = toml::to_string(world).context("cannot encode the stage's world")?;
    crate::atomic::write(&path, text.as_bytes())?;
    Ok(path)
}

/// The evaluation's JSON lines: per field, each controller that runs
/// there, per seed.
fn evaluate(campaign: &Campaign, e: &Evaluation, options: &CampaignOptions) -> Result<Vec<String>> {
    let world = world_at(&e.world, options.scale, &options.out);
    let mut runs = Vec::new();
    for field in &e.fields {
        let label = field.to_string();
        for c in &e.controllers {
            let controller = if c == "oc" {
                ControllerChoice::Orbital
            } else if is_policy_file(c) {
                ControllerChoice::Policy(PathBuf::from(c))
            } else {
                let stage = campaign
                    .stage(c)
                    .with_context(|| format!("controllers: no stage {c:?}"))?;
                let made_on = stage.fields();
                if made_on.len() == 1 && made_on[0] != label {
                    continue;
                }
                ControllerChoice::Policy(options.out.join(format!("{c}.policy")))
            };
            for &seed in &e.seeds {
                runs.push((field.clone(), controller.clone(), seed));
            }
        }
    }
    runs.par_iter()
        .map(|(field, controller, seed)| {
            // on a screen, the shape's puck count by the puck rule
            let mut config = world.clone();
            config.world.seed = *seed;
            config.world.field = field.clone();
            config.validate()?;
            let mut scenario = config.scenario()?;
            scenario.controller = controller.clone();
            let (mut sim, mut c) = scenario.build()?;
            let summary = crate::run_summary::run_timed(&mut sim, &mut c, world.steps);
            let name = match controller {
                ControllerChoice::Policy(p) => format!("policy:{}", p.display()),
                _ => "oc".to_string(),
            };
            Ok(format!(
                "{{\"field\": {}, \"controller\": {}, \"seed\": {seed}, \"steps\": {}, \"formations\": {}}}\n",
                serde_json::to_string(&field.to_string())?,
                serde_json::to_string(&name)?,
                world.steps,
                summary.formations
            ))
        })
        .collect()
}
