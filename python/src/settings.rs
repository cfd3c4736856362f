//! The environments' keyword arguments, checked: each bad one gets an
//! error that names the argument, its value and the problem, before any
//! world is built.
//!
//! The names mirror `host run`'s flags (`field`, `robots`, `pucks`,
//! `sensors`, `seed`) plus what an environment adds (`max_steps`,
//! `thresholds`, `reward`, the observation and action kinds).

use shared::{ActionTable, StateHasher};
use sim::base::ranges::{Range, RangeError, PUCKS, ROBOTS, STEPS};
use sim::config::validate::ConfigError;
use sim::config::{SimConfig, Thresholds};
use sim::episodes::reward::Reward;
use sim::fields::source::FieldSource;
use sim::scenario::arena::ArenaSpec;
use sim::scenario::arena_choice::ArenaChoice;
use sim::scenario::choices::{ScenarioChoices, WorldChoices};
use sim::scenario::sensor_choice::SensorChoice;
use sim::scenario::sensor_setup::SensorSetup;
use sim::scenario::trained_for;
use sim::scenario::{Arena, ControllerChoice, PreparedScenario, ScenarioError};
use sim::sensors::robot::RobotSensorConfig;
use std::fmt;

/// What a seed must be: the environments take 64-bit signed integers, as
/// NumPy's seeds are, so the largest is `i64::MAX`.
pub const SEED_RANGE: &str = "must be a whole number from 0 to 2**63 - 1";

/// A keyword argument that cannot be used: `name = value: problem`.
#[derive(Clone, Debug, PartialEq)]
pub struct ArgumentError {
    /// The keyword argument.
    pub argument: String,
    /// Its value as the user wrote it.
    pub value: String,
    /// What is wrong with it.
    pub problem: String,
}

impl ArgumentError {
    /// The error of `argument` with `value`.
    pub fn new(
        argument: &str,
        value: impl fmt::Display,
        problem: impl Into<String>,
    ) -> ArgumentError {
        ArgumentError {
            argument: argument.to_string(),
            value: value.to_string(),
            problem: problem.into(),
        }
    }
}

impl fmt::Display for ArgumentError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{} = {}: {}", self.argument, self.value, self.problem)
    }
}

impl std::error::Error for ArgumentError {}

/// What a robot observes each step.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ObservationKind {
    /// The sensor reading as [`READING_LEN`] floats.
    Reading,
    /// The reading hashed into a discrete state by this hasher.
    State(StateHasher),
}

/// Floats per robot of a [`ObservationKind::Reading`] observation: field
/// values left, mid, right (0 to 1), then puck left, puck right, obstacle
/// left, obstacle right (0 or 1).
pub const READING_LEN: usize = 7;

/// How a robot acts each step.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ActionKind {
    /// An index into the action table.
    Discrete,
    /// An angular speed in radians per step, clipped to the table's
    /// largest magnitude.
    Continuous,
}

/// What resets an ended episode.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Autoreset {
    /// Nothing: stepping an ended world is refused until it is reset (a
    /// single environment).
    Off,
    /// Gymnasium's default: the step after the end resets the world,
    /// ignores its actions and returns the first observation with reward 0.
    NextStep,
    /// The ending step resets the world at once and returns the first
    /// observation of the new episode, the last one of the old beside it.
    SameStep,
}

/// The default discount of `success-shaped`'s shaping: what PPO and most
/// deep learners use.
pub const DEFAULT_GAMMA: f64 = 0.99;

