//! A built simulation and its controller from a few choices (field,
//! controller, sensor model, counts, seed), with the per-field defaults of
//! the thesis' experiments.
//!
//! Room 10 of the simulator (`lib.rs`): above the step loop, it chooses and builds what runs.

pub mod arena;
pub mod arena_choice;
pub mod choices;
pub mod flat_field;
pub mod panel;
pub mod puck_rule;
pub mod sensor_choice;
pub mod sensor_setup;
pub mod trained_for;

use crate::config::actuation::ActuationNoise;
use crate::config::validate::ConfigError;
use crate::config::BroadPhase;
use crate::config::{SimConfig, Thresholds, Walls};
use crate::control::greedy::GreedyPolicy;
use crate::control::orbital::{OrbitalConfig, OrbitalConstruction};
use crate::control::policy_file::{self, PolicyFileError};
use crate::control::random::RandomTurns;
use crate::control::Controller;
use crate::fields::source::{FieldError, FieldSource};
use crate::fields::ScalarField;
use crate::scenario::arena::ArenaSpec;
use crate::scenario::sensor_setup::{SelectedSensors, SensorSetup};
use crate::sensors::robot_noise::RobotNoise;
use crate::simulation::Simulation;
use shared::ActionTable;
use std::fmt;
use std::path::PathBuf;
use std::str::FromStr;
use std::sync::Arc;

/// Which controller drives the robots.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum ControllerChoice {
    /// Orbital construction (`oc`).
    Orbital,
    /// Uniformly random actions (`random`).
    Random,
    /// A greedy policy blob (`policy:FILE`).
    Policy(PathBuf),
}

impl FromStr for ControllerChoice {
    type Err = String;

    fn from_str(s: &str) -> Result<ControllerChoice, String> {
        match s {
            "oc" => Ok(ControllerChoice::Orbital),
            "random" => Ok(ControllerChoice::Random),
            _ => match s.strip_prefix("policy:") {
                Some(path) if !path.is_empty() => Ok(ControllerChoice::Policy(PathBuf::from(path))),
                _ => Err(format!(
                    "unknown controller {s:?}: expected oc, random or policy:FILE"
                )),
            },
        }
    }
}

impl fmt::Display for ControllerChoice {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ControllerChoice::Orbital => f.write_str("oc"),
            ControllerChoice::Random => f.write_str("random"),
            ControllerChoice::Policy(p) => write!(f, "policy:{}", p.display()),
        }
    }
}

/// What to simulate.
#[derive(Clone, Debug, PartialEq)]
pub struct Scenario {
    /// The field.
    pub field: FieldSource,
    /// The controller.
    pub controller: ControllerChoice,
    /// Number of robots; `None` for the arena's (8 in the thesis' arena).
    pub robots: Option<usize>,
    /// Number of pucks; `None` for the arena's (250 in the thesis' arena).
    pub pucks: Option<usize>,
    /// Seed of every generator.
    pub seed: u64,
    /// Contact search.
    pub broad_phase: BroadPhase,
    /// The arena.
    pub arena: Arena,
    /// The robots' sensor model.
    pub sensors: SensorSetup,
    /// Noise of the robot sensor model and of the robots' motion: the
    /// default noise ([`RobotNoise::randomised`],
    /// [`ActuationNoise::randomised`]) times this; 0 for none.
    pub noise: f64,
    /// How the border keeps the bodies in; `None` for the arena's own
    /// ([`Walls`]: the thesis' square's default, a screen's bezel).
    pub walls: Option<Walls>,
    /// Steps before an unformed episode counts as stuck; `None` for a
    /// screen arena's own, else the field's ([`field_config`]).
    pub stuck_limit: Option<u64>,
}

