//! One trial: an arm's controller on its configuration for its steps, with
//! what the reports need recorded on the way.

use super::plan::{TrialPlan, RESULT_FORMAT};
use super::spec::ArmController;
use crate::learn::QTable;
use crate::train::{TrainConfig, Trainer};
use anyhow::{Context, Result};
use serde::{Deserialize, Serialize};
use shared::ActionTable;
use sim::control::greedy::GreedyPolicy;
use sim::control::orbital::{OrbitalConfig, OrbitalConstruction};
use sim::control::random::RandomTurns;
use sim::scenario::sensor_setup::SelectedSensors;
use sim::{episodes::EpisodeEnd, simulation::Simulation, simulation::Totals};
use std::path::{Path, PathBuf};
use std::time::Instant;

/// Steps per collision block (the thesis' chapter 6 metric).
pub const BLOCK_STEPS: u64 = 1000;

/// Everything recorded about one finished trial (one JSON file).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TrialResult {
    /// [`RESULT_FORMAT`].
    pub format: u32,
    /// Hash of everything that determines the trial (see `plan`).
    pub config_hash: String,
    /// The experiment's name.
    pub experiment: String,
    /// The arm's name.
    pub arm: String,
    /// Trial index, from 0.
    pub trial: usize,
    /// The trial's seed.
    pub seed: u64,
    /// Steps run.
    pub steps: u64,
    /// Episodes that formed the shape.
    pub formations: u64,
    /// Episodes reset at the stuck limit.
    pub stuck: u64,
    /// The step (from 1) at which each formation happened.
    pub formation_steps: Vec<u64>,
    /// Robot-robot contacts per 1000 steps over the whole trial.
    pub collisions_per_1000: f64,
    /// Robot-robot contacts in each full block of [`BLOCK_STEPS`] steps.
    pub collisions_per_block: Vec<u64>,
    /// States of the Q-table with at least one update at the end
    /// (learning arms; pre-training included).
    pub states_visited: Option<usize>,
    /// States of the hasher (learning arms).
    pub states_total: Option<usize>,
    /// Speed of the trial's run (pre-training excluded).
    pub steps_per_second: f64,
    /// Wall time of the trial's run.
    pub seconds: f64,
}

impl TrialResult {
    /// The result stored at `path`, if the file is a trial result of the
    /// current format.
    pub fn read_current(path: &Path) -> Option<TrialResult> {
        let bytes = std::fs::read(path).ok()?;
        let result: TrialResult = serde_json::from_slice(&bytes).ok()?;
        (result.format == RESULT_FORMAT).then_some(result)
    }
}

/// The arm directories under `dir/trials/` with their `.json` files, both
/// sorted; none if there is no such directory.
pub fn stored_files(dir: &Path) -> Result<Vec<(PathBuf, Vec<PathBuf>)>> {
    let Ok(entries) = std::fs::read_dir(dir.join("trials")) else {
        return Ok(Vec::new());
    };
    let mut arm_dirs: Vec<_> = entries
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.is_dir())
        .collect();
    arm_dirs.sort();
    arm_dirs
        .into_iter()
        .map(|arm_dir| {
            let mut files: Vec<_> = std::fs::read_dir(&arm_dir)
                .with_context(|| format!("cannot list {}", arm_dir.display()))?
                .filter_map(|e| e.ok().map(|e| e.path()))
                .filter(|p| p.extension().is_some_and(|e| e == "json"))
                .collect();
            files.sort();
            Ok((arm_dir, files))
        })
        .collect()
}

/// Follows a run step by step: formation times and collision blocks.
#[derive(Clone, Debug, Default)]
struct Recorder {
    formation_steps: Vec<u64>,
    collisions_per_block: Vec<u64>,
    contacts_at_block_start: u64,
}

impl Recorder {
    fn after_step(&mut self, end: Option<EpisodeEnd>, totals: &Totals) {
        if end == Some(EpisodeEnd::Formed) {
            self.formation_steps.push(totals.steps);
        }
        if totals.steps % BLOCK_STEPS == 0 {
            self.collisions_per_block
                .push(totals.robot_contacts - self.contacts_at_block_start);
            self.contacts_at_block_start = totals.robot_contacts;
        }
    }
}

/// A trial's run, stepped by its caller: orbital construction on its own
/// simulation, or a learner's training run.
#[allow(
    clippy::large_enum_variant,
    reason = "one per trial: the policy variant's table inline costs nothing"
)]
pub enum Running {
    /// Orbital construction.
    Oc(Box<Simulation<SelectedSensors>>, OrbitalConstruction),
    /// Q-learning.
    Learn(Box<Trainer<SelectedSensors>>),
    /// A policy's greedy actions.
    Policy(Box<Simulation<SelectedSensors>>, GreedyPolicy),
    /// Uniformly random turns.
    Random(Box<Simulation<SelectedSensors>>, RandomTurns),
}

