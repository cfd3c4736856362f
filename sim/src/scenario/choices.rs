//! The world's settings as a user names them (`--field`, `--sensors`,
//! `--arena`, `--robots`, `--pucks`, `--seed`, `--noise`, `--walls`): what
//! `host run`, training and the live view (`view`) turn into a [`Scenario`].
//! On a screen arena the puck count left unset is the shape's by the puck
//! rule ([`rule_pucks`]).

use crate::config::{BroadPhase, Walls};
use crate::fields::source::FieldSource;
use crate::scenario::arena_choice::ArenaChoice;
use crate::scenario::puck_rule::rule_pucks;
use crate::scenario::sensor_choice::SensorChoice;
use crate::scenario::{Arena, ControllerChoice, Scenario, ScenarioError};

/// A world's settings by name; `None` takes the arena's own.
#[derive(Clone, Debug, PartialEq)]
pub struct ScenarioChoices {
    /// The field.
    pub field: FieldSource,
    /// The controller.
    pub controller: ControllerChoice,
    /// The sensor model.
    pub sensors: SensorChoice,
    /// The arena; `None` for [`ArenaChoice::default_for`] the sensor model.
    pub arena: Option<ArenaChoice>,
    /// Number of robots.
    pub robots: Option<usize>,
    /// Number of pucks.
    pub pucks: Option<usize>,
    /// Seed of every generator.
    pub seed: u64,
    /// Noise, times the default ([`Scenario::noise`]).
    pub noise: f64,
    /// How the border keeps the bodies in.
    pub walls: Option<Walls>,
}

impl Default for ScenarioChoices {
    /// [`Scenario::default`]'s: the thesis' standard run.
    fn default() -> ScenarioChoices {
        let s = Scenario::default();
        ScenarioChoices {
            field: s.field,
            controller: s.controller,
            sensors: SensorChoice::default(),
            arena: None,
            robots: s.robots,
            pucks: s.pucks,
            seed: s.seed,
            noise: s.noise,
            walls: s.walls,
        }
    }
}

impl ScenarioChoices {
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

    /// The scenario, arena and sensor files read and checked (the counts,
    /// noise and settings are checked when it is prepared or built); on a
    /// screen arena the puck count left unset is the puck rule's.
    pub fn scenario(&self) -> Result<Scenario, ScenarioError> {
        let arena = self.arena_choice().arena()?;
        Ok(Scenario {
            field: self.field.clone(),
            controller: self.controller.clone(),
            robots: self.robots,
            pucks: self.pucks_in(&arena)?,
            seed: self.seed,
            broad_phase: BroadPhase::Grid,
            arena,
            sensors: self.sensors.setup()?,
            noise: self.noise,
            walls: self.walls,
        })
    }
}
