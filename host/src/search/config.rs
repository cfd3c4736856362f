//! The search's own settings (`host search`); the world it searches in is
//! a training config's ([`crate::train::TrainConfig`]: field, sensors,
//! arena, counts, noise, hasher, seed, output), by default the robot's on
//! the TV ([`default_world`]).

use crate::train::TrainConfig;
use anyhow::{bail, Result};
use serde::{Deserialize, Serialize};
use sim::fields::source::FieldSource;
use sim::scenario::arena_choice::ArenaChoice;
use sim::scenario::choices::WorldChoices;
use sim::scenario::sensor_choice::SensorChoice;
use std::path::PathBuf;

/// The world a search runs in unless a `--config` file says otherwise: the
/// robot's senses (`robot`) on the 75" TV (`tv75`) at the default noise
/// (1); every other setting a training config's default.
pub fn default_world() -> TrainConfig {
    TrainConfig {
        world: WorldChoices {
            sensors: SensorChoice::Robot(None),
            arena: Some(ArenaChoice::Named("tv75".into())),
            noise: 1.0,
            ..WorldChoices::default()
        },
        ..TrainConfig::default()
    }
}

/// Where the search starts.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(try_from = "String", into = "String")]
pub enum Start {
    /// Orbital construction distilled into a table on a world of the run's
    /// settings (`oc`; the run's `--distil-oc` steps, else
    /// [`DEFAULT_DISTIL_STEPS`]).
    Orbital,
    /// A table of uniformly random actions drawn from the run's seed
    /// (`random`).
    Random,
    /// A policy blob's table or a checkpoint's greedy table (a path).
    File(PathBuf),
}

/// Steps of orbital construction distilled for `--start oc` without
/// `--distil-oc`.
pub const DEFAULT_DISTIL_STEPS: u64 = 2_000_000;

impl std::str::FromStr for Start {
    type Err = String;

    fn from_str(s: &str) -> Result<Start, String> {
        match s {
            "oc" => Ok(Start::Orbital),
            "random" => Ok(Start::Random),
            "" => Err("empty start: expected oc, random or a policy or checkpoint file".into()),
            path => Ok(Start::File(PathBuf::from(path))),
        }
    }
}

impl std::fmt::Display for Start {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Start::Orbital => f.write_str("oc"),
            Start::Random => f.write_str("random"),
            Start::File(p) => write!(f, "{}", p.display()),
        }
    }
}

sim::text_form!(Start);

/// The cross-entropy search's settings.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, clap::Args)]
pub struct SearchConfig {
    /// The table the search starts from: oc (orbital construction
    /// distilled), random, or a policy blob or checkpoint file.
    #[arg(long, default_value = "oc")]
    pub start: Start,
    /// Generations.
    #[arg(long, default_value_t = 20)]
    pub generations: u64,
    /// Candidates per generation, the best table so far among them.
    #[arg(long, default_value_t = 16)]
    pub population: usize,
    /// Candidates whose actions the distribution moves towards.
    #[arg(long, default_value_t = 4)]
    pub elites: usize,
    /// Worlds (seeds) each candidate is scored on per generation, the same
    /// for every candidate of a generation.
    #[arg(long, default_value_t = 2)]
    pub fitness_seeds: usize,
    /// Steps per fitness world.
    #[arg(long, default_value_t = 50_000)]
    pub fitness_steps: u64,
    /// Validation worlds, disjoint from every fitness world: a generation's
    /// best candidate replaces the result only if it forms more there.
    #[arg(long, default_value_t = 4)]
    pub validation_seeds: usize,
    /// Steps per validation world.
    #[arg(long, default_value_t = 50_000)]
    pub validation_steps: u64,
    /// Probability of the start table's action in every state at the start.
    #[arg(long, default_value_t = 0.9)]
    pub keep: f64,
    /// Fraction by which each generation moves the distribution towards
    /// the elites' actions.
    #[arg(long, default_value_t = 0.5)]
    pub rate: f64,
    /// Least probability of any action in any state.
    #[arg(long, default_value_t = 0.01)]
    pub floor: f64,
    /// Threads scoring candidates (0: one per core); the result is the same
    /// for any number.
    #[arg(long, default_value_t = 0)]
    pub threads: usize,
    /// Another field every candidate is also scored on (repeatable), with
    /// its shape's puck count on a screen unless --pucks is given: one
    /// general table for several shapes, ranked by the sum over the fields
    /// of ln(1 + formations).
    #[arg(long = "also-field", value_name = "FIELD")]
    #[serde(default)]
    pub also_field: Vec<FieldSource>,
    /// Another noise level (multiples of the default, repeatable) every
    /// field is also scored at, ranked like --also-field: a table that
    /// keeps its count when the world is noisier than the run's --noise.
    #[arg(long = "also-noise", value_name = "MULTIPLE")]
    #[serde(default)]
    pub also_noise: Vec<f64>,
    /// A challenger becomes the result only if it also forms at least this
    /// share of the start table's count on the validation worlds of every
    /// field and noise level (0: no such bar): a general table that gains
    /// on some shapes without giving up others.
    #[arg(long, value_name = "SHARE", default_value_t = 0.0)]
    #[serde(default)]
    pub hold_share: f64,
}

impl SearchConfig {
    /// Checks the settings; errors name the setting.
    pub fn validate(&self, actions: usize) -> Result<()> {
        use sim::base::ranges;
        let counts = [
            (&ranges::GENERATIONS, "--generations", self.generations),
            (&ranges::CANDIDATES, "--population", self.population as u64),
            (&ranges::CANDIDATES, "--elites", self.elites as u64),
            (
                &ranges::SEARCH_WORLDS,
                "--fitness-seeds",
                self.fitness_seeds as u64,
            ),
            (&ranges::STEPS, "--fitness-steps", self.fitness_steps),
            (
                &ranges::SEARCH_WORLDS,
                "--validation-seeds",
                self.validation_seeds as u64,
            ),
            (&ranges::STEPS, "--validation-steps", self.validation_steps),
        ];
        for (range, flag, value) in counts {
            range.check_count(flag, value)?;
        }
        // 0: one per core
        if self.threads != 0 {
            ranges::THREADS.check_count("--threads", self.threads as u64)?;
        }
        for (flag, value) in [
            ("--keep", self.keep),
            ("--rate", self.rate),
            ("--floor", self.floor),
            ("--hold-share", self.hold_share),
        ] {
            ranges::SEARCH_PROBABILITY.check_as(flag, value)?;
        }
        if self.population < 2 {
            bail!(
                "--population = {}: must be at least 2 (the best table so far and a new one)",
                self.population
            );
        }
        if self.elites > self.population {
            bail!(
                "--elites = {}: cannot exceed --population = {}",
                self.elites,
                self.population
            );
        }
        let most = 1.0 / actions as f64;
        if !(0.0..=most).contains(&self.floor) {
            bail!(
                "--floor = {}: must be in [0, {most}] with {actions} actions",
                self.floor
            );
        }
        Ok(())
    }
}