impl Running {
    /// The run of `plan` at its start; `seed_table` is the pre-trained table
    /// of a pre-trained arm.
    pub fn start(plan: &TrialPlan, seed_table: Option<QTable>) -> Result<Running> {
        let c = &plan.config;
        Ok(match plan.controller {
            ArmController::Oc => {
                let mut prepared = c.prepare()?;
                let config = prepared.config_mut();
                config.world.innies = c.oc_innies(config.world.robots);
                let oc = OrbitalConstruction::new(OrbitalConfig::default(), &config.thresholds);
                let sim = prepared
                    .simulation(c.world.seed)
                    .context("invalid settings")?;
                Running::Oc(Box::new(sim), oc)
            }
            ArmController::Learn => {
                Running::Learn(Box::new(Trainer::start(c.clone(), seed_table)?))
            }
            ArmController::Policy => {
                let path = plan
                    .policy
                    .as_deref()
                    .context("a policy arm without its policy file")?;
                let blob = sim::control::policy_file::read(path)?;
                let mut prepared = c.prepare()?;
                sim::scenario::drive_with(prepared.config_mut(), &blob);
                let sim = prepared
                    .simulation(c.world.seed)
                    .context("invalid settings")?;
                Running::Policy(Box::new(sim), GreedyPolicy::new(blob))
            }
            ArmController::Random => {
                let prepared = c.prepare()?;
                let forward_speed = prepared.config().world.forward_speed as f32;
                let actions =
                    ActionTable::new(&c.learn.actions, forward_speed).context("invalid actions")?;
                let sim = prepared
                    .simulation(c.world.seed)
                    .context("invalid settings")?;
                Running::Random(Box::new(sim), RandomTurns::new(actions))
            }
        })
    }

    /// One step; how the episode ended, if it did.
    pub fn step(&mut self) -> Option<EpisodeEnd> {
        match self {
            Running::Oc(sim, oc) => sim.step(oc),
            Running::Learn(trainer) => trainer.step(),
            Running::Policy(sim, policy) => sim.step(policy),
            Running::Random(sim, random) => sim.step(random),
        }
    }

    /// The simulation.
    pub fn simulation(&self) -> &Simulation<SelectedSensors> {
        match self {
            Running::Oc(sim, _) | Running::Policy(sim, _) | Running::Random(sim, _) => sim,
            Running::Learn(trainer) => trainer.simulation(),
        }
    }

    /// The learner's states visited and states in all, for a learning run.
    fn states(&self) -> Option<(usize, usize)> {
        match self {
            Running::Oc(..) | Running::Policy(..) | Running::Random(..) => None,
            Running::Learn(trainer) => {
                let q = trainer.learner().table();
                Some((q.states_visited(), q.hasher().num_states()))
            }
        }
    }
}

/// Steps between the frames a watched trial shows (`host experiment --view`).
pub const WATCH_STEPS: u64 = 20_000;

/// Runs a trial; `seed_table` is the pre-trained table of a pre-trained arm.
pub fn run(plan: &TrialPlan, seed_table: Option<QTable>) -> Result<TrialResult> {
    run_watched(plan, seed_table, &mut |_, _| Ok(()))
}

/// [`run`], `watch` shown the run and its steps so far at its start and
/// every [`WATCH_STEPS`] steps (it only looks: the trial is the same).
pub fn run_watched(
    plan: &TrialPlan,
    seed_table: Option<QTable>,
    watch: &mut dyn FnMut(&Running, u64) -> Result<()>,
) -> Result<TrialResult> {
    let mut running = Running::start(plan, seed_table)?;
    let mut recorder = Recorder::default();
    let start = Instant::now();
    watch(&running, 0)?;
    for step in 1..=plan.config.steps {
        let end = running.step();
        recorder.after_step(end, running.simulation().totals());
        if step % WATCH_STEPS == 0 {
            watch(&running, step)?;
        }
    }
    let (totals, states) = (running.simulation().totals().clone(), running.states());
    let c = &plan.config;
    let seconds = start.elapsed().as_secs_f64();
    Ok(TrialResult {
        format: RESULT_FORMAT,
        config_hash: plan.hash.clone(),
        experiment: plan.experiment.clone(),
        arm: plan.arm.clone(),
        trial: plan.trial,
        seed: c.world.seed,
        steps: totals.steps,
        formations: totals.formations,
        stuck: totals.stuck,
        formation_steps: recorder.formation_steps,
        collisions_per_1000: totals.collisions_per_1000(),
        collisions_per_block: recorder.collisions_per_block,
        states_visited: states.map(|s| s.0),
        states_total: states.map(|s| s.1),
        steps_per_second: if seconds > 0.0 {
            totals.steps as f64 / seconds
        } else {
            f64::INFINITY
        },
        seconds,
    })
}

/// Pre-trains a Q-table: a plain training run of `config`.
pub fn pretrain(
    config: &TrainConfig,
) -> Result<Trainer<sim::scenario::sensor_setup::SelectedSensors>> {
    let mut trainer = Trainer::start(config.clone(), None)?;
    trainer.run(config.steps);
    Ok(trainer)
}
