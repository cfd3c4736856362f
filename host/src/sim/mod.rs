//! The simulator, one pipeline stage per module (like rapier's):
//! [`world`] (bodies, arena, robots) -> [`physics`] (integration, the
//! [`broadphase`] over a [`grid`], contacts in one canonical order,
//! impulses) -> [`sensors`] (the thesis' discs, or the robot's
//! [`robot_sensors`]: [`photo_sensors`] and [`pixy_camera`]) -> controller (`crate::controller`) -> actions;
//! with the scalar [`field`]s, [`eval`]uation and the episode loop in
//! [`simulation`]. Everything random comes from a seeded [`SimRng`]; the
//! whole state is serde-serialisable for bit-exact checkpoints.

pub mod bitset;
pub mod body;
pub mod broadphase;
pub mod config;
pub mod eval;
pub mod field;
pub mod grid;
pub mod letters;
pub mod photo_sensors;
pub mod physics;
pub mod pixy_camera;
pub mod robot_sensors;
pub mod sensors;
pub mod simulation;
pub mod trig;
pub mod vec2;
pub mod world;

pub use body::{Body, Robot, RobotKind};
pub use config::{BroadPhase, ConfigError, EpisodeConfig, PhysicsConfig, SimConfig, Thresholds, WorldConfig};
pub use eval::{eval, eval_prime, EvalPrime, EvalTracker};
pub use field::{FieldError, FieldSource, ScalarField};
pub use letters::Letter;
pub use robot_sensors::{RobotObservation, RobotSensorConfig, RobotSensors};
pub use sensors::{DiscSensorConfig, DiscSensors, Footprint, FootprintKind, ObstacleTargets, SensorDisc, SensorModel};
pub use simulation::{EpisodeEnd, EpisodeStart, Simulation, SimulationState, StepOutcome, Totals};
pub use vec2::Vec2;
pub use world::{World, WorldState};

/// The generator behind every random choice: PCG 128/64 (serialisable).
pub type SimRng = rand_pcg::Pcg64;
