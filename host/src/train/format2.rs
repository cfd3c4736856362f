//! Format 2: the training settings and state as they were laid out before
//! the noise models (the robots' motion, the robot senses' noise and
//! latency) and before a run's arena and noise were settings: the thesis'
//! square or a rectangular arena of fixed settings, every count given.
//! Format-2 files are read into format 7's layout ([`super::format7`]);
//! settings and states that use nothing newer, but something format 1
//! lacks, convert to this layout again, byte for byte what earlier builds
//! wrote (`checkpoint::write_earlier_format`), and an experiment trial's
//! settings that do hash in it (`experiment::plan`).
//!
//! postcard is positional: these structs list the fields of format 2 in
//! their order, the types they share with the newest format unchanged.
//! The world's seed and episode count are derived on reading, as for
//! format 1 ([`super::format1`]).

use super::config::{FormationCheck, ObstacleDiscs, OutputConfig};
use super::format3::PhysicsConfigV3;
use super::format7::{LearnConfigV7, LearnerRules, QLearnerV7, StateV7, TrainConfigV7};
use crate::learn::PendingSteps;
use serde::{Deserialize, Serialize};
use shared::SensorReading;
use sim::config::actuation::ActuationNoise;
use sim::config::robot_shape::RobotShape;
use sim::config::{EpisodeConfig, SimConfig, SuccessSignal, Thresholds, Walls, WorldConfig};
use sim::fields::{FieldFrame, FieldSampling};
use sim::scenario::arena_choice::ArenaChoice;
use sim::scenario::sensor_choice::SensorChoice;
use sim::scenario::{THESIS_PUCKS, THESIS_ROBOTS};
use sim::{
    base::rng::SimRng, config::disc_sensors::DiscSensorConfig, config::BroadPhase,
    fields::source::FieldSource, physics::body::Body, physics::body::Robot,
    simulation::SimulationState, simulation::Totals, world::World, world::WorldState,
};

/// A training state in format 2's layout.
#[derive(Serialize, Deserialize)]
pub struct StateV2 {
    pub(super) config: TrainConfigV2,
    pub(super) field_crc: u32,
    pub(super) sim: SimulationV2,
    pub(super) learner: QLearnerV7,
}

/// A [`TrainConfigV7`] without the settings added since format 2: the
/// thesis' square, no noise, the counts resolved.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TrainConfigV2 {
    pub(super) field: FieldSource,
    pub(super) sensors: SensorChoice,
    pub(super) robots: usize,
    pub(super) pucks: usize,
    pub(super) steps: u64,
    pub(super) seed: u64,
    pub(super) stuck_limit: Option<u64>,
    pub(super) learn: LearnConfigV7,
    pub(super) output: OutputConfig,
    pub(super) formation_check: FormationCheck,
    pub(super) success: SuccessSignal,
    pub(super) innies: Option<usize>,
    pub(super) obstacle_discs: Option<ObstacleDiscs>,
}

impl TrainConfigV2 {
    /// The settings in format 2, if they run in the thesis' square
    /// without noise, policy selection or distillation.
    pub fn of(c: &TrainConfigV7) -> Option<TrainConfigV2> {
        let plain = c.arena_choice() == ArenaChoice::Thesis
            && c.walls_in_effect() == Walls::Segments
            && c.rules == LearnerRules::default()
            && c.epsilon_decay.is_none()
            && c.noise == 0.0
            && c.select.is_none()
            && c.distil_oc.is_none();
        plain.then(|| TrainConfigV2 {
            field: c.field.clone(),
            sensors: c.sensors.clone(),
            robots: c.robots.unwrap_or(THESIS_ROBOTS),
            pucks: c.pucks.unwrap_or(THESIS_PUCKS),
            steps: c.steps,
            seed: c.seed,
            stuck_limit: c.stuck_limit,
            learn: c.learn.clone(),
            output: c.output.clone(),
            formation_check: c.formation_check,
            success: c.success,
            innies: c.innies,
            obstacle_discs: c.obstacle_discs,
        })
    }
}

impl From<TrainConfigV2> for TrainConfigV7 {
    /// The settings in the thesis' square, without noise, with wall
    /// segments.
    fn from(c: TrainConfigV2) -> TrainConfigV7 {
        let mut config = TrainConfigV7 {
            field: c.field,
            sensors: c.sensors,
            arena: Some(ArenaChoice::Thesis),
            robots: Some(c.robots),
            pucks: Some(c.pucks),
            noise: 0.0,
            steps: c.steps,
            seed: c.seed,
            stuck_limit: c.stuck_limit,
            learn: c.learn,
            output: c.output,
            formation_check: c.formation_check,
            success: c.success,
            innies: c.innies,
            obstacle_discs: c.obstacle_discs,
            select: None,
            distil_oc: None,
            walls: None,
            rules: LearnerRules::default(),
            epsilon_decay: None,
            n_step: None,
        };
        // format 2's runs had wall segments
        if config.walls_in_effect() != Walls::Segments {
            config.walls = Some(Walls::Segments);
        }
        config
    }
}

#[derive(Serialize, Deserialize)]
pub(super) struct SimulationV2 {
    pub(super) config: SimConfigV2,
    pub(super) world: WorldV2,
    pub(super) controller_rng: SimRng,
    pub(super) episode_step: u64,
    pub(super) totals: Totals,
    pub(super) readings: Vec<SensorReading>,
    pub(super) checked_signal: Option<f64>,
}

