//! Format 7: the training state as postcard laid it out before checkpoints
//! described themselves, and the layout every older format converts
//! through ([`super::format1`] to [`super::format6`] read into it). Its
//! settings keep the learner's rules beside the learner's other settings
//! (`rules`), as they were.
//!
//! A [`TrainConfig`] is of this layout when every setting added since
//! keeps its default: [`TrainConfigV7::of`] projects a config onto the
//! layout's fields and accepts it only when converting back gives the
//! same config, so a new setting needs no guard here. An experiment
//! trial's hash is that of the oldest layout that holds its settings
//! (`experiment::plan`), so the hashes of trials run before a setting
//! existed do not change.

use super::config::{FormationCheck, ObstacleDiscs, OutputConfig, TrainConfig};
use super::selection::{SelectConfig, Selected};
use super::trainer::TrainingState;
use crate::learn::{LearnConfig, PendingSteps, QLearner, QTable, StateHasherName, Updates};
use serde::{Deserialize, Serialize};
use sim::config::{SuccessSignal, Walls};
use sim::episodes::reward::Reward;
use sim::fields::source::FieldSource;
use sim::scenario::arena_choice::ArenaChoice;
use sim::scenario::choices::WorldChoices;
use sim::scenario::sensor_choice::SensorChoice;
use sim::simulation::SimulationState;

/// A training state in format 7's layout.
#[derive(Clone, Serialize, Deserialize)]
pub struct StateV7 {
    pub(super) config: TrainConfigV7,
    pub(super) field_crc: u32,
    pub(super) sim: SimulationState,
    pub(super) learner: QLearnerV7,
    pub(super) selected: Option<Selected>,
    pub(super) pending: PendingSteps,
}

/// The learner's settings in format 7's layout: without its rules.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct LearnConfigV7 {
    pub(super) hasher: StateHasherName,
    pub(super) actions: Vec<f32>,
    pub(super) alpha: f64,
    pub(super) gamma: f64,
    pub(super) epsilon: f64,
    pub(super) initial_q: f64,
    pub(super) reward: Reward,
}

/// The learner's rules in format 7's layout (from format 4 on).
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
pub struct LearnerRules {
    pub(super) tie_tolerance: f64,
    pub(super) updates: Updates,
}

impl Default for LearnerRules {
    /// The thesis author's program: exact ties, sequential updates.
    fn default() -> LearnerRules {
        let d = LearnConfig::default();
        LearnerRules {
            tie_tolerance: d.tie_tolerance,
            updates: d.updates,
        }
    }
}

/// A learner in format 7's layout: its settings without the rules, its
/// table and its last reward signal.
#[derive(Clone, Serialize, Deserialize)]
pub struct QLearnerV7 {
    pub(super) config: LearnConfigV7,
    q: QTable,
    last_signal: f64,
}

/// A [`TrainConfig`] in format 7's layout.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TrainConfigV7 {
    pub(super) field: FieldSource,
    pub(super) sensors: SensorChoice,
    pub(super) arena: Option<ArenaChoice>,
    pub(super) robots: Option<usize>,
    pub(super) pucks: Option<usize>,
    pub(super) noise: f64,
    pub(super) steps: u64,
    pub(super) seed: u64,
    pub(super) stuck_limit: Option<u64>,
    pub(super) learn: LearnConfigV7,
    pub(super) output: OutputConfig,
    pub(super) formation_check: FormationCheck,
    pub(super) success: SuccessSignal,
    pub(super) innies: Option<usize>,
    pub(super) obstacle_discs: Option<ObstacleDiscs>,
    pub(super) select: Option<SelectConfig>,
    pub(super) distil_oc: Option<u64>,
    pub(super) walls: Option<Walls>,
    pub(super) rules: LearnerRules,
    pub(super) epsilon_decay: Option<u64>,
    pub(super) n_step: Option<u32>,
}

impl LearnConfigV7 {
    /// `c` without its rules.
    fn project(c: &LearnConfig) -> LearnConfigV7 {
        LearnConfigV7 {
            hasher: c.hasher,
            actions: c.actions.clone(),
            alpha: c.alpha,
            gamma: c.gamma,
            epsilon: c.epsilon,
            initial_q: c.initial_q,
            reward: c.reward,
        }
    }

