//! The step loop: decide, act, step physics, sense, evaluate, and end and
//! reset episodes.
//!
//! Sensing happens once per step, after physics: the readings a step's
//! controller sees after acting (s' of a learner's update) are exactly the
//! ones the next step decides on. Only an episode reset senses again, so
//! that the first decision of an episode sees the fresh world; s' of an
//! episode's last step is still the pre-reset world's.
//!
//! [`Simulation`] owns the world, the field (shared, read-only), the sensor
//! model and the counters; the controller is passed to each call so the
//! trainer keeps ownership of its learner. [`SimulationState`] is everything
//! that determines the future: saving it and resuming gives the same
//! trajectory bit for bit.
//!
//! Two ways to drive it: [`Simulation::step`] with a [`Controller`] (the
//! controllers of this crate, the host's learner), or a loop of the
//! caller's own (an external learner, the Python front end): observe
//! [`Simulation::readings`], choose the turns, [`Simulation::advance`], and
//! [`Simulation::reset_episode`] when the [`StepReport`] says the episode
//! ended. Both give the same trajectory for the same turns.
//!
//! Room 9 of the simulator (`lib.rs`): the loop that runs the four stages of a
//! step, checks formations and resets stuck episodes.

use crate::base::rng::SimRng;
use crate::config::validate::ConfigError;
use crate::config::{SimConfig, SuccessSignal};
use crate::control::{Controller, Perception};
use crate::episodes::eval::{eval, eval_prime_of, EvalPrime, EvalTracker, PuckChange};
use crate::episodes::{EpisodeEnd, EpisodeStart, StepOutcome};
use crate::fields::ScalarField;
use crate::sensors::disc::DiscSensors;
use crate::sensors::{SensorMemory, SensorModel};
use crate::world::World;
use rand::SeedableRng;
use serde::{Deserialize, Serialize};
use shared::SensorReading;
use std::sync::Arc;

/// What one [`Simulation::advance`] produced.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StepReport {
    /// Steps of the episode so far, this one included.
    pub episode_step: u64,
    /// Eval after the step: every step if asked for, otherwise only at
    /// formation checks.
    pub eval: Option<f64>,
    /// Set when this step ended the episode.
    pub end: Option<EpisodeEnd>,
    /// Robot-robot pairs in contact during the step.
    pub robot_contacts: usize,
}

/// Counters over the simulation's life.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
pub struct Totals {
    /// Steps run.
    pub steps: u64,
    /// Episodes that formed the shape.
    pub formations: u64,
    /// Episodes reset at the stuck limit.
    pub stuck: u64,
    /// Robot-robot contacts, summed over steps.
    pub robot_contacts: u64,
    /// Sum of Eval at formation checks.
    pub eval_sum: f64,
    /// Number of formation checks.
    pub eval_checks: u64,
}

impl Totals {
    /// Robot-robot collisions per 1000 steps.
    pub fn collisions_per_1000(&self) -> f64 {
        if self.steps == 0 {
            0.0
        } else {
            self.robot_contacts as f64 * 1000.0 / self.steps as f64
        }
    }

    /// Mean Eval over the formation checks (0 before the first).
    pub fn mean_eval(&self) -> f64 {
        if self.eval_checks == 0 {
            0.0
        } else {
            self.eval_sum / self.eval_checks as f64
        }
    }
}

/// Everything that determines a simulation's future.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct SimulationState {
    /// The settings.
    pub config: SimConfig,
    /// Bodies, robots, the world's generator.
    pub world: World,
    /// The generator handed to the controller.
    pub controller_rng: SimRng,
    /// Steps of the current episode.
    pub episode_step: u64,
    /// Counters.
    pub totals: Totals,
    /// Every robot's current reading, which the next decision uses (sensed
    /// after the last step, or after the last reset).
    pub readings: Vec<SensorReading>,
    /// With `episode.stale_eval`: the success signal measured at the last
    /// check (or at the episode's start), which the next check tests.
    /// `None` otherwise.
    pub checked_signal: Option<f64>,
    /// What the sensor model remembers (the robot model's camera links),
    /// as of [`Simulation::snapshot`].
    pub sensor_memory: SensorMemory,
}

/// A running simulation with sensor model `S`.
pub struct Simulation<S: SensorModel = DiscSensors> {
    state: SimulationState,
    field: Arc<ScalarField>,
    sensors: S,
    evaluation: EvalTracker,
    turns: Vec<f32>,
}

