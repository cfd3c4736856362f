//! Format 4: the training settings as they were laid out before decaying
//! exploration (`epsilon_decay`). States without it keep this layout, so a
//! checkpoint is byte for byte what earlier builds wrote and an experiment
//! trial's hash the one they gave it (`experiment::plan`).
//!
//! postcard is positional: these structs list format 4's fields in their
//! order, the types they share with the newest format unchanged.

use super::config::{FormationCheck, ObstacleDiscs, OutputConfig, TrainConfig};
use super::selection::{SelectConfig, Selected};
use super::trainer::TrainingState;
use crate::learn::{LearnConfig, LearnerRules, QLearner};
use serde::{Deserialize, Serialize};
use sim::config::{SuccessSignal, Walls};
use sim::fields::source::FieldSource;
use sim::scenario::arena_choice::ArenaChoice;
use sim::scenario::sensor_choice::SensorChoice;
use sim::simulation::SimulationState;

/// A training state in format 4's layout.
#[derive(Serialize, Deserialize)]
pub struct StateV4 {
    config: TrainConfigV4,
    field_crc: u32,
    sim: SimulationState,
    learner: QLearner,
    selected: Option<Selected>,
}

/// A [`TrainConfig`] without `epsilon_decay`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TrainConfigV4 {
    field: FieldSource,
    sensors: SensorChoice,
    arena: Option<ArenaChoice>,
    robots: Option<usize>,
    pucks: Option<usize>,
    noise: f64,
    steps: u64,
    seed: u64,
    stuck_limit: Option<u64>,
    learn: LearnConfig,
    output: OutputConfig,
    formation_check: FormationCheck,
    success: SuccessSignal,
    innies: Option<usize>,
    obstacle_discs: Option<ObstacleDiscs>,
    select: Option<SelectConfig>,
    distil_oc: Option<u64>,
    walls: Option<Walls>,
    rules: LearnerRules,
}

impl TrainConfigV4 {
    /// The settings in format 4, if the run's exploration does not decay.
    pub fn of(c: &TrainConfig) -> Option<TrainConfigV4> {
        c.epsilon_decay.is_none().then(|| TrainConfigV4 {
            field: c.field.clone(),
            sensors: c.sensors.clone(),
            arena: c.arena.clone(),
            robots: c.robots,
            pucks: c.pucks,
            noise: c.noise,
            steps: c.steps,
            seed: c.seed,
            stuck_limit: c.stuck_limit,
            learn: c.learn.clone(),
            output: c.output.clone(),
            formation_check: c.formation_check,
            success: c.success,
            innies: c.innies,
            obstacle_discs: c.obstacle_discs,
            select: c.select,
            distil_oc: c.distil_oc,
            walls: c.walls,
            rules: c.rules,
        })
    }
}

impl From<TrainConfigV4> for TrainConfig {
    /// The settings, exploration constant.
    fn from(c: TrainConfigV4) -> TrainConfig {
        TrainConfig {
            field: c.field,
            sensors: c.sensors,
            arena: c.arena,
            robots: c.robots,
            pucks: c.pucks,
            noise: c.noise,
            steps: c.steps,
            seed: c.seed,
            stuck_limit: c.stuck_limit,
            learn: c.learn,
            output: c.output,
            formation_check: c.formation_check,
            success: c.success,
            innies: c.innies,
            obstacle_discs: c.obstacle_discs,
            select: c.select,
            distil_oc: c.distil_oc,
            walls: c.walls,
            rules: c.rules,
            epsilon_decay: None,
        }
    }
}

impl StateV4 {
    /// The state in format 4, if its settings fit ([`TrainConfigV4::of`]).
    pub fn of(state: &TrainingState) -> Option<StateV4> {
        Some(StateV4 {
            config: TrainConfigV4::of(&state.config)?,
            field_crc: state.field_crc,
            sim: state.sim.clone(),
            learner: state.learner.clone(),
            selected: state.selected.clone(),
        })
    }

    /// The state, exploration constant.
    pub fn into_state(self) -> TrainingState {
        TrainingState {
            config: self.config.into(),
            field_crc: self.field_crc,
            sim: self.sim,
            learner: self.learner,
            selected: self.selected,
        }
    }
}