/// The keyword arguments as given (Python's types, not yet checked).
#[derive(Clone, Debug, PartialEq)]
pub struct EnvArgs {
    /// `field`: `annulus`, `letter:T` or an image path.
    pub field: String,
    /// `arena`: `thesis` or `tv75`; `None` for tv75 with the robot's
    /// senses and the thesis' square otherwise, as `host run`.
    pub arena: Option<String>,
    /// `robots`; `None` for the arena's.
    pub robots: Option<i64>,
    /// `pucks`; `None` for the arena's.
    pub pucks: Option<i64>,
    /// `sensors`: `disc`, `disc-thesis` or `robot`.
    pub sensors: String,
    /// `robot_config`: the robot sensor model's settings as JSON text.
    pub robot_config: Option<String>,
    /// `seed`.
    pub seed: i64,
    /// `max_steps`: truncate episodes after this many steps.
    pub max_steps: Option<i64>,
    /// `thresholds`: (outie, innie).
    pub thresholds: Option<(f64, f64)>,
    /// `reward`: a [`Reward`] name.
    pub reward: String,
    /// `gamma`: the learner's discount, for `success-shaped`'s shaping.
    pub gamma: f64,
    /// `observation`: `reading` or `state`.
    pub observation: String,
    /// `hasher`: a [`StateHasher`] name, for `observation="state"`.
    pub hasher: String,
    /// `action`: `discrete` or `continuous`.
    pub action: String,
    /// `actions`: the action table's angular speeds.
    pub actions: Vec<f32>,
    /// `forward_speed`: units per step.
    pub forward_speed: f32,
    /// The world's other settings (`noise`, `walls`, any setting of
    /// [`WorldChoices`] not named above), by name, as text.
    pub world: Vec<(String, String)>,
}

impl Default for EnvArgs {
    /// The thesis' standard configuration, as `host run` defaults it.
    fn default() -> EnvArgs {
        EnvArgs {
            field: "annulus".into(),
            arena: None,
            robots: None,
            pucks: None,
            sensors: "disc".into(),
            robot_config: None,
            seed: 1,
            max_steps: None,
            thresholds: None,
            reward: "reference".into(),
            gamma: DEFAULT_GAMMA,
            observation: "reading".into(),
            hasher: "original".into(),
            action: "discrete".into(),
            actions: ActionTable::DEFAULT_ANGULAR.to_vec(),
            forward_speed: ActionTable::DEFAULT_FORWARD_SPEED,
            world: Vec::new(),
        }
    }
}

/// The checked settings every world of an environment shares.
#[derive(Clone, Debug)]
pub struct EnvSettings {
    /// The scenario, validated, with its field loaded.
    pub prepared: PreparedScenario,
    /// The seed of the first world.
    pub seed: u64,
    /// Truncate episodes after this many steps (besides the stuck limit).
    pub max_steps: Option<u64>,
    /// The reward every robot receives.
    pub reward: Reward,
    /// The discount of `success-shaped`'s shaping.
    pub gamma: f64,
    /// What a robot observes.
    pub observation: ObservationKind,
    /// How a robot acts.
    pub action: ActionKind,
    /// The action table (for continuous actions, its largest magnitude is
    /// the bound).
    pub actions: ActionTable,
    /// The sensor model and arena, as a policy blob records what it was
    /// trained for.
    pub trained_for: shared::TrainedFor,
}

/// A count or step number, inside its row of the ranges table: every
/// refusal worded as the table words it (`pucks = 0: outside its plausible
/// range [1, 100000] (...)`), whichever side of the range it falls.
pub fn count(range: &'static Range, name: &str, value: i64) -> Result<u64, RangeError> {
    range.check_as(name, value as f64)?;
    // inside the range, so at least its minimum, which is not negative
    Ok(value.unsigned_abs())
}

/// The seeds of `worlds` worlds numbered from `first` (world `i`: `first +
/// i`), each a seed of [`SEED_RANGE`]; `first` is named `seed` in errors.
pub fn world_seeds(first: i64, worlds: usize) -> Result<Vec<u64>, ArgumentError> {
    let first = u64::try_from(first).map_err(|_| ArgumentError::new("seed", first, SEED_RANGE))?;
    let last = first.saturating_add(worlds.saturating_sub(1) as u64);
    if last > i64::MAX as u64 {
        return Err(ArgumentError::new(
            "seed",
            first,
            format!(
                "with {worlds} worlds (world i is seeded seed + i) must be a whole number from 0 to 2**63 - {worlds}"
            ),
        ));
    }
    Ok((first..=last).collect())
}