/// Added to the seed for the controller's generator, so that it draws a
/// stream independent of the world's.
const CONTROLLER_STREAM: u64 = 0x9E37_79B9_7F4A_7C15;

impl Simulation<DiscSensors> {
    /// A simulation with the reference disc sensors of `config.sensors`.
    pub fn new(
        config: SimConfig,
        field: Arc<ScalarField>,
        seed: u64,
    ) -> Result<Simulation, ConfigError> {
        let sensors = DiscSensors::new(&config.sensors, config.world.robot_radius);
        Simulation::with_sensors(config, field, sensors, seed)
    }
}

impl<S: SensorModel> Simulation<S> {
    /// A simulation with any sensor model; the world's generator is seeded
    /// with `seed`, the controller's with a value derived from it.
    pub fn with_sensors(
        config: SimConfig,
        field: Arc<ScalarField>,
        sensors: S,
        seed: u64,
    ) -> Result<Self, ConfigError> {
        let world = World::new(&config, seed)?;
        let controller_rng = SimRng::seed_from_u64(seed.wrapping_add(CONTROLLER_STREAM));
        let state = SimulationState {
            config,
            world,
            controller_rng,
            episode_step: 0,
            totals: Totals::default(),
            readings: Vec::new(),
            checked_signal: None,
            sensor_memory: SensorMemory::default(),
        };
        Ok(Simulation::resume(state, field, sensors))
    }

    /// Continues from a saved state. Its readings are used as saved; a
    /// state without one reading per robot (a fresh or hand-made one) is
    /// sensed first, and one that tests stale signals but holds none is
    /// measured now.
    pub fn resume(mut state: SimulationState, field: Arc<ScalarField>, mut sensors: S) -> Self {
        let robots = state.world.robots().len();
        sensors.restore(&state.sensor_memory);
        if state.readings.len() != robots {
            state.readings = vec![SensorReading::default(); robots];
            sensors.sense(&state.world, &field, &mut state.readings);
        }
        let evaluation = EvalTracker::new(&state.world, &field, &state.config.thresholds);
        if state.config.episode.stale_eval && state.checked_signal.is_none() {
            let e = evaluation.eval(&state.world, &state.config.thresholds);
            state.checked_signal = Some(success_signal(&state.world, &field, &state.config, e));
        }
        Simulation {
            state,
            field,
            sensors,
            evaluation,
            turns: vec![0.0; robots],
        }
    }

    /// The state (its sensor memory as of the last snapshot; save a
    /// [`Simulation::snapshot`] for a bit-exact resume).
    pub fn state(&self) -> &SimulationState {
        &self.state
    }

    /// The state to save for a bit-exact resume, the sensor model's memory
    /// included.
    pub fn snapshot(&self) -> SimulationState {
        SimulationState {
            sensor_memory: self.sensors.memory(),
            ..self.state.clone()
        }
    }

    /// The world.
    pub fn world(&self) -> &World {
        &self.state.world
    }

    /// The field.
    pub fn field(&self) -> &ScalarField {
        &self.field
    }

    /// The sensor model.
    pub fn sensors(&self) -> &S {
        &self.sensors
    }

    /// The settings.
    pub fn config(&self) -> &SimConfig {
        &self.state.config
    }

    /// Counters so far.
    pub fn totals(&self) -> &Totals {
        &self.state.totals
    }

    /// The readings the next decision uses: sensed after the last step
    /// (or the last reset).
    pub fn readings(&self) -> &[SensorReading] {
        &self.state.readings
    }

    /// The pucks whose distance to the band changed in the last step that
    /// measured Eval, each with its change of Eval (none right after a
    /// reset): what the `per-robot` reward credits the robots with.
    pub fn puck_changes(&self) -> &[PuckChange] {
        self.evaluation.changes()
    }

    /// Eval of the current world.
    pub fn eval(&self) -> f64 {
        eval(
            &self.state.world,
            &self.field,
            &self.state.config.thresholds,
        )
    }

