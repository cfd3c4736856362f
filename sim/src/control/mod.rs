//! The controller hook: every robot's angular speed from its sensor reading.
//!
//! One [`Controller`] drives the whole swarm, so a learner can share one
//! table between robots and apply their updates in robot order. Each step
//! the simulation
//! 1. at an episode's first step, calls [`Controller::episode_start`] with
//!    the fresh world;
//! 2. calls [`Controller::decide`] with one [`SensorReading`] per robot,
//!    which writes each robot's angular speed;
//! 3. turns the robots, runs physics and senses again;
//! 4. calls [`Controller::observe`] with the [`StepOutcome`]: the new
//!    readings, Eval when requested or at a formation check, and whether the
//!    episode ended (it is reset right after `observe` returns).
//!
//! Room 8 of the simulator (`lib.rs`), the fourth stage of a step (world -> physics -> sensors -> **control**).

pub mod greedy;
pub mod orbital;
pub mod policy_file;
pub mod random;

use crate::base::rng::SimRng;
use crate::episodes::{EpisodeStart, StepOutcome};
use crate::physics::body::Robot;
use shared::SensorReading;

/// What a controller sees before choosing: every robot's reading and kind.
#[derive(Clone, Copy, Debug)]
pub struct Perception<'a> {
    /// Robot `i`'s reading is `readings[i]`.
    pub readings: &'a [SensorReading],
    /// Robot `i`'s kind and heading.
    pub robots: &'a [Robot],
    /// Steps since the episode began (0 on its first step).
    pub episode_step: u64,
}

/// Chooses the robots' turns; may learn from what happens.
pub trait Controller {
    /// Writes each robot's angular speed, radians per step (positive =
    /// right), into `turns` (one entry per robot). Random choices must be
    /// drawn from `rng`, which the simulation seeds and checkpoints.
    fn decide(&mut self, perception: &Perception<'_>, turns: &mut [f32], rng: &mut SimRng);

    /// Whether [`StepOutcome::eval`] should be computed after every step (a
    /// learner's reward needs it); otherwise only at formation checks.
    fn wants_eval_every_step(&self) -> bool {
        false
    }

    /// Called before the first decision of every episode (the first step
    /// of a simulation and the step after each reset).
    fn episode_start(&mut self, _start: &EpisodeStart<'_>) {}

    /// Called after every physics step, before an ended episode is reset.
    fn observe(&mut self, _outcome: &StepOutcome<'_>) {}
}

/// Forwards every call, so a boxed controller is a controller.
impl<C: Controller + ?Sized> Controller for Box<C> {
    fn decide(&mut self, perception: &Perception<'_>, turns: &mut [f32], rng: &mut SimRng) {
        (**self).decide(perception, turns, rng)
    }

    fn wants_eval_every_step(&self) -> bool {
        (**self).wants_eval_every_step()
    }

    fn episode_start(&mut self, start: &EpisodeStart<'_>) {
        (**self).episode_start(start)
    }

    fn observe(&mut self, outcome: &StepOutcome<'_>) {
        (**self).observe(outcome)
    }
}

/// Forwards every call, so a wrapper can drive a borrowed controller.
impl<C: Controller + ?Sized> Controller for &mut C {
    fn decide(&mut self, perception: &Perception<'_>, turns: &mut [f32], rng: &mut SimRng) {
        (**self).decide(perception, turns, rng)
    }

    fn wants_eval_every_step(&self) -> bool {
        (**self).wants_eval_every_step()
    }

    fn episode_start(&mut self, start: &EpisodeStart<'_>) {
        (**self).episode_start(start)
    }

    fn observe(&mut self, outcome: &StepOutcome<'_>) {
        (**self).observe(outcome)
    }
}
