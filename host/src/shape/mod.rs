//! `host shape IMAGE`: from a picture to a flashable policy and its report
//! card, one pipeline of separate steps over the policy search
//! ([`crate::search`]), for the robot on the TV by default:
//!
//! 1. the image ([`image::check`]): inverted with `--invert`, refused
//!    when it looks drawn dark on light or when fewer than six pucks on it
//!    reach success; the puck count by the puck rule;
//! 2. the budget: `--budget-minutes` turned once into the search's
//!    generations from a step rate measured on this machine for this shape
//!    (a short timed run of the general table), recorded in the state file
//!    ([`state`]); `--generations` gives the count instead;
//! 3. the start: the best on the shape of the shipped general table
//!    ([`GENERAL_TABLE`], built in) and orbital construction distilled
//!    into a table of its hasher and into one of the role hasher (the
//!    robots of odd id innies, as flashed, on every shape), scored on
//!    start worlds of their own; the search keeps the start's hasher;
//! 4. the search ([`search_settings`]: the general table's recipe) at the
//!    run's noise, every candidate also scored at twice it, a challenger
//!    kept only if it forms more on validation worlds never scored on, so
//!    the result never forms less than its start there;
//! 5. the report card ([`card`]) on report worlds disjoint from every
//!    search world.
//!
//! Seeds: the search's fitness worlds' are even and its validation
//! worlds' odd ([`crate::search::fitness`]); the start worlds are the
//! fitness seeds of a generation no search reaches ([`START_GENERATION`]);
//! the report worlds' are odd, from a stream of their own, any validation
//! seed among them skipped.
//!
//! Files in `DIR` (all written atomically): `NAME.shape.json` (the state),
//! `NAME.policy`, `NAME.search.json`, `NAME.report.json`,
//! `NAME.report.md`, `NAME.png`, and with `--invert` `NAME.field.png`
//! (the inverted image, the field the run uses).

pub mod card;
pub mod image;
pub mod state;

use crate::search::command::{run_from, scorer_of, write_result, Progress};
use crate::search::fitness::{fitness_seeds, validation_seeds, Scorer};
use crate::search::{SearchConfig, Start};
use crate::train::distil::distil_orbital;
use crate::train::TrainConfig;
use anyhow::{bail, Context, Result};
use card::{evaluate, write_picture, Card, Contender};
use shared::{PolicyBlob, PolicyTable, StateHasher};
use state::{Budget, RunKey, ShapeState, StartChoice};
use std::path::PathBuf;
use std::time::Instant;

/// The shipped general table (`policies/robot-general.policy`), built in
/// so that `host shape` runs from any directory.
pub const GENERAL_TABLE: &[u8] = include_bytes!("../../../policies/robot-general.policy");

/// Where the general table ships, as the search log names the start.
pub const GENERAL_TABLE_PATH: &str = "policies/robot-general.policy";

/// Report worlds.
pub const REPORT_SEEDS: usize = 4;

/// Steps per report world (times `--scale`).
pub const REPORT_STEPS: u64 = 250_000;

/// Steps of orbital construction distilled for its start (times
/// `--scale`).
pub const DISTIL_STEPS: u64 = 500_000;

/// Start worlds.
pub const START_SEEDS: usize = 2;

/// The generation whose fitness seeds are the start worlds' (no search
/// has this many generations).
pub const START_GENERATION: u64 = u64::MAX;

/// The generation whose fitness seeds are the timed run's.
const MEASURE_GENERATION: u64 = u64::MAX - 1;

/// Steps per world of the timed run.
const MEASURE_STEPS: u64 = 20_000;

/// Mixed into the seed for the report worlds' seeds.
const REPORT_STREAM: u64 = 0x5EA9_0000_0000_0001;

/// Fewest steps a scaled count falls to.
const LEAST_STEPS: u64 = 100;

/// What `host shape` is asked to do.
#[derive(Clone, Debug)]
pub struct ShapeRequest {
    /// The world: the image as its field, the flags applied (sensors,
    /// arena, noise, seed, pucks, output directory and name).
    pub world: TrainConfig,
    /// Invert the image first.
    pub invert: bool,
    /// The budget, minutes.
    pub budget_minutes: f64,
    /// The search's generations instead of the budget's.
    pub generations: Option<u64>,
    /// The fraction of every step count (search, distillation, report).
    pub scale: f64,
}

/// What `host shape` did.
#[derive(Clone, Debug)]
pub struct ShapeReport {
    /// The report card.
    pub card: Card,
    /// Generations run earlier and resumed from.
    pub resumed: usize,
    /// The files written.
    pub files: Vec<PathBuf>,
}

