//! Format 4: the training state as it was laid out before the robots'
//! outline ([`sim::config::robot_shape::RobotShape`]) was a world setting
//! and before decaying exploration (`epsilon_decay`). Files are read into
//! format 7's layout ([`super::format7`]); a state whose robots are discs
//! and whose exploration does not decay converts to this layout (or an
//! older one) again, byte for byte what earlier builds wrote
//! (`checkpoint::write_earlier_format`), and an experiment trial's settings
//! that do hash in it (`experiment::plan`).
//!
//! postcard is positional: these structs list the fields of format 4 in
//! their order, the types they share with the newest format unchanged.
//! [`WorldConfigV4`] is also the world layout of format 4.

use super::config::{FormationCheck, ObstacleDiscs, OutputConfig};
use super::format7::{LearnConfigV7, LearnerRules, QLearnerV7, StateV7, TrainConfigV7};
use super::selection::{SelectConfig, Selected};
use crate::learn::PendingSteps;
use serde::{Deserialize, Serialize};
use shared::SensorReading;
use sim::config::actuation::ActuationNoise;
use sim::config::robot_shape::RobotShape;
use sim::config::{
    EpisodeConfig, PhysicsConfig, SimConfig, SuccessSignal, Thresholds, Walls, WorldConfig,
};
use sim::fields::source::FieldSource;
use sim::fields::{FieldFrame, FieldSampling};
use sim::scenario::arena_choice::ArenaChoice;
use sim::scenario::sensor_choice::SensorChoice;
use sim::sensors::SensorMemory;
use sim::{
    base::rng::SimRng, config::disc_sensors::DiscSensorConfig, config::BroadPhase,
    physics::body::Body, physics::body::Robot, simulation::SimulationState, simulation::Totals,
    world::World, world::WorldState,
};

/// A training state in format 4's layout.
#[derive(Serialize, Deserialize)]
pub struct StateV4 {
    config: TrainConfigV4,
    field_crc: u32,
    sim: SimulationV4,
    learner: QLearnerV7,
    selected: Option<Selected>,
}

/// A [`TrainConfigV7`] without `epsilon_decay`.
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
}

impl TrainConfigV4 {
    /// The settings in format 4, if the run's exploration does not decay.
    pub fn of(c: &TrainConfigV7) -> Option<TrainConfigV4> {
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

impl From<TrainConfigV4> for TrainConfigV7 {
    /// The settings, exploration constant.
    fn from(c: TrainConfigV4) -> TrainConfigV7 {
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
            epsilon_decay: None,
            n_step: None,
        }
    }
}

#[derive(Serialize, Deserialize)]
struct SimulationV4 {
    config: SimConfigV4,
    world: WorldV4,
    controller_rng: SimRng,
    episode_step: u64,
    totals: Totals,
    readings: Vec<SensorReading>,
    checked_signal: Option<f64>,
    sensor_memory: SensorMemory,
}

#[derive(Serialize, Deserialize)]
struct SimConfigV4 {
    world: WorldConfigV4,
    physics: PhysicsConfig,
    sensors: DiscSensorConfig,
    thresholds: Thresholds,
    episode: EpisodeConfig,
}

/// The world settings without the robots' outline: discs. The world
/// layout of formats 3 and 4.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct WorldConfigV4 {
    arena_width: f64,
    arena_height: f64,
    unit_mm: f64,
    robots: usize,
    innies: usize,
    pucks: usize,
    robot_radius: f64,
    puck_radius: f64,
    puck_mass: Option<f64>,
    forward_speed: f64,
    broad_phase: BroadPhase,
    field_frame: Option<FieldFrame>,
    field_sampling: FieldSampling,
    actuation: ActuationNoise,
}

impl WorldConfigV4 {
    /// The settings in format 4, if the robots are discs.
    pub fn of(w: &WorldConfig) -> Option<WorldConfigV4> {
        w.robot_shape.is_disc().then(|| WorldConfigV4 {
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
            actuation: w.actuation.clone(),
        })
    }

    /// The settings, the robots discs.
    pub fn into_config(self) -> WorldConfig {
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
            actuation: self.actuation,
        }
    }
}

#[derive(Serialize, Deserialize)]
struct WorldV4 {
    config: WorldConfigV4,
    physics: PhysicsConfig,
    bodies: Vec<Body>,
    robots: Vec<Robot>,
    steps: u64,
    rng: SimRng,
    seed: u64,
    episode: u64,
    last_turns: Vec<f32>,
}

impl StateV4 {
    /// The state in format 4, if its robots are discs and its
    /// exploration does not decay.
    pub fn of(state: &StateV7) -> Option<StateV4> {
        let s = &state.sim;
        let w = s.world.state();
        Some(StateV4 {
            config: TrainConfigV4::of(&state.config)?,
            field_crc: state.field_crc,
            sim: SimulationV4 {
                config: SimConfigV4 {
                    world: WorldConfigV4::of(&s.config.world)?,
                    physics: s.config.physics.clone(),
                    sensors: s.config.sensors.clone(),
                    thresholds: s.config.thresholds.clone(),
                    episode: s.config.episode.clone(),
                },
                world: WorldV4 {
                    config: WorldConfigV4::of(&w.config)?,
                    physics: w.physics.clone(),
                    bodies: w.bodies.clone(),
                    robots: w.robots.clone(),
                    steps: w.steps,
                    rng: w.rng.clone(),
                    seed: w.seed,
                    episode: w.episode,
                    last_turns: w.last_turns.clone(),
                },
                controller_rng: s.controller_rng.clone(),
                episode_step: s.episode_step,
                totals: s.totals.clone(),
                readings: s.readings.clone(),
                checked_signal: s.checked_signal,
                sensor_memory: s.sensor_memory.clone(),
            },
            learner: state.learner.clone(),
            selected: state.selected.clone(),
        })
    }

    /// The state, its robots discs, its exploration constant.
    pub fn into_v7(self) -> StateV7 {
        let s = self.sim;
        let w = s.world;
        StateV7 {
            config: self.config.into(),
            field_crc: self.field_crc,
            sim: SimulationState {
                config: SimConfig {
                    world: s.config.world.into_config(),
                    physics: s.config.physics,
                    sensors: s.config.sensors,
                    thresholds: s.config.thresholds,
                    episode: s.config.episode,
                },
                world: World::from_state(WorldState {
                    config: w.config.into_config(),
                    physics: w.physics,
                    bodies: w.bodies,
                    robots: w.robots,
                    steps: w.steps,
                    rng: w.rng,
                    seed: w.seed,
                    episode: w.episode,
                    last_turns: w.last_turns,
                }),
                controller_rng: s.controller_rng,
                episode_step: s.episode_step,
                totals: s.totals,
                readings: s.readings,
                checked_signal: s.checked_signal,
                sensor_memory: s.sensor_memory,
            },
            learner: self.learner,
            selected: self.selected,
            pending: PendingSteps::default(),
        }
    }
}