#[derive(Serialize, Deserialize)]
pub(super) struct SimConfigV2 {
    pub(super) world: WorldConfigV2,
    pub(super) physics: PhysicsConfigV3,
    pub(super) sensors: DiscSensorConfig,
    pub(super) thresholds: Thresholds,
    pub(super) episode: EpisodeConfig,
}

/// The world settings without the actuation noise.
#[derive(Serialize, Deserialize)]
pub(super) struct WorldConfigV2 {
    pub(super) arena_width: f64,
    pub(super) arena_height: f64,
    pub(super) unit_mm: f64,
    pub(super) robots: usize,
    pub(super) innies: usize,
    pub(super) pucks: usize,
    pub(super) robot_radius: f64,
    pub(super) puck_radius: f64,
    pub(super) puck_mass: Option<f64>,
    pub(super) forward_speed: f64,
    pub(super) broad_phase: BroadPhase,
    pub(super) field_frame: Option<FieldFrame>,
    pub(super) field_sampling: FieldSampling,
}

impl WorldConfigV2 {
    pub(super) fn of(w: &WorldConfig) -> Option<WorldConfigV2> {
        (w.actuation.is_none() && w.robot_shape.is_disc()).then_some(WorldConfigV2 {
            arena_width: w.arena_width,
            arena_height: w.arena_height,
            unit_mm: w.unit_mm,
            robots: w.robots,
            innies: w.innies,
            pucks: w.pucks,
            robot_radius: w.robot_radius,
            puck_radius: w.puck_radius,
            puck_mass: w.puck_mass,
            forward_speed: w.forward_speed,
            broad_phase: w.broad_phase,
            field_frame: w.field_frame,
            field_sampling: w.field_sampling,
        })
    }

    pub(super) fn into_config(self) -> WorldConfig {
        WorldConfig {
            arena_width: self.arena_width,
            arena_height: self.arena_height,
            unit_mm: self.unit_mm,
            robots: self.robots,
            innies: self.innies,
            pucks: self.pucks,
            robot_radius: self.robot_radius,
            robot_shape: RobotShape::Disc,
            puck_radius: self.puck_radius,
            puck_mass: self.puck_mass,
            forward_speed: self.forward_speed,
            broad_phase: self.broad_phase,
            field_frame: self.field_frame,
            field_sampling: self.field_sampling,
            actuation: ActuationNoise::NONE,
        }
    }
}

#[derive(Serialize, Deserialize)]
pub(super) struct WorldV2 {
    pub(super) config: WorldConfigV2,
    pub(super) physics: PhysicsConfigV3,
    pub(super) bodies: Vec<Body>,
    pub(super) robots: Vec<Robot>,
    pub(super) steps: u64,
    pub(super) rng: SimRng,
}

/// The episodes a run has begun after its first: one per episode ended.
fn episodes(totals: &Totals) -> u64 {
    totals.formations + totals.stuck
}

impl StateV2 {
    /// The state in format 2, if it uses nothing newer: the config of
    /// [`TrainConfigV2::of`], no motion noise, no sensor memory, the world
    /// seeded with the run's seed and one episode begun per episode ended.
    pub fn of(state: &StateV7) -> Option<StateV2> {
        let s = &state.sim;
        let w = s.world.state();
        let config = TrainConfigV2::of(&state.config)?;
        let plain = state.selected.is_none()
            && s.sensor_memory.cameras.is_empty()
            && w.seed == state.config.seed
            && w.episode == episodes(&s.totals)
            && w.last_turns.is_empty();
        plain.then_some(())?;
        Some(StateV2 {
            config,
            field_crc: state.field_crc,
            sim: SimulationV2 {
                config: SimConfigV2 {
                    world: WorldConfigV2::of(&s.config.world)?,
                    physics: PhysicsConfigV3::of(&s.config.physics)?,
                    sensors: s.config.sensors.clone(),
                    thresholds: s.config.thresholds.clone(),
                    episode: s.config.episode.clone(),
                },
                world: WorldV2 {
                    config: WorldConfigV2::of(&w.config)?,
                    physics: PhysicsConfigV3::of(&w.physics)?,
                    bodies: w.bodies.clone(),
                    robots: w.robots.clone(),
                    steps: w.steps,
                    rng: w.rng.clone(),
                },
                controller_rng: s.controller_rng.clone(),
                episode_step: s.episode_step,
                totals: s.totals.clone(),
                readings: s.readings.clone(),
                checked_signal: s.checked_signal,
            },
            learner: state.learner.clone(),
        })
    }

    /// The state, with what format 2 lacks derived as [`StateV2::of`]
    /// requires it.
    pub fn into_v7(self) -> StateV7 {
        let (c, s) = (self.config, self.sim);
        let (seed, episode) = (c.seed, episodes(&s.totals));
        let w = s.world;
        StateV7 {
            config: c.into(),
            field_crc: self.field_crc,
            sim: SimulationState {
                config: SimConfig {
                    world: s.config.world.into_config(),
                    physics: s.config.physics.into_config(),
                    sensors: s.config.sensors,
                    thresholds: s.config.thresholds,
                    episode: s.config.episode,
                },
                world: World::from_state(WorldState {
                    config: w.config.into_config(),
                    physics: w.physics.into_config(),
                    bodies: w.bodies,
                    robots: w.robots,
                    steps: w.steps,
                    rng: w.rng,
                    seed,
                    episode,
                    last_turns: Vec::new(),
                }),
                controller_rng: s.controller_rng,
                episode_step: s.episode_step,
                totals: s.totals,
                readings: s.readings,
                checked_signal: s.checked_signal,
                sensor_memory: Default::default(),
            },
            learner: self.learner,
            selected: None,
            pending: PendingSteps::default(),
        }
    }
}
