//! Formats 5 and 6: the training state as it was laid out before n-step
//! returns (`n_step`, and the robots' waiting steps beside the learner).
//! Files are read into format 7's layout ([`super::format7`]); a state of
//! one-step returns converts to this layout (or an older one) again, byte
//! for byte what earlier builds wrote (`checkpoint::write_earlier_format`),
//! and an experiment trial's settings that do hash in it
//! (`experiment::plan`).
//!
//! postcard is positional: these structs list the fields of formats 5 and
//! 6 in their order, the types they share with the newest format
//! unchanged (the two formats differ only in the rewards format 5's
//! readers know).

use super::config::{FormationCheck, ObstacleDiscs, OutputConfig};
use super::format7::{LearnConfigV7, LearnerRules, QLearnerV7, StateV7, TrainConfigV7};
use super::selection::{SelectConfig, Selected};
use crate::learn::PendingSteps;
use serde::{Deserialize, Serialize};
use sim::config::{SuccessSignal, Walls};
use sim::fields::source::FieldSource;
use sim::scenario::arena_choice::ArenaChoice;
use sim::scenario::sensor_choice::SensorChoice;
use sim::simulation::SimulationState;

/// A training state in the layout of formats 5 and 6.
#[derive(Serialize, Deserialize)]
pub struct StateV6 {
    config: TrainConfigV6,
    field_crc: u32,
    sim: SimulationState,
    learner: QLearnerV7,
    selected: Option<Selected>,
}

/// A [`TrainConfigV7`] without `n_step`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TrainConfigV6 {
    field: FieldSource,
    sensors: SensorChoice,
    arena: Option<ArenaChoice>,
    robots: Option<usize>,
    pucks: Option<usize>,
    noise: f64,
    steps: u64,
    seed: u64,
    stuck_limit: Option<u64>,
    learn: LearnConfigV7,
    output: OutputConfig,
    formation_check: FormationCheck,
    success: SuccessSignal,
    innies: Option<usize>,
    obstacle_discs: Option<ObstacleDiscs>,
    select: Option<SelectConfig>,
    distil_oc: Option<u64>,
    walls: Option<Walls>,
    rules: LearnerRules,
    epsilon_decay: Option<u64>,
}

impl TrainConfigV6 {
    /// The settings in this layout, if the run's returns are one-step.
    pub fn of(c: &TrainConfigV7) -> Option<TrainConfigV6> {
        c.n_step.is_none().then(|| TrainConfigV6 {
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
            epsilon_decay: c.epsilon_decay,
        })
    }
}

impl From<TrainConfigV6> for TrainConfigV7 {
    /// The settings, returns one-step.
    fn from(c: TrainConfigV6) -> TrainConfigV7 {
        TrainConfigV7 {
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
            epsilon_decay: c.epsilon_decay,
            n_step: None,
        }
    }
}

impl StateV6 {
    /// The state in this layout, if its returns are one-step (so no robot
    /// has a step waiting).
    pub fn of(state: &StateV7) -> Option<StateV6> {
        if !state.pending.is_empty() {
            return None;
        }
        Some(StateV6 {
            config: TrainConfigV6::of(&state.config)?,
            field_crc: state.field_crc,
            sim: state.sim.clone(),
            learner: state.learner.clone(),
            selected: state.selected.clone(),
        })
    }

    /// The state, its returns one-step.
    pub fn into_v7(self) -> StateV7 {
        StateV7 {
            config: self.config.into(),
            field_crc: self.field_crc,
            sim: self.sim,
            learner: self.learner,
            selected: self.selected,
            pending: PendingSteps::default(),
        }
    }
}
