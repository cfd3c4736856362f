//! The world's settings as a user names them (`--field`, `--sensors`,
//! `--arena`, `--robots`, `--pucks`, `--seed`, `--noise`, `--walls`): what
//! `host run`, training and the live view (`view`) turn into a [`Scenario`]:
//! [`WorldChoices`], with a controller [`ScenarioChoices`]. On a screen
//! arena the puck count left unset is the shape's by the puck rule
//! ([`rule_pucks`]).

use crate::base::ranges::{self, RangeError};
use crate::config::validate::ConfigError;
use crate::config::{BroadPhase, Walls};
use crate::fields::source::FieldSource;
use crate::scenario::arena_choice::ArenaChoice;
use crate::scenario::puck_rule::rule_pucks;
use crate::scenario::sensor_choice::SensorChoice;
use crate::scenario::{Arena, ControllerChoice, Scenario, ScenarioError};
use serde::{Deserialize, Serialize};
use serde_json::{Map, Value};
use std::fmt;
use std::sync::LazyLock;

/// A world's settings by name; `None` takes the arena's own. The one
/// declaration of the settings every front end shares: a training run's
/// (flattened into its config, so they are its file keys, checkpoint
/// fields and flags), `host run`'s flags, the live view's URL parameters
/// and Python's keyword arguments are these fields by name, and each
/// field's doc comment is its flag's help. A front end hands the struct on
/// whole; its serde form is the settings by name ([`WorldChoices::pairs`],
/// [`WorldChoices::set`]).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[cfg_attr(feature = "clap", derive(clap::Args))]
#[serde(default)]
pub struct WorldChoices {
    /// The field: annulus, letter:T (our T, I, L, V, X, Z), thesis:T (the
    /// thesis' T, L, V, X, Z), either turned (letter:L@mirror; @rot90,
    /// @rot180, @rot270 clockwise, @mirror, @mirror-rot90, ...), a generated
    /// shape (gen:FAMILY:SEED, docs/generated-shapes.md) or an image file
    /// (PNG, JPEG) [default: annulus].
    #[cfg_attr(feature = "clap", arg(long, required = false))]
    pub field: FieldSource,
    /// Sensor model: disc (the reference model's discs), disc-thesis (with
    /// the thesis' larger, robots-only obstacle discs), robot (the Zumo's
    /// photo-transistors and Pixy camera, through the firmware's arithmetic)
    /// or robot:CONFIG.json (docs/robot-sensors.md) [default: disc].
    #[cfg_attr(feature = "clap", arg(long, required = false))]
    pub sensors: SensorChoice,
    /// The arena: thesis (the reference model's 800 x 800 square), tv75
    /// (the thesis' 75" TV lying flat) or a FILE.toml of a screen arena
    /// [default: tv75 with the robot's senses, else thesis].
    #[cfg_attr(feature = "clap", arg(long))]
    pub arena: Option<ArenaChoice>,
    /// Number of robots [default: the arena's: 8 in the thesis' square, 5
    /// on tv75].
    #[cfg_attr(feature = "clap", arg(long))]
    pub robots: Option<usize>,
    /// Number of pucks [default: the arena's: 250 in the thesis' square; on
    /// a screen, the shape's by the puck rule].
    #[cfg_attr(feature = "clap", arg(long))]
    pub pucks: Option<usize>,
    /// Seed of every random choice [default: 1].
    #[cfg_attr(feature = "clap", arg(long, required = false))]
    pub seed: u64,
    /// Real-world noise (domain randomisation) in multiples of the default
    /// (0 none, 1 the default, 2 twice as much): the robots' motion and the
    /// robot senses' readings [default: 0].
    #[cfg_attr(feature = "clap", arg(long, required = false))]
    pub noise: f64,
    /// How the arena's border keeps the bodies in: clamp (put back inside,
    /// no contact: the thesis author's program) or segments (walls the
    /// bodies bounce off) [default: clamp in the thesis' square, segments
    /// on a screen].
    #[cfg_attr(feature = "clap", arg(long))]
    pub walls: Option<Walls>,
    /// Steps before an unformed episode counts as stuck [default: a screen
    /// arena's own (15,000 on tv75), else the field's: 150,000 on the
    /// annulus, 50,000 otherwise].
    #[cfg_attr(feature = "clap", arg(long))]
    pub stuck_limit: Option<u64>,
}

