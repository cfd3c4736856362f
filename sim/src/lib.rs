//! The simulator of policy-guided puck construction by robot swarms.
//!
//! One pipeline stage per module, like rapier's, with the data flowing
//! down: [`world`] (arena, [`body`]s, robots) -> [`physics`] (integration,
//! the [`broadphase`] over a [`grid`], contacts in one canonical order,
//! impulses) -> a [`sensor_model`] (the thesis' [`disc_sensors`], or the
//! robot's [`robot_sensors`]: [`photo_sensors`] and [`pixy_camera`]) ->
//! a [`control`]ler ([`controllers`]: orbital construction, a greedy
//! policy table, random turns) -> turns; with the scalar [`field`]s
//! ([`field_source`], [`letters`]), [`eval`]uation, the learning
//! [`reward`]s and the step loop and episodes in [`simulation`].
//! [`scenario`] builds a simulation from a few choices; [`render`] draws
//! it; [`policy_file`] reads policy blobs.
//!
//! Arenas: the thesis' square, or a screen lying flat with the field on
//! it ([`arena`]: the 75" TV of the thesis' hardware; [`panel`]: the image
//! the screen shows).
//!
//! Everything random comes from a seeded [`SimRng`]; the whole state is
//! serde-serialisable for bit-exact checkpoints. The crate reads field
//! images and policy files, and writes no files.
#![warn(missing_docs)]

pub mod actuation;
pub mod arena;
pub mod bitset;
pub mod body;
pub mod broadphase;
pub mod camera_memory;
pub mod config;
pub mod control;
pub mod controllers;
pub mod disc_sensor_config;
pub mod disc_sensors;
pub mod episode;
pub mod eval;
pub mod field;
pub mod field_source;
pub mod grid;
pub mod letters;
pub mod mixed_sensors;
pub mod noise;
pub mod panel;
pub mod photo_sensors;
pub mod physics;
pub mod pixy_camera;
pub mod policy_file;
pub mod render;
pub mod reward;
pub mod rng;
pub mod robot_noise;
pub mod robot_sensors;
pub mod rounding;
pub mod scenario;
pub mod sensor_model;
pub mod sensor_setup;
pub mod simulation;
pub mod trig;
pub mod validate;
pub mod vec2;
pub mod world;

pub use arena::{ArenaSpec, FieldFit};
pub use body::{Body, Robot, RobotKind};
pub use broadphase::BroadPhase;
pub use config::{EpisodeConfig, PhysicsConfig, SimConfig, SuccessSignal, Thresholds, WorldConfig};
pub use control::{Controller, Perception};
pub use disc_sensor_config::{DiscSensorConfig, ObstacleTargets, SensorDisc};
pub use disc_sensors::DiscSensors;
pub use episode::{EpisodeEnd, EpisodeStart, StepOutcome};
pub use eval::{eval, eval_prime, EvalPrime, EvalTracker};
pub use field::{FieldFrame, FieldLayout, FieldSampling, ScalarField};
pub use field_source::{FieldError, FieldSource};
pub use letters::Letter;
pub use reward::Reward;
pub use rng::SimRng;
pub use robot_sensors::{RobotObservation, RobotSensorConfig, RobotSensors};
pub use scenario::{Arena, ControllerChoice, PreparedScenario, Scenario, ScenarioError};
pub use sensor_model::{Footprint, FootprintKind, SensorModel};
pub use sensor_setup::{SelectedSensors, SensorSetup};
pub use simulation::{Simulation, SimulationState, StepReport, Totals};
pub use validate::ConfigError;
pub use vec2::Vec2;
pub use world::{World, WorldState};