    /// The settings with `rules`; the ones added since at their defaults.
    #[allow(
        clippy::needless_update,
        reason = "a setting added later takes its default here"
    )]
    fn with_rules(self, rules: LearnerRules) -> LearnConfig {
        LearnConfig {
            hasher: self.hasher,
            actions: self.actions,
            alpha: self.alpha,
            gamma: self.gamma,
            epsilon: self.epsilon,
            initial_q: self.initial_q,
            reward: self.reward,
            tie_tolerance: rules.tie_tolerance,
            updates: rules.updates,
            ..LearnConfig::default()
        }
    }
}

impl TrainConfigV7 {
    /// `c`'s settings of this layout, whatever the rest.
    fn project(c: &TrainConfig) -> TrainConfigV7 {
        let w = &c.world;
        TrainConfigV7 {
            field: w.field.clone(),
            sensors: w.sensors.clone(),
            arena: w.arena.clone(),
            robots: w.robots,
            pucks: w.pucks,
            noise: w.noise,
            steps: c.steps,
            seed: w.seed,
            stuck_limit: w.stuck_limit,
            learn: LearnConfigV7::project(&c.learn),
            output: c.output.clone(),
            formation_check: c.formation_check,
            success: c.success,
            innies: c.innies,
            obstacle_discs: c.obstacle_discs,
            select: c.select,
            distil_oc: c.distil_oc,
            walls: w.walls,
            rules: LearnerRules {
                tie_tolerance: c.learn.tie_tolerance,
                updates: c.learn.updates,
            },
            epsilon_decay: c.epsilon_decay,
            n_step: c.n_step,
        }
    }

    /// The run's border ([`TrainConfig::walls_in_effect`]).
    pub(super) fn walls_in_effect(&self) -> Walls {
        TrainConfig::from(self.clone()).walls_in_effect()
    }

    /// The run's arena ([`TrainConfig::arena_choice`]).
    pub(super) fn arena_choice(&self) -> ArenaChoice {
        TrainConfig::from(self.clone()).arena_choice()
    }

    /// The settings in this layout, if every setting it lacks keeps its
    /// default (the round trip through it gives `c` back).
    pub fn of(c: &TrainConfig) -> Option<TrainConfigV7> {
        let v7 = TrainConfigV7::project(c);
        (TrainConfig::from(v7.clone()) == *c).then_some(v7)
    }
}

impl Default for TrainConfigV7 {
    /// [`TrainConfig::default`] in this layout.
    fn default() -> TrainConfigV7 {
        TrainConfigV7::project(&TrainConfig::default())
    }
}

impl From<TrainConfigV7> for TrainConfig {
    /// The settings; those added since at their defaults.
    #[allow(
        clippy::needless_update,
        reason = "a setting added later takes its default here"
    )]
    fn from(c: TrainConfigV7) -> TrainConfig {
        TrainConfig {
            world: WorldChoices {
                field: c.field,
                sensors: c.sensors,
                arena: c.arena,
                robots: c.robots,
                pucks: c.pucks,
                seed: c.seed,
                noise: c.noise,
                walls: c.walls,
                stuck_limit: c.stuck_limit,
                ..WorldChoices::default()
            },
            steps: c.steps,
            learn: c.learn.with_rules(c.rules),
            output: c.output,
            formation_check: c.formation_check,
            success: c.success,
            innies: c.innies,
            obstacle_discs: c.obstacle_discs,
            select: c.select,
            distil_oc: c.distil_oc,
            epsilon_decay: c.epsilon_decay,
            n_step: c.n_step,
            ..TrainConfig::default()
        }
    }
}

impl StateV7 {
    /// The state in this layout, if its settings are.
    pub fn of(state: &TrainingState) -> Option<StateV7> {
        let config = TrainConfigV7::of(&state.config)?;
        Some(StateV7 {
            learner: QLearnerV7 {
                config: LearnConfigV7::project(state.learner.config()),
                q: state.learner.table().clone(),
                last_signal: state.learner.signal(),
            },
            config,
            field_crc: state.field_crc,
            sim: state.sim.clone(),
            selected: state.selected.clone(),
            pending: state.pending.clone(),
        })
    }

    /// The state; the learner takes the run's rules.
    pub fn into_state(self) -> TrainingState {
        let rules = self.config.rules;
        let l = self.learner;
        TrainingState {
            config: self.config.into(),
            field_crc: self.field_crc,
            sim: self.sim,
            learner: QLearner::saved(l.config.with_rules(rules), l.q, l.last_signal),
            selected: self.selected,
            pending: self.pending,
        }
    }
}
