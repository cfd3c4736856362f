//! Format 1: the training settings and state as they were laid out before
//! the settings of the thesis author's runs existed (formation checks every
//! N steps on a stale Eval, the success signal, innies, obstacle discs; the
//! simulation's stale signal) and before rectangular and screen arenas
//! (a square arena's side only). Format-1 files are read into format 7's
//! layout ([`super::format7`]); settings and states that use none of the
//! newer settings convert to this layout again, byte for byte what earlier
//! builds wrote (`checkpoint::write_earlier_format`), and an experiment
//! trial's settings that do hash in it (`experiment::plan`).
//!
//! postcard is positional: these structs list the fields of format 1 in
//! their order, the types they share with the newer formats unchanged.
//! Format 1 is format 2 ([`super::format2`]) with fewer settings, so these
//! convert to and from format 2's layout.

use super::config::{FormationCheck, OutputConfig};
use super::format2::{SimConfigV2, SimulationV2, StateV2, TrainConfigV2, WorldConfigV2, WorldV2};
use super::format3::PhysicsConfigV3;
use super::format7::{LearnConfigV7, QLearnerV7, StateV7, TrainConfigV7};
use serde::{Deserialize, Serialize};
use shared::SensorReading;
use sim::config::{EpisodeConfig, SuccessSignal, Thresholds, WorldConfig};
use sim::fields::FieldSampling;
use sim::scenario::sensor_choice::SensorChoice;
use sim::{
    base::rng::SimRng, config::disc_sensors::DiscSensorConfig, config::BroadPhase,
    fields::source::FieldSource, physics::body::Body, physics::body::Robot, simulation::Totals,
};

/// A training state in format 1's layout.
#[derive(Serialize, Deserialize)]
pub struct StateV1 {
    config: TrainConfigV1,
    field_crc: u32,
    sim: SimulationV1,
    learner: QLearnerV7,
}

/// A [`TrainConfigV7`] without the settings added since format 1.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct TrainConfigV1 {
    field: FieldSource,
    sensors: SensorChoice,
    robots: usize,
    pucks: usize,
    steps: u64,
    seed: u64,
    stuck_limit: Option<u64>,
    learn: LearnConfigV7,
    output: OutputConfig,
}

#[derive(Serialize, Deserialize)]
struct SimulationV1 {
    config: SimConfigV1,
    world: WorldV1,
    controller_rng: SimRng,
    episode_step: u64,
    totals: Totals,
    readings: Vec<SensorReading>,
}

/// A square arena's world settings.
#[derive(Clone, Serialize, Deserialize)]
struct WorldConfigV1 {
    arena_size: f64,
    robots: usize,
    innies: usize,
    pucks: usize,
    robot_radius: f64,
    puck_radius: f64,
    forward_speed: f64,
    broad_phase: BroadPhase,
}

impl WorldConfigV1 {
    /// The settings in format 1, if the arena is the reference model's kind:
    /// square, 5 mm per unit, pucks of the default mass, the field over the
    /// whole arena read at the nearest cell.
    fn of(w: &WorldConfigV2) -> Option<WorldConfigV1> {
        let plain = w.arena_width == w.arena_height
            && w.unit_mm == WorldConfig::default().unit_mm
            && w.puck_mass.is_none()
            && w.field_frame.is_none()
            && w.field_sampling == FieldSampling::Nearest;
        plain.then_some(WorldConfigV1 {
            arena_size: w.arena_width,
            robots: w.robots,
            innies: w.innies,
            pucks: w.pucks,
            robot_radius: w.robot_radius,
            puck_radius: w.puck_radius,
            forward_speed: w.forward_speed,
            broad_phase: w.broad_phase,
        })
    }

    fn into_v2(self) -> WorldConfigV2 {
        let d = WorldConfig::default();
        WorldConfigV2 {
            arena_width: self.arena_size,
            arena_height: self.arena_size,
            unit_mm: d.unit_mm,
            robots: self.robots,
            innies: self.innies,
            pucks: self.pucks,
            robot_radius: self.robot_radius,
            puck_radius: self.puck_radius,
            puck_mass: None,
            forward_speed: self.forward_speed,
            broad_phase: self.broad_phase,
            field_frame: None,
            field_sampling: FieldSampling::Nearest,
        }
    }
}

/// A world's state in format 1's layout.
#[derive(Serialize, Deserialize)]
struct WorldV1 {
    config: WorldConfigV1,
    physics: PhysicsConfigV3,
    bodies: Vec<Body>,
    robots: Vec<Robot>,
    steps: u64,
    rng: SimRng,
}

