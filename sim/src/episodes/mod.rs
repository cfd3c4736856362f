//! What the simulation tells a controller about episodes: the fresh world
//! at an episode's start, each step's outcome, and why an episode ended.
//!
//! Room 7 of the simulator (`lib.rs`): Eval, rewards and the episode events the simulation hands to the control stage.

pub mod eval;
pub mod reward;

use crate::config::SimConfig;
use crate::fields::ScalarField;
use crate::world::World;
use serde::{Deserialize, Serialize};
use shared::SensorReading;

/// Why an episode ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum EpisodeEnd {
    /// Eval exceeded the success threshold at a check.
    Formed,
    /// The stuck limit was reached without success.
    Stuck,
}

/// What a step produced, as the controller sees it.
#[derive(Clone, Copy, Debug)]
pub struct StepOutcome<'a> {
    /// Steps of the episode so far, this one included.
    pub episode_step: u64,
    /// Eval after the step: every step if the controller asked for it,
    /// otherwise only at formation checks.
    pub eval: Option<f64>,
    /// Set when this step ended the episode; the world is reset after the
    /// controller has seen it.
    pub end: Option<EpisodeEnd>,
    /// Robot-robot pairs in contact during the step.
    pub robot_contacts: usize,
    /// The world after the step (before any reset), for other measures
    /// such as Eval'.
    pub world: &'a World,
    /// The field.
    pub field: &'a ScalarField,
    /// The settings (thresholds, Eval' weights).
    pub config: &'a SimConfig,
    /// Every robot's reading sensed after the step (before any reset): the
    /// states the robots reached.
    pub readings: &'a [SensorReading],
    /// With Eval measured this step: the pucks whose distance to the band
    /// changed, each with its change of Eval (the `per-robot` reward's
    /// credit).
    pub puck_changes: &'a [eval::PuckChange],
}

/// The fresh world of an episode, shown to the controller before its first
/// decision (for example to reset a reward's baseline).
#[derive(Clone, Copy, Debug)]
pub struct EpisodeStart<'a> {
    /// The world at the episode's start.
    pub world: &'a World,
    /// The field.
    pub field: &'a ScalarField,
    /// The settings.
    pub config: &'a SimConfig,
}
