//! The world's settings as a user names them (`--field`, `--sensors`,
//! `--arena`, `--robots`, `--pucks`, `--seed`, `--noise`, `--walls`): what
//! `host run`, training and the live view (`view`) turn into a [`Scenario`]:
//! [`WorldChoices`], with a controller [`ScenarioChoices`]. On a screen
//! arena the puck count left unset is the shape's by the puck rule
//! ([`rule_pucks`]).

use crate::base::ranges::{self, RangeError};
use crate::config::{BroadPhase, Walls};
use crate::fields::source::FieldSource;
use crate::scenario::arena_choice::ArenaChoice;
use crate::scenario::puck_rule::rule_pucks;
use crate::scenario::sensor_choice::SensorChoice;
use crate::scenario::{Arena, ControllerChoice, Scenario, ScenarioError};
use serde::Serialize;

/// A world's settings by name; `None` takes the arena's own. The settings
/// every front end shares (the training config, `host run`, the live view),
/// kept in one struct so that each hands it on whole. Serialised, its
/// fields are the settings' names (a test checks each front end by them).
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct WorldChoices {
    /// The field.
    pub field: FieldSource,
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
        }
    }
}

impl WorldChoices {
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
    /// The scenario, arena and sensor files read and checked (the counts,
    /// noise and settings are checked when it is prepared or built); on a
    /// screen arena the puck count left unset is the puck rule's.
    pub fn scenario(&self) -> Result<Scenario, ScenarioError> {
        let w = &self.world;
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
        })
    }
}

/// Checks the world's counts and noise against their rows of the table of
/// ranges, named as every front end names them (`robots`, `pucks`,
/// `noise`): the one check of these settings, which a training config and
/// a scenario both make.
pub fn check_world_ranges(
    robots: Option<usize>,
    pucks: Option<usize>,
    noise: f64,
) -> Result<(), RangeError> {
    if let Some(robots) = robots {
        ranges::ROBOTS.check_count("robots", robots as u64)?;
    }
    if let Some(pucks) = pucks {
        ranges::PUCKS.check_count("pucks", pucks as u64)?;
    }
    ranges::NOISE.check(noise)
}