/// The sensor model named, and the robot sensor model's settings of
/// `robot_config` (JSON) if given.
fn sensors(
    name: &str,
    robot_config: Option<&str>,
) -> Result<(SensorChoice, Option<SensorSetup>), ArgumentError> {
    let choice = match name.parse::<SensorChoice>() {
        Ok(
            choice @ (SensorChoice::Disc | SensorChoice::DiscThesis | SensorChoice::Robot(None)),
        ) => choice,
        _ => {
            return Err(ArgumentError::new(
                "sensors",
                format!("{name:?}"),
                format!("unknown sensor model; expected {}", SensorChoice::NAMES),
            ))
        }
    };
    let Some(json) = robot_config else {
        return Ok((choice, None));
    };
    if !choice.is_robot() {
        return Err(ArgumentError::new(
            "robot_config",
            json,
            "is only for sensors=\"robot\"",
        ));
    }
    let config: RobotSensorConfig = serde_json::from_str(json).map_err(|e| {
        ArgumentError::new(
            "robot_config",
            json,
            format!("is not a valid robot sensor config: {e}"),
        )
    })?;
    config
        .validate()
        .map_err(|e| ArgumentError::new("robot_config", json, e.to_string()))?;
    Ok((choice, Some(SensorSetup::Robot(Box::new(config)))))
}

/// Why an environment cannot be built: a bad argument, or settings the
/// simulator refuses (too many bodies for the arena, an unreadable field
/// image).
#[derive(Debug)]
pub enum SettingsError {
    /// One argument is wrong on its own.
    Argument(ArgumentError),
    /// A count outside its row of the ranges table.
    Range(RangeError),
    /// The simulator refused the combination.
    Scenario(ScenarioError),
}

impl fmt::Display for SettingsError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            SettingsError::Argument(e) => e.fmt(f),
            SettingsError::Range(e) => e.fmt(f),
            SettingsError::Scenario(e) => e.fmt(f),
        }
    }
}

impl std::error::Error for SettingsError {}

impl From<RangeError> for SettingsError {
    fn from(e: RangeError) -> SettingsError {
        SettingsError::Range(e)
    }
}

impl From<ArgumentError> for SettingsError {
    fn from(e: ArgumentError) -> SettingsError {
        SettingsError::Argument(e)
    }
}