    /// One step driven by `controller`: announce a new episode to it,
    /// decide on the current readings, [`advance`](Self::advance), report
    /// the outcome to it, and [`reset_episode`](Self::reset_episode) if the
    /// episode ended. Returns how the episode ended, if it did.
    pub fn step<C: Controller + ?Sized>(&mut self, controller: &mut C) -> Option<EpisodeEnd> {
        let s = &mut self.state;
        if s.episode_step == 0 {
            controller.episode_start(&EpisodeStart {
                world: &s.world,
                field: &self.field,
                config: &s.config,
            });
        }
        let perception = Perception {
            readings: &s.readings,
            robots: s.world.robots(),
            episode_step: s.episode_step,
        };
        let mut turns = std::mem::take(&mut self.turns);
        controller.decide(&perception, &mut turns, &mut s.controller_rng);
        let report = self.advance(&turns, controller.wants_eval_every_step());
        self.turns = turns;
        let s = &self.state;
        controller.observe(&StepOutcome {
            episode_step: report.episode_step,
            eval: report.eval,
            end: report.end,
            robot_contacts: report.robot_contacts,
            world: &s.world,
            field: &self.field,
            config: &s.config,
            readings: &s.readings,
            puck_changes: self.evaluation.changes(),
        });
        if report.end.is_some() {
            self.reset_episode();
        }
        report.end
    }

    /// One step with the robots' turns chosen by the caller (radians, one
    /// per robot, positive = right): turn and move, sense, evaluate (every
    /// step if `eval_every_step`, otherwise at formation checks), count.
    /// A check tests the success signal (`episode.success_signal`) of the
    /// current world, or with `episode.stale_eval` the one measured at the
    /// previous check; a formation at a check wins over the stuck limit.
    /// The readings after the step are [`readings`](Self::readings). An
    /// ended episode is not reset here: call
    /// [`reset_episode`](Self::reset_episode) before the next step (a
    /// stuck episode that goes on reports `Stuck` again every step).
    pub fn advance(&mut self, turns: &[f32], eval_every_step: bool) -> StepReport {
        let s = &mut self.state;
        s.world.step(turns);
        self.sensors.sense(&s.world, &self.field, &mut s.readings);
        s.episode_step += 1;

        let episode = &s.config.episode;
        let check = s.episode_step % episode.check_interval == 0;
        let eval = (check || eval_every_step).then(|| {
            self.evaluation
                .update(&mut s.world, &self.field, &s.config.thresholds);
            self.evaluation.eval(&s.world, &s.config.thresholds)
        });
        let mut end = None;
        if let (true, Some(e)) = (check, eval) {
            s.totals.eval_sum += e;
            s.totals.eval_checks += 1;
            let signal = success_signal(&s.world, &self.field, &s.config, e);
            let tested = if episode.stale_eval {
                s.checked_signal.replace(signal).unwrap_or(signal)
            } else {
                signal
            };
            if tested > episode.success_eval {
                end = Some(EpisodeEnd::Formed);
            }
        }
        if end.is_none() && s.episode_step >= episode.stuck_limit {
            end = Some(EpisodeEnd::Stuck);
        }
        let robot_contacts = s.world.robot_contacts();
        s.totals.steps += 1;
        s.totals.robot_contacts += robot_contacts as u64;
        match end {
            Some(EpisodeEnd::Formed) => s.totals.formations += 1,
            Some(EpisodeEnd::Stuck) => s.totals.stuck += 1,
            None => {}
        }
        StepReport {
            episode_step: s.episode_step,
            eval,
            end,
            robot_contacts,
        }
    }

    /// Starts a new episode: new start positions and headings drawn from
    /// the world's generator, sensed at once.
    pub fn reset_episode(&mut self) {
        let s = &mut self.state;
        s.world.reset();
        s.episode_step = 0;
        self.evaluation
            .rebuild(&s.world, &self.field, &s.config.thresholds);
        self.sensors.sense(&s.world, &self.field, &mut s.readings);
        if s.config.episode.stale_eval {
            let e = self.evaluation.eval(&s.world, &s.config.thresholds);
            s.checked_signal = Some(success_signal(&s.world, &self.field, &s.config, e));
        }
    }

    /// Runs `steps` steps.
    pub fn run<C: Controller + ?Sized>(&mut self, controller: &mut C, steps: u64) {
        for _ in 0..steps {
            self.step(controller);
        }
    }
}

/// The value a formation check tests: `eval` (the world's Eval), or Eval'.
fn success_signal(world: &World, field: &ScalarField, config: &SimConfig, eval: f64) -> f64 {
    let variant = match config.episode.success_signal {
        SuccessSignal::Eval => return eval,
        SuccessSignal::EvalPrime => EvalPrime::AsWritten,
        SuccessSignal::EvalPrimeSpread => EvalPrime::Spread,
    };
    eval_prime_of(world, field, config, variant)
}