impl Default for Scenario {
    /// The thesis' standard run: annulus, orbital construction, 8 robots,
    /// 250 pucks, seed 1.
    fn default() -> Scenario {
        Scenario {
            field: FieldSource::Annulus,
            controller: ControllerChoice::Orbital,
            robots: None,
            pucks: None,
            seed: 1,
            broad_phase: BroadPhase::Grid,
            arena: Arena::default(),
            sensors: SensorSetup::Disc,
            noise: 0.0,
            walls: None,
            stuck_limit: None,
        }
    }
}

/// Robots in the thesis' arena.
pub const THESIS_ROBOTS: usize = 8;
/// Pucks in the thesis' arena.
pub const THESIS_PUCKS: usize = 250;

/// The settings of a field's experiments: the reference defaults with the
/// given counts; the annulus thresholds and 150,000-step stuck limit on the
/// annulus, thresholds 1.0 and a 50,000-step limit on letters and images.
/// Every robot is an outie.
pub fn field_config(field: &FieldSource, robots: usize, pucks: usize) -> SimConfig {
    let mut c = SimConfig::default();
    c.world.robots = robots;
    c.world.pucks = pucks;
    c.thresholds = field_thresholds(field);
    if !field.has_cavity() {
        c.episode.stuck_limit = 50_000;
    }
    c
}

/// The target band of a field's experiments: the annulus thresholds on
/// the annulus, 1.0 on letters and images.
pub fn field_thresholds(field: &FieldSource) -> Thresholds {
    if field.has_cavity() {
        Thresholds::default()
    } else {
        Thresholds::LETTERS
    }
}

/// The number of innies orbital construction uses: half the robots on a
/// field with a cavity (the annulus), none otherwise (thesis Tables 1, 4).
pub fn orbital_innies(field: &FieldSource, robots: usize) -> usize {
    if field.has_cavity() {
        robots / 2
    } else {
        0
    }
}

/// The innies of a swarm of `robots` flashed with ids 0, 1, 2, ...: the
/// robots whose id makes them innies by the firmware's rule
/// ([`shared::Role::of_robot_id`]: odd ids), on every field. A role-aware
/// policy runs with these wherever it runs, as the flashed robots do.
pub fn role_innies(robots: usize) -> usize {
    (0..robots)
        .filter(|&id| {
            u8::try_from(id).is_ok_and(|id| shared::Role::of_robot_id(id) == shared::Role::Innie)
        })
        .count()
}

/// Settings for robots driven by `blob`: its forward speed, and with the
/// role hasher the flashed swarm's innies ([`role_innies`]).
pub fn drive_with(config: &mut SimConfig, blob: &shared::PolicyBlob) {
    config.world.forward_speed = f64::from(blob.actions().forward_speed());
    if blob.hasher().has_role_bit() {
        config.world.innies = role_innies(config.world.robots);
    }
}

/// The arena a scenario runs in.
#[derive(Clone, Debug, PartialEq)]
pub enum Arena {
    /// The reference model's square arena of this side (800 in the thesis),
    /// the field stretched over it and read at the nearest cell.
    Square(f64),
    /// A screen arena (`docs/robot-sensors.md`).
    Screen(Box<ArenaSpec>),
}

impl Default for Arena {
    /// The thesis' 800 x 800 square.
    fn default() -> Arena {
        Arena::Square(800.0)
    }
}

impl Arena {
    /// The field of `source` as this arena shows it.
    pub fn load(&self, source: &FieldSource) -> Result<ScalarField, FieldError> {
        match self {
            Arena::Square(_) => source.load(),
            Arena::Screen(spec) => spec.load_field(source),
        }
    }
}