#[derive(Serialize, Deserialize)]
struct SimConfigV1 {
    world: WorldConfigV1,
    physics: PhysicsConfigV3,
    sensors: DiscSensorConfig,
    thresholds: Thresholds,
    episode: EpisodeV1,
}

#[derive(Serialize, Deserialize)]
struct EpisodeV1 {
    success_eval: f64,
    check_interval: u64,
    stuck_limit: u64,
    phi: f64,
    nu: f64,
}

impl TrainConfigV1 {
    /// The settings in format 1, if they use nothing format 1 cannot hold.
    pub fn of(c: &TrainConfigV7) -> Option<TrainConfigV1> {
        TrainConfigV2::of(c).and_then(|c| TrainConfigV1::of_v2(&c))
    }

    fn of_v2(c: &TrainConfigV2) -> Option<TrainConfigV1> {
        let plain = c.formation_check == FormationCheck::default()
            && c.success == SuccessSignal::Eval
            && c.innies.is_none()
            && c.obstacle_discs.is_none();
        plain.then(|| TrainConfigV1 {
            field: c.field.clone(),
            sensors: c.sensors.clone(),
            robots: c.robots,
            pucks: c.pucks,
            steps: c.steps,
            seed: c.seed,
            stuck_limit: c.stuck_limit,
            learn: c.learn.clone(),
            output: c.output.clone(),
        })
    }

    /// The settings with every one format 1 lacks at its default.
    fn into_v2(self) -> TrainConfigV2 {
        let d = TrainConfigV7::default();
        TrainConfigV2 {
            field: self.field,
            sensors: self.sensors,
            robots: self.robots,
            pucks: self.pucks,
            steps: self.steps,
            seed: self.seed,
            stuck_limit: self.stuck_limit,
            learn: self.learn,
            output: self.output,
            formation_check: d.formation_check,
            success: d.success,
            innies: d.innies,
            obstacle_discs: d.obstacle_discs,
        }
    }
}

impl StateV1 {
    /// The state in format 1, if it uses nothing format 1 cannot hold.
    pub fn of(state: &StateV7) -> Option<StateV1> {
        let v2 = StateV2::of(state)?;
        let (s, e) = (&v2.sim, &v2.sim.config.episode);
        let plain_sim =
            !e.stale_eval && e.success_signal == SuccessSignal::Eval && s.checked_signal.is_none();
        plain_sim.then_some(())?;
        let w = &s.world;
        Some(StateV1 {
            config: TrainConfigV1::of_v2(&v2.config)?,
            field_crc: v2.field_crc,
            sim: SimulationV1 {
                config: SimConfigV1 {
                    world: WorldConfigV1::of(&s.config.world)?,
                    physics: s.config.physics.clone(),
                    sensors: s.config.sensors.clone(),
                    thresholds: s.config.thresholds.clone(),
                    episode: EpisodeV1 {
                        success_eval: e.success_eval,
                        check_interval: e.check_interval,
                        stuck_limit: e.stuck_limit,
                        phi: e.phi,
                        nu: e.nu,
                    },
                },
                world: WorldV1 {
                    config: WorldConfigV1::of(&w.config)?,
                    physics: w.physics.clone(),
                    bodies: w.bodies.clone(),
                    robots: w.robots.clone(),
                    steps: w.steps,
                    rng: w.rng.clone(),
                },
                controller_rng: s.controller_rng.clone(),
                episode_step: s.episode_step,
                totals: s.totals.clone(),
                readings: s.readings.clone(),
            },
            learner: v2.learner,
        })
    }

    /// The state, with every setting format 1 lacks at its default.
    pub fn into_v7(self) -> StateV7 {
        let s = self.sim;
        let e = s.config.episode;
        let w = s.world;
        StateV2 {
            config: self.config.into_v2(),
            field_crc: self.field_crc,
            sim: SimulationV2 {
                config: SimConfigV2 {
                    world: s.config.world.into_v2(),
                    physics: s.config.physics,
                    sensors: s.config.sensors,
                    thresholds: s.config.thresholds,
                    episode: EpisodeConfig {
                        success_eval: e.success_eval,
                        check_interval: e.check_interval,
                        stuck_limit: e.stuck_limit,
                        phi: e.phi,
                        nu: e.nu,
                        ..EpisodeConfig::default()
                    },
                },
                world: WorldV2 {
                    config: w.config.into_v2(),
                    physics: w.physics,
                    bodies: w.bodies,
                    robots: w.robots,
                    steps: w.steps,
                    rng: w.rng,
                },
                controller_rng: s.controller_rng,
                episode_step: s.episode_step,
                totals: s.totals,
                readings: s.readings,
                checked_signal: None,
            },
            learner: self.learner,
        }
        .into_v7()
    }
}