impl EnvArgs {
    /// Checks every argument, then builds and validates the scenario and
    /// loads its field.
    pub fn settings(&self) -> Result<EnvSettings, SettingsError> {
        let field: FieldSource = self.field.parse().map_err(|e| {
            ArgumentError::new("field", format!("{:?}", self.field), format!("{e}"))
        })?;
        let robots = self
            .robots
            .map(|r| count(&ROBOTS, "robots", r))
            .transpose()?;
        let pucks = self.pucks.map(|p| count(&PUCKS, "pucks", p)).transpose()?;
        // inside their ranges, so they fit
        let (robots, pucks) = (robots.map(|r| r as usize), pucks.map(|p| p as usize));
        let seed = world_seeds(self.seed, 1)?[0];
        let max_steps = self
            .max_steps
            .map(|m| count(&STEPS, "max_steps", m))
            .transpose()?;
        let reward: Reward = self
            .reward
            .parse()
            .map_err(|e: String| ArgumentError::new("reward", format!("{:?}", self.reward), e))?;
        if !(0.0..=1.0).contains(&self.gamma) {
            return Err(
                ArgumentError::new("gamma", self.gamma, "must be a discount in [0, 1]").into(),
            );
        }
        // The hasher is checked whatever the observation, so that a setting
        // the environment would ignore is not taken silently.
        let hasher = StateHasher::from_name(&self.hasher).ok_or_else(|| {
            ArgumentError::new(
                "hasher",
                format!("{:?}", self.hasher),
                format!("unknown hasher; expected {}", StateHasher::NAMES),
            )
        })?;
        if hasher.has_role_bit() {
            // The environments have no innies yet, so every state would be
            // an outie's: refuse rather than mislead.
            return Err(ArgumentError::new(
                "hasher",
                format!("{:?}", self.hasher),
                "the role layout needs innies, which the Python environments do not have yet",
            )
            .into());
        }
        let observation = match self.observation.as_str() {
            "reading" => ObservationKind::Reading,
            "state" => ObservationKind::State(hasher),
            other => {
                return Err(ArgumentError::new(
                    "observation",
                    format!("{other:?}"),
                    "expected \"reading\" or \"state\"",
                )
                .into())
            }
        };
        let action = match self.action.as_str() {
            "discrete" => ActionKind::Discrete,
            "continuous" => ActionKind::Continuous,
            other => {
                return Err(ArgumentError::new(
                    "action",
                    format!("{other:?}"),
                    "expected \"discrete\" or \"continuous\"",
                )
                .into())
            }
        };
        let forward = &sim::base::ranges::FORWARD_SPEED;
        if let Err(e) = forward.check(f64::from(self.forward_speed)) {
            // the f32 as written (its shortest decimal form), not widened
            let written = self.forward_speed.to_string().parse().unwrap_or(e.value);
            let value = sim::base::ranges::number(written);
            let problem = format!("outside its plausible range {forward} ({})", forward.why);
            return Err(ArgumentError::new("forward_speed", value, problem).into());
        }
        let actions = ActionTable::new(&self.actions, self.forward_speed).map_err(|e| {
            ArgumentError::new("actions", format!("{:?}", self.actions), e.to_string())
        })?;
        let (sensors, robot_setup) = sensors(&self.sensors, self.robot_config.as_deref())?;
        let arena = match self.arena.as_deref() {
            None => None,
            Some("thesis") => Some(ArenaChoice::Thesis),
            Some(name) if ArenaSpec::by_name(name).is_some() => {
                Some(ArenaChoice::Named(name.to_string()))
            }
            Some(name) => {
                return Err(ArgumentError::new(
                    "arena",
                    format!("{name:?}"),
                    format!("expected \"thesis\" or one of {}", ArenaSpec::NAMES),
                )
                .into())
            }
        };
        // The world's settings: those above, checked as the environments
        // word their errors, then the rest by name.
        let mut world = WorldChoices {
            field,
            sensors,
            arena,
            robots,
            pucks,
            seed,
            ..WorldChoices::default()
        };
        for (name, text) in &self.world {
            world
                .set(name, text)
                .map_err(|e| ArgumentError::new(&e.name, format!("{:?}", e.value), e.problem))?;
        }
        // What a policy exported from here records, as `host train`'s does.
        let trained_for = trained_for::trained_for(&world.sensors, &world.arena_choice());
        // Random is the controller whose settings leave every robot an
        // outie, as the trainer has them; the environment never uses it.
        let mut scenario = ScenarioChoices {
            controller: ControllerChoice::Random,
            world,
        }
        .scenario()
        .map_err(SettingsError::Scenario)?;
        if let Some(setup) = robot_setup {
            scenario.sensors = setup;
        }
        // The arena's counts where none are given.
        let (default_robots, default_pucks) = match &scenario.arena {
            Arena::Square(_) => (
                SimConfig::default().world.robots,
                SimConfig::default().world.pucks,
            ),
            Arena::Screen(spec) => (spec.robots, spec.pucks),
        };
        let pucks = scenario.pucks;
        let mut prepared = scenario.prepare().map_err(|e| match e {
            // The one combination no single argument decides.
            ScenarioError::Config(c @ ConfigError::TooManyBodies { .. }) => {
                let counts = format!(
                    "{}, {}",
                    robots.unwrap_or(default_robots),
                    pucks.unwrap_or(default_pucks)
                );
                SettingsError::Argument(ArgumentError::new("robots, pucks", counts, c.to_string()))
            }
            other => SettingsError::Scenario(other),
        })?;
        let config = prepared.config_mut();
        config.world.forward_speed = f64::from(self.forward_speed);
        if let Some((outie, innie)) = self.thresholds {
            let shown = format!("({outie}, {innie})");
            let unit = |v: f64| (0.0..=1.0).contains(&v);
            if !(unit(outie) && unit(innie) && outie <= innie) {
                return Err(ArgumentError::new(
                    "thresholds",
                    shown,
                    "must be (outie, innie) with 0 <= outie <= innie <= 1",
                )
                .into());
            }
            config.thresholds = Thresholds { outie, innie };
        }
        config
            .validate()
            .map_err(|e| SettingsError::Scenario(ScenarioError::Config(e)))?;
        Ok(EnvSettings {
            prepared,
            seed,
            max_steps,
            reward,
            gamma: self.gamma,
            observation,
            action,
            actions,
            trained_for,
        })
    }
}

impl EnvSettings {
    /// Robots per world.
    pub fn robots(&self) -> usize {
        self.prepared.config().world.robots
    }