impl Scenario {
    /// The settings for `field` (loaded by [`Arena::load`]): [`field_config`]
    /// in this scenario's arena, with its counts and contact search, and
    /// [`orbital_innies`] for orbital construction.
    pub fn config(&self, field: &ScalarField) -> SimConfig {
        let mut c = field_config(&self.field, THESIS_ROBOTS, THESIS_PUCKS);
        match &self.arena {
            Arena::Square(size) => {
                c.world.arena_width = *size;
                c.world.arena_height = *size;
            }
            Arena::Screen(spec) => spec.apply(&mut c, field),
        }
        if let Some(robots) = self.robots {
            c.world.robots = robots;
        }
        if let Some(pucks) = self.pucks {
            c.world.pucks = pucks;
        }
        c.world.broad_phase = self.broad_phase;
        if let Some(walls) = self.walls {
            c.physics.walls = walls;
        }
        if let Some(limit) = self.stuck_limit {
            c.episode.stuck_limit = limit;
        }
        // robots on a screen may show only a share of the motion noise
        let motion = match &self.arena {
            Arena::Screen(spec) => self.noise * spec.motion_noise,
            Arena::Square(_) => self.noise,
        };
        if motion > 0.0 {
            c.world.actuation = ActuationNoise::randomised().scaled(motion);
        }
        if self.controller == ControllerChoice::Orbital {
            c.world.innies = orbital_innies(&self.field, c.world.robots);
        }
        c
    }

    /// Loads the field and policy, validates the settings and builds the
    /// simulation and controller. Errors name the offending input.
    pub fn build(
        &self,
    ) -> Result<(Simulation<SelectedSensors>, Box<dyn Controller + Send>), ScenarioError> {
        if let ControllerChoice::Policy(path) = &self.controller {
            return self.build_with_policy(policy_file::read(path)?);
        }
        let prepared = self.prepare()?;
        let controller: Box<dyn Controller + Send> = match &self.controller {
            ControllerChoice::Random => Box::new(RandomTurns::new(ActionTable::default())),
            _ => Box::new(OrbitalConstruction::new(
                OrbitalConfig::default(),
                &prepared.config().thresholds,
            )),
        };
        let sim = prepared.simulation(self.seed)?;
        Ok((sim, controller))
    }

    /// Builds the simulation with `blob` driving the robots (a policy
    /// already decoded, such as one uploaded to the live view), as
    /// [`build`](Self::build) does for `policy:FILE`.
    pub fn build_with_policy(
        &self,
        blob: shared::PolicyBlob,
    ) -> Result<(Simulation<SelectedSensors>, Box<dyn Controller + Send>), ScenarioError> {
        let mut prepared = self.prepare()?;
        drive_with(prepared.config_mut(), &blob);
        let sim = prepared.simulation(self.seed)?;
        Ok((sim, Box::new(GreedyPolicy::new(blob))))
    }

    /// Validates the arena and the sensor settings, loads the field once
    /// and derives the settings ([`config`](Self::config)): what any number
    /// of simulations of this scenario share. For callers that choose the
    /// turns themselves (the Python environments, one world per seed).
    pub fn prepare(&self) -> Result<PreparedScenario, ScenarioError> {
        if let Arena::Screen(spec) = &self.arena {
            spec.validate()?;
        }
        choices::check_world_ranges(self.robots, self.pucks, self.noise)
            .map_err(ConfigError::from)?;
        let sensors = if self.noise > 0.0 {
            self.sensors
                .with_noise(&RobotNoise::randomised().scaled(self.noise))
        } else {
            self.sensors.clone()
        };
        // a flat-field corrected panel shows less of its unevenness
        let sensors = match &self.arena {
            Arena::Screen(spec) => sensors.with_unevenness(spec.brightness_unevenness),
            Arena::Square(_) => sensors,
        };
        sensors.validate()?;
        let field = Arc::new(self.arena.load(&self.field)?);
        let config = self.config(&field);
        config.validate()?;
        Ok(PreparedScenario {
            config,
            field,
            sensors,
        })
    }
}

/// A scenario's settings, loaded field and sensor settings, from
/// [`Scenario::prepare`]: builds fresh simulations without loading the
/// field again.
#[derive(Clone, Debug)]
pub struct PreparedScenario {
    config: SimConfig,
    field: Arc<ScalarField>,
    sensors: SensorSetup,
}

