//! Format 3: the training settings and state as they were laid out before
//! the arena's border became a setting (`physics.walls`, the run's
//! `walls`) and before the learner's rules (`rules`: tie tolerance,
//! batched updates). Every format-3 run's border was wall segments. Files
//! are read into format 7's layout ([`super::format7`]); states that use
//! segments and the default rules convert to this layout again, byte for
//! byte what earlier builds wrote (`checkpoint::write_earlier_format`), and
//! an experiment trial's settings that do hash in it (`experiment::plan`).
//!
//! postcard is positional: these structs list format 3's fields in their
//! order, the types they share with the newest format unchanged.
//! [`PhysicsConfigV3`] is also the physics layout of formats 1 and 2; the
//! world's is format 4's ([`WorldConfigV4`]: discs).

use super::config::{FormationCheck, ObstacleDiscs, OutputConfig};
use super::format4::WorldConfigV4;
use super::format7::{LearnConfigV7, LearnerRules, QLearnerV7, StateV7, TrainConfigV7};
use super::selection::{SelectConfig, Selected};
use crate::learn::PendingSteps;
use serde::{Deserialize, Serialize};
use shared::SensorReading;
use sim::base::rng::SimRng;
use sim::config::disc_sensors::DiscSensorConfig;
use sim::config::{EpisodeConfig, PhysicsConfig, SimConfig, SuccessSignal, Thresholds, Walls};
use sim::fields::source::FieldSource;
use sim::physics::body::{Body, Robot};
use sim::scenario::arena_choice::ArenaChoice;
use sim::scenario::sensor_choice::SensorChoice;
use sim::sensors::SensorMemory;
use sim::simulation::{SimulationState, Totals};
use sim::world::{World, WorldState};

/// A training state in format 3's layout.
#[derive(Serialize, Deserialize)]
pub struct StateV3 {
    config: TrainConfigV3,
    field_crc: u32,
    sim: SimulationV3,
    learner: QLearnerV7,
    selected: Option<Selected>,
}

/// A [`TrainConfigV7`] without `walls` and `rules`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TrainConfigV3 {
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
}

impl TrainConfigV3 {
    /// The settings in format 3, if the run's border is wall segments and
    /// its learner keeps the default rules.
    pub fn of(c: &TrainConfigV7) -> Option<TrainConfigV3> {
        let plain = c.walls_in_effect() == Walls::Segments
            && c.rules == LearnerRules::default()
            && c.epsilon_decay.is_none();
        plain.then(|| TrainConfigV3 {
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
        })
    }
}

impl From<TrainConfigV3> for TrainConfigV7 {
    /// The settings with wall segments (said outright where the arena's
    /// own border would be another) and the default rules.
    fn from(c: TrainConfigV3) -> TrainConfigV7 {
        let mut config = TrainConfigV7 {
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
            walls: None,
            rules: LearnerRules::default(),
            epsilon_decay: None,
            n_step: None,
        };
        if config.walls_in_effect() != Walls::Segments {
            config.walls = Some(Walls::Segments);
        }
        config
    }
}

/// A [`PhysicsConfig`] without `walls`: wall segments. The physics layout
/// of formats 1 to 3.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct PhysicsConfigV3 {
    deceleration: f64,
    stop_speed: f64,
    overlap_threshold: f64,
    wall_radius: f64,
}

impl PhysicsConfigV3 {
    /// The constants in this layout, if the border is wall segments.
    pub fn of(p: &PhysicsConfig) -> Option<PhysicsConfigV3> {
        (p.walls == Walls::Segments).then_some(PhysicsConfigV3 {
            deceleration: p.deceleration,
            stop_speed: p.stop_speed,
            overlap_threshold: p.overlap_threshold,
            wall_radius: p.wall_radius,
        })
    }

    /// The constants, with wall segments.
    pub fn into_config(self) -> PhysicsConfig {
        PhysicsConfig {
            deceleration: self.deceleration,
            stop_speed: self.stop_speed,
            overlap_threshold: self.overlap_threshold,
            wall_radius: self.wall_radius,
            walls: Walls::Segments,
        }
    }
}

#[derive(Serialize, Deserialize)]
struct SimConfigV3 {
    world: WorldConfigV4,
    physics: PhysicsConfigV3,
    sensors: DiscSensorConfig,
    thresholds: Thresholds,
    episode: EpisodeConfig,
}

#[derive(Serialize, Deserialize)]
struct WorldV3 {
    config: WorldConfigV4,
    physics: PhysicsConfigV3,
    bodies: Vec<Body>,
    robots: Vec<Robot>,
    steps: u64,
    rng: SimRng,
    seed: u64,
    episode: u64,
    last_turns: Vec<f32>,
}

#[derive(Serialize, Deserialize)]
struct SimulationV3 {
    config: SimConfigV3,
    world: WorldV3,
    controller_rng: SimRng,
    episode_step: u64,
    totals: Totals,
    readings: Vec<SensorReading>,
    checked_signal: Option<f64>,
    sensor_memory: SensorMemory,
}

impl StateV3 {
    /// The state in format 3, if it uses nothing newer: the settings of
    /// [`TrainConfigV3::of`] and wall segments in the simulation.
    pub fn of(state: &StateV7) -> Option<StateV3> {
        let s = &state.sim;
        let w = s.world.state();
        Some(StateV3 {
            config: TrainConfigV3::of(&state.config)?,
            field_crc: state.field_crc,
            sim: SimulationV3 {
                config: SimConfigV3 {
                    world: WorldConfigV4::of(&s.config.world)?,
                    physics: PhysicsConfigV3::of(&s.config.physics)?,
                    sensors: s.config.sensors.clone(),
                    thresholds: s.config.thresholds.clone(),
                    episode: s.config.episode.clone(),
                },
                world: WorldV3 {
                    config: WorldConfigV4::of(&w.config)?,
                    physics: PhysicsConfigV3::of(&w.physics)?,
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

    /// The state, with wall segments and the default rules.
    pub fn into_v7(self) -> StateV7 {
        let s = self.sim;
        let w = s.world;
        let world = World::from_state(WorldState {
            config: w.config.into_config(),
            physics: w.physics.into_config(),
            bodies: w.bodies,
            robots: w.robots,
            steps: w.steps,
            rng: w.rng,
            seed: w.seed,
            episode: w.episode,
            last_turns: w.last_turns,
        });
        StateV7 {
            config: self.config.into(),
            field_crc: self.field_crc,
            sim: SimulationState {
                config: SimConfig {
                    world: s.config.world.into_config(),
                    physics: s.config.physics.into_config(),
                    sensors: s.config.sensors,
                    thresholds: s.config.thresholds,
                    episode: s.config.episode,
                },
                world,
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