impl std::fmt::Display for ShapeReport {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let c = &self.card;
        if self.resumed > 0 {
            writeln!(f, "resumed after {} generations", self.resumed)?;
        }
        writeln!(
            f,
            "{}: {} pucks, hasher {}, start {}, {} generations",
            c.field, c.pucks, c.hasher, c.start, c.generations
        )?;
        writeln!(
            f,
            "formations per million steps ({} worlds of {} steps): default noise, 2x",
            c.seeds.len(),
            c.steps
        )?;
        for (label, l) in [("result", c.result), ("oc", c.oc), ("general", c.general)] {
            writeln!(f, "  {label:<8} {:>8.1} {:>8.1}", l.default, l.twice)?;
        }
        for file in &self.files {
            writeln!(f, "wrote {}", file.display())?;
        }
        Ok(())
    }
}

/// `steps` times `scale`, at least [`LEAST_STEPS`].
fn scaled(steps: u64, scale: f64) -> u64 {
    ((steps as f64 * scale).round() as u64).max(LEAST_STEPS)
}

/// The search's settings: the general table's recipe
/// (`policies/README.md`), its step counts times `scale`, every
/// candidate also scored at twice the noise; one generation until the
/// budget gives the count.
pub fn search_settings(scale: f64) -> SearchConfig {
    SearchConfig {
        start: Start::File(PathBuf::from(GENERAL_TABLE_PATH)),
        generations: 1,
        population: 8,
        elites: 2,
        fitness_seeds: 2,
        fitness_steps: scaled(50_000, scale),
        validation_seeds: 4,
        validation_steps: scaled(50_000, scale),
        keep: 0.9,
        rate: 0.5,
        floor: 0.01,
        threads: 0,
        also_field: Vec::new(),
        also_noise: vec![2.0],
        hold_share: 0.0,
    }
}

/// The budget in generations: the minutes' worth of steps at the rate of
/// a short timed run of `table` on the shape's worlds, less what the
/// distillation, the start, its validation and the report card take, over
/// a generation's steps; at least one.
fn budget(
    request: &ShapeRequest,
    scorer: &Scorer,
    table: &PolicyTable,
    settings: &SearchConfig,
    seed: u64,
) -> Result<Budget> {
    if let Some(generations) = request.generations {
        return Ok(Budget {
            steps_per_second: None,
            generations,
        });
    }
    let worlds = scorer.fields() as u64;
    let threads = scorer.threads() as u64;
    let seeds = fitness_seeds(seed, MEASURE_GENERATION, (threads / worlds).max(1) as usize);
    let started = Instant::now();
    scorer.score(std::slice::from_ref(table), &seeds, MEASURE_STEPS)?;
    let rate = (MEASURE_STEPS * worlds * seeds.len() as u64) as f64
        / started.elapsed().as_secs_f64().max(1e-6);
    let generation =
        (settings.population * settings.fitness_seeds) as u64 * settings.fitness_steps * worlds
            + settings.validation_seeds as u64 * settings.validation_steps * worlds;
    // the two distillations run one world at a time
    let fixed = 2 * scaled(DISTIL_STEPS, request.scale) * threads
        + STARTS.len() as u64 * START_SEEDS as u64 * settings.fitness_steps * worlds
        + settings.validation_seeds as u64 * settings.validation_steps * worlds
        + 3 * 2 * REPORT_SEEDS as u64 * scaled(REPORT_STEPS, request.scale);
    let steps = request.budget_minutes * 60.0 * rate - fixed as f64;
    let most = sim::base::ranges::GENERATIONS.max as u64;
    Ok(Budget {
        steps_per_second: Some(rate.round()),
        generations: ((steps / generation as f64).floor().max(1.0) as u64).min(most),
    })
}

/// The starts a run may take, in the order a tie keeps: the general
/// table, OC distilled into its hasher, OC distilled into the role hasher.
const STARTS: [&str; 3] = ["general", "oc", "oc-role"];

/// The best on the shape's start worlds of [`STARTS`] (the earlier on a
/// tie).
fn choose_start(
    config: &TrainConfig,
    scorer: &Scorer,
    general: &PolicyTable,
    settings: &SearchConfig,
    scale: f64,
) -> Result<StartChoice> {
    let seeds = fitness_seeds(config.world.seed, START_GENERATION, START_SEEDS);
    let distilled = scaled(DISTIL_STEPS, scale);
    let mut role = config.clone();
    role.learn.hasher.0 = StateHasher::OriginalRole;
    let tables = [
        general.clone(),
        distil_orbital(config, distilled)?,
        distil_orbital(&role, distilled)?,
    ];
    let mut scores = scorer.score(&tables, &seeds, settings.fitness_steps)?;
    let best = (1..tables.len()).fold(0, |best, i| {
        if scores[i].beats(&scores[best]) {
            i
        } else {
            best
        }
    });
    let (oc_role, oc, general) = (scores.remove(2), scores.remove(1), scores.remove(0));
    Ok(StartChoice {
        chosen: STARTS[best].to_string(),
        general,
        oc,
        oc_role,
        seeds,
        hasher: tables[best].hasher().name().to_string(),
        table: tables[best].packed().to_vec(),
    })
}