    /// The continuous action's bound: the table's largest angular speed.
    pub fn max_turn(&self) -> f32 {
        self.actions
            .angular_speeds()
            .iter()
            .fold(0.0f32, |m, a| m.max(a.abs()))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn error_of(args: EnvArgs) -> String {
        args.settings().unwrap_err().to_string()
    }

    #[test]
    fn the_defaults_are_the_standard_configuration() {
        let s = EnvArgs::default().settings().unwrap();
        assert_eq!(s.robots(), 8);
        assert_eq!(s.prepared.config().world.pucks, 250);
        assert_eq!(s.prepared.config().world.innies, 0);
        assert_eq!(s.max_turn(), 0.3);
    }

    #[test]
    fn a_count_is_refused_in_the_ranges_tables_words_on_either_side_of_its_range() {
        for pucks in [-3, 0, 100_001] {
            let e = error_of(EnvArgs {
                pucks: Some(pucks),
                ..EnvArgs::default()
            });
            let expected = format!("pucks = {pucks}: outside its plausible range [1, 100000] (");
            assert!(e.starts_with(&expected), "{e}");
        }
        let e = error_of(EnvArgs {
            max_steps: Some(-1),
            ..EnvArgs::default()
        });
        assert!(
            e.starts_with("max_steps = -1: outside its plausible range [1, 1e10] steps"),
            "{e}"
        );
    }

    #[test]
    fn the_hasher_is_checked_whatever_the_observation() {
        let refusals = [
            ("original-role", "the role layout needs innies"),
            ("md5", "unknown hasher"),
        ];
        for observation in ["reading", "state"] {
            for (hasher, problem) in refusals {
                let e = error_of(EnvArgs {
                    observation: observation.into(),
                    hasher: hasher.into(),
                    ..EnvArgs::default()
                });
                assert!(
                    e.starts_with(&format!("hasher = {hasher:?}: {problem}")),
                    "{e}"
                );
            }
        }
    }

    #[test]
    fn every_worlds_seed_is_at_most_2_to_the_63_minus_1() {
        assert_eq!(world_seeds(5, 3).unwrap(), [5, 6, 7]);
        assert_eq!(world_seeds(i64::MAX, 1).unwrap(), [i64::MAX as u64]);
        assert_eq!(
            world_seeds(-1, 1).unwrap_err().to_string(),
            "seed = -1: must be a whole number from 0 to 2**63 - 1"
        );
        assert_eq!(
            world_seeds(i64::MAX - 1, 3).unwrap_err().to_string(),
            "seed = 9223372036854775806: with 3 worlds (world i is seeded seed + i) \
             must be a whole number from 0 to 2**63 - 3"
        );
    }

    #[test]
    fn each_bad_argument_is_named_with_its_value_and_problem() {
        let e = error_of(EnvArgs {
            robots: Some(0),
            ..EnvArgs::default()
        });
        assert!(
            e.starts_with("robots = 0: outside its plausible range [1, 1000] ("),
            "{e}"
        );
        let e = error_of(EnvArgs {
            sensors: "pixy".into(),
            ..EnvArgs::default()
        });
        assert!(
            e.starts_with("sensors = \"pixy\": unknown sensor model"),
            "{e}"
        );
        let e = error_of(EnvArgs {
            field: "letter:Q".into(),
            ..EnvArgs::default()
        });
        assert!(e.starts_with("field = \"letter:Q\""), "{e}");
        let e = error_of(EnvArgs {
            thresholds: Some((0.9, 0.2)),
            ..EnvArgs::default()
        });
        assert!(e.starts_with("thresholds = (0.9, 0.2)"), "{e}");
        let e = error_of(EnvArgs {
            actions: vec![0.1],
            ..EnvArgs::default()
        });
        assert!(e.starts_with("actions = [0.1]: action count 1"), "{e}");
        let e = error_of(EnvArgs {
            pucks: Some(100_000),
            ..EnvArgs::default()
        });
        assert!(e.starts_with("robots, pucks = 8, 100000: "), "{e}");
        let e = error_of(EnvArgs {
            robot_config: Some("{}".into()),
            ..EnvArgs::default()
        });
        assert!(
            e.starts_with("robot_config = {}: is only for sensors=\"robot\""),
            "{e}"
        );
        let bad_camera = r#"{"camera": {"height_mm": 0}}"#;
        let e = error_of(EnvArgs {
            sensors: "robot".into(),
            robot_config: Some(bad_camera.into()),
            ..EnvArgs::default()
        });
        assert!(e.contains("camera.height_mm"), "{e}");
    }
}