impl Default for WorldChoices {
    /// [`Scenario::default`]'s: the thesis' standard run.
    fn default() -> WorldChoices {
        let s = Scenario::default();
        WorldChoices {
            field: s.field,
            sensors: SensorChoice::default(),
            arena: None,
            robots: s.robots,
            pucks: s.pucks,
            seed: s.seed,
            noise: s.noise,
            walls: s.walls,
            stuck_limit: s.stuck_limit,
        }
    }
}

/// A world setting given by name and text that cannot be used.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SettingError {
    /// The setting's name as given.
    pub name: String,
    /// Its value as given.
    pub value: String,
    /// What is wrong.
    pub problem: String,
}

impl fmt::Display for SettingError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{} = {:?}: {}", self.name, self.value, self.problem)
    }
}

impl core::error::Error for SettingError {}

impl WorldChoices {
    /// The settings' names, sorted.
    pub fn names() -> &'static [String] {
        static NAMES: LazyLock<Vec<String>> =
            LazyLock::new(|| WorldChoices::default().fields().keys().cloned().collect());
        &NAMES
    }

    /// Each setting by name (sorted), as text that [`WorldChoices::set`]
    /// reads back (a setting left to the arena, `None`, as "").
    pub fn pairs(&self) -> Vec<(String, String)> {
        self.fields()
            .into_iter()
            .map(|(name, value)| {
                let text = match value {
                    Value::Null => String::new(),
                    Value::String(s) => s,
                    other => other.to_string(),
                };
                (name, text)
            })
            .collect()
    }

    /// Sets the setting `name` from `text`, read as the setting's type
    /// reads it (a name, a number; "" leaves an optional setting to the
    /// arena): the one way a front end of text (the view's URL, Python's
    /// keyword arguments) sets a world setting. Errors name the setting.
    pub fn set(&mut self, name: &str, text: &str) -> Result<(), SettingError> {
        let error = |problem: String| SettingError {
            name: name.to_string(),
            value: text.to_string(),
            problem,
        };
        let mut fields = self.fields();
        if !fields.contains_key(name) {
            return Err(error(format!(
                "no such setting; the world's are {}",
                WorldChoices::names().join(", ")
            )));
        }
        let read = |fields: &mut Map<String, Value>, value: Value| {
            fields.insert(name.to_string(), value);
            serde_json::from_value::<WorldChoices>(Value::Object(fields.clone()))
        };
        let as_text = if text.is_empty() {
            Value::Null
        } else {
            Value::String(text.to_string())
        };
        *self = match read(&mut fields, as_text) {
            Ok(world) => world,
            Err(e) => match serde_json::from_str::<serde_json::Number>(text) {
                Ok(number) => {
                    read(&mut fields, Value::Number(number)).map_err(|e| error(e.to_string()))?
                }
                Err(_) => return Err(error(e.to_string())),
            },
        };
        Ok(())
    }

    /// Checks every numeric setting against the row of the table of ranges
    /// its name names ([`ranges::row`]), named as every front end names
    /// it: the one check of the world's settings.
    pub fn check_ranges(&self) -> Result<(), RangeError> {
        for (name, value) in self.fields() {
            if let (Some(x), Some(row)) = (value.as_f64(), ranges::row(&name)) {
                row.check_as(&name, x)?;
            }
        }
        Ok(())
    }

    /// The settings as a map from name to value, sorted by name.
    fn fields(&self) -> Map<String, Value> {
        match serde_json::to_value(self) {
            Ok(Value::Object(map)) => map,
            // a struct of plain values serialises to an object
            _ => Map::new(),
        }
    }

    /// The arena named, or the sensor model's default.
    pub fn arena_choice(&self) -> ArenaChoice {
        self.arena
            .clone()
            .unwrap_or_else(|| ArenaChoice::default_for(self.sensors.is_robot()))
    }

    /// The puck count: the one given, else on a screen arena the field's
    /// by the puck rule, else `None` (the arena's own).
    pub fn pucks(&self) -> Result<Option<usize>, ScenarioError> {
        self.pucks_in(&self.arena_choice().arena()?)
    }

    /// [`pucks`](Self::pucks) in `arena`, the arena this choice names.
    fn pucks_in(&self, arena: &Arena) -> Result<Option<usize>, ScenarioError> {
        match (self.pucks, arena) {
            (None, Arena::Screen(_)) => Ok(Some(rule_pucks(&self.field, arena)?)),
            (pucks, _) => Ok(pucks),
        }
    }
}