/// Runs `host shape`, resuming from the state file if there is one.
pub fn shape(request: &ShapeRequest) -> Result<ShapeReport> {
    let dir = request.world.output.dir.clone();
    crate::atomic::create_dirs(&dir)?;
    crate::atomic::check_writable(&dir)?;
    let name = request.world.name();
    let at = |suffix: &str| dir.join(format!("{name}.{suffix}"));
    // 1. the image
    let checked = image::check(&request.world, request.invert, &at("field.png"))?;
    let general = PolicyBlob::decode(GENERAL_TABLE).context("the built-in general table")?;
    let mut world = request.world.clone();
    world.world.field = checked.field;
    world.world.pucks = Some(checked.pucks);
    world.learn.hasher.0 = general.hasher();
    let mut settings = search_settings(request.scale);
    let (mut config, scorer) = scorer_of(world, &settings)?;
    if *general.actions() != scorer.actions() {
        bail!("the general table's actions are not this world's: it is for the robot's actions");
    }
    // 2. the budget
    let key = RunKey {
        image: request.world.world.field.to_string(),
        invert: request.invert,
        world: config.clone(),
        scale: request.scale,
        budget_minutes: request.budget_minutes,
        generations: request.generations,
    };
    let state_file = at("shape.json");
    let mut state = match ShapeState::resume(&state_file, &key)? {
        Some(state) => state,
        None => ShapeState {
            format: state::FORMAT,
            budget: budget(
                request,
                &scorer,
                general.table(),
                &settings,
                config.world.seed,
            )?,
            run: key,
            start: None,
            generations: Vec::new(),
        },
    };
    settings.generations = state.budget.generations;
    // 3. the start
    let start = match &state.start {
        Some(start) => start.clone(),
        None => {
            let start = choose_start(&config, &scorer, general.table(), &settings, request.scale)?;
            state.start = Some(start.clone());
            state.write(&state_file)?;
            start
        }
    };
    let distilled = if start.chosen == "general" {
        0
    } else {
        settings.start = Start::Orbital;
        scaled(DISTIL_STEPS, request.scale)
    };
    let in_state = || format!("state file {}: the start table", state_file.display());
    config.learn.hasher.0 = StateHasher::from_name(&start.hasher)
        .with_context(|| format!("{}: no hasher {:?}", in_state(), start.hasher))?;
    let table =
        PolicyTable::from_packed(config.learn.hasher.0, &start.table).with_context(in_state)?;
    // 4. the search
    let done = state.generations.clone();
    let mut progress = Progress::new(settings.generations, done.len() as u64);
    let log = run_from(
        &config,
        &settings,
        &scorer,
        table,
        distilled,
        &done,
        &mut |g| {
            state.generations.push(g.clone());
            state.write(&state_file)?;
            progress.generation(g);
            Ok(())
        },
    )?;
    progress.done();
    let (policy, log_file) = write_result(&config, &scorer, &log)?;
    // 5. the report card
    let result = sim::control::policy_file::read(&policy)?;
    let validation = validation_seeds(config.world.seed, settings.validation_seeds);
    let seeds: Vec<u64> = validation_seeds(config.world.seed ^ REPORT_STREAM, 2 * REPORT_SEEDS)
        .into_iter()
        .filter(|s| !validation.contains(s))
        .take(REPORT_SEEDS)
        .collect();
    let steps = scaled(REPORT_STEPS, request.scale);
    let contenders = [
        ("result", Contender::Table(Box::new(result.clone()))),
        ("oc", Contender::Orbital),
        ("general", Contender::Table(Box::new(general))),
    ];
    let (levels, worlds) = evaluate(&config, &contenders, &seeds, steps)?;
    let card = Card {
        field: config.world.field.to_string(),
        pucks: checked.pucks,
        hasher: config.learn.hasher.0.name().to_string(),
        seeds: seeds.clone(),
        steps,
        minutes: request.budget_minutes,
        start: start.chosen,
        generations: settings.generations,
        result: levels[0],
        oc: levels[1],
        general: levels[2],
        worlds,
    };
    card.write(&dir, &name)?;
    let picture = at("png");
    write_picture(&config, &result, seeds[0], steps, &picture)?;
    let mut files = vec![
        policy,
        log_file,
        at("report.json"),
        at("report.md"),
        picture,
    ];
    if request.invert {
        files.push(at("field.png"));
    }
    Ok(ShapeReport {
        card,
        resumed: done.len(),
        files,
    })
}