impl PreparedScenario {
    /// The settings every simulation gets.
    pub fn config(&self) -> &SimConfig {
        &self.config
    }

    /// The loaded field.
    pub fn field(&self) -> &Arc<ScalarField> {
        &self.field
    }

    /// The sensor settings, the scenario's noise applied.
    pub fn sensors(&self) -> &SensorSetup {
        &self.sensors
    }

    /// The settings, to adjust (thresholds, stuck limit, forward speed)
    /// before building simulations; [`simulation`](Self::simulation)
    /// validates them.
    pub fn config_mut(&mut self) -> &mut SimConfig {
        &mut self.config
    }

    /// A fresh simulation whose world is seeded with `seed`, exactly as
    /// [`Scenario::build`] builds it for that seed.
    pub fn simulation(&self, seed: u64) -> Result<Simulation<SelectedSensors>, ScenarioError> {
        self.config.validate()?;
        let sensors = self.sensors.build(&self.config);
        Ok(Simulation::with_sensors(
            self.config.clone(),
            self.field.clone(),
            sensors,
            seed,
        )?)
    }
}

/// Why a [`Scenario`] cannot be built.
#[derive(Debug)]
pub enum ScenarioError {
    /// A setting is out of range.
    Config(ConfigError),
    /// The field cannot be loaded.
    Field(FieldError),
    /// The policy file cannot be used.
    Policy(PolicyFileError),
    /// A settings file (a screen arena, a robot sensor config) cannot be
    /// read or is not valid.
    SettingsFile {
        /// What the file holds.
        what: &'static str,
        /// The file.
        path: PathBuf,
        /// What is wrong with it.
        problem: String,
    },
    /// No built-in screen arena has this name.
    UnknownArena(String),
    /// A screen arena is needed where this arena (the thesis' square) was given.
    NotAScreen(String),
    /// The field has no puck count by the puck rule
    /// ([`puck_rule`](crate::scenario::puck_rule)): too few pucks placed on
    /// the shape reach success.
    TooFewPucks {
        /// The field.
        field: FieldSource,
        /// The most pucks on the shape that reach success (0 for none).
        most: usize,
    },
}

/// The fewest pucks a shape may take by the puck rule
/// ([`puck_rule`](crate::scenario::puck_rule)): a shape on which fewer
/// reach success is refused.
pub const LEAST_PUCKS: usize = 6;

impl fmt::Display for ScenarioError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ScenarioError::Config(e) => write!(f, "invalid simulation settings: {e}"),
            ScenarioError::Field(e) => e.fmt(f),
            ScenarioError::Policy(e) => e.fmt(f),
            ScenarioError::SettingsFile {
                what,
                path,
                problem,
            } => write!(f, "{what} {} {problem}", path.display()),
            ScenarioError::UnknownArena(name) => write!(
                f,
                "unknown arena {name:?}: expected thesis, {} or a FILE.toml",
                ArenaSpec::NAMES
            ),
            ScenarioError::NotAScreen(arena) => write!(
                f,
                "--arena {arena}: a screen arena is needed ({} or a FILE.toml), not the thesis' square",
                ArenaSpec::NAMES
            ),
            ScenarioError::TooFewPucks { field, most } => write!(
                f,
                "field {field}: {most} pucks placed on the shape reach the success Eval, \
                 fewer than the {LEAST_PUCKS} a shape needs (give the count with --pucks)"
            ),
        }
    }
}

impl std::error::Error for ScenarioError {}

impl From<ConfigError> for ScenarioError {
    fn from(e: ConfigError) -> ScenarioError {
        ScenarioError::Config(e)
    }
}

impl From<FieldError> for ScenarioError {
    fn from(e: FieldError) -> ScenarioError {
        ScenarioError::Field(e)
    }
}

impl From<PolicyFileError> for ScenarioError {
    fn from(e: PolicyFileError) -> ScenarioError {
        ScenarioError::Policy(e)
    }
}