/// A world's settings and its controller by name.
#[derive(Clone, Debug, PartialEq)]
pub struct ScenarioChoices {
    /// The controller.
    pub controller: ControllerChoice,
    /// The world.
    pub world: WorldChoices,
}

impl ScenarioChoices {
    /// The scenario, its numeric settings checked against their ranges
    /// ([`WorldChoices::check_ranges`]) and its arena and sensor files read
    /// and checked (the rest is checked when it is prepared or built); on a
    /// screen arena the puck count left unset is the puck rule's.
    pub fn scenario(&self) -> Result<Scenario, ScenarioError> {
        let w = &self.world;
        w.check_ranges().map_err(ConfigError::from)?;
        let arena = w.arena_choice().arena()?;
        Ok(Scenario {
            field: w.field.clone(),
            controller: self.controller.clone(),
            robots: w.robots,
            pucks: w.pucks_in(&arena)?,
            seed: w.seed,
            broad_phase: BroadPhase::Grid,
            arena,
            sensors: w.sensors.setup()?,
            noise: w.noise,
            walls: w.walls,
            stuck_limit: w.stuck_limit,
        })
    }
}

/// Checks the world's counts and noise (`robots`, `pucks`, `noise`)
/// against their rows of the table of ranges: what a scenario built
/// without a [`WorldChoices`] checks, the same way.
pub fn check_world_ranges(
    robots: Option<usize>,
    pucks: Option<usize>,
    noise: f64,
) -> Result<(), RangeError> {
    WorldChoices {
        robots,
        pucks,
        noise,
        ..WorldChoices::default()
    }
    .check_ranges()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_setting_reads_back_from_its_text_by_name() {
        let mut world = WorldChoices {
            field: "letter:L@mirror".parse().unwrap(),
            sensors: SensorChoice::Robot(None),
            arena: Some(ArenaChoice::Named("tv75".into())),
            robots: Some(4),
            pucks: None,
            seed: 7,
            noise: 1.5,
            walls: Some(Walls::Segments),
            stuck_limit: Some(3_000),
        };
        let mut again = WorldChoices::default();
        for (name, text) in world.pairs() {
            again.set(&name, &text).unwrap();
        }
        assert_eq!(again, world);
        let names: Vec<String> = world.pairs().into_iter().map(|(n, _)| n).collect();
        assert_eq!(names, WorldChoices::names());
        // "" leaves an optional setting to the arena
        world.set("robots", "").unwrap();
        assert_eq!(world.robots, None);
    }

    #[test]
    fn a_bad_setting_is_named_with_its_value_and_changes_nothing() {
        let mut world = WorldChoices::default();
        for (name, text, says) in [
            ("robots", "four", "expected usize"),
            ("seed", "-1", "expected u64"),
            ("noise", "loud", "expected f64"),
            ("field", "letter:Q", "unknown letter \"Q\""),
            ("robot", "4", "no such setting"),
        ] {
            let e = world.set(name, text).unwrap_err();
            assert_eq!((e.name.as_str(), e.value.as_str()), (name, text));
            assert!(e.problem.contains(says), "{e}");
        }
        assert_eq!(world, WorldChoices::default());
    }
}
