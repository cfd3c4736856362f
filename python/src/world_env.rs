//! One world of an environment: a simulation driven through the
//! simulator's step API ([`Simulation::advance`], [`Simulation::reset_episode`])
//! with what an environment adds on top: the global reward, truncation at
//! `max_steps`, and who resets an ended episode.

use crate::settings::EnvSettings;
use shared::{ActionId, SensorReading};
use sim::episodes::reward::{robot_credit, Transition};
use sim::episodes::EpisodeEnd;
use sim::scenario::sensor_setup::SelectedSensors;
use sim::scenario::ScenarioError;
use sim::simulation::{Simulation, Totals};

/// What one step of one world produced, besides its observation.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct WorldStep {
    /// The world's reward: every robot's, except with `per-robot`
    /// ([`WorldEnv::robot_rewards`]).
    pub reward: f64,
    /// The episode ended in a formation.
    pub terminated: bool,
    /// The episode was cut: the stuck limit or `max_steps`.
    pub truncated: bool,
    /// This step only reset the world (next-step autoreset): the actions
    /// were ignored and the observation is the new episode's first.
    pub reset: bool,
    /// Eval after the step.
    pub eval: f64,
    /// Steps of the episode so far.
    pub episode_step: u64,
    /// Robot-robot pairs in contact during the step.
    pub robot_contacts: usize,
}

impl WorldStep {
    /// Whether the step ended the episode.
    pub fn ended(&self) -> bool {
        self.terminated || self.truncated
    }
}

/// One world's actions in one step, one per robot, as the caller gave them (checked by
/// the batch before any world steps).
#[derive(Clone, Copy, Debug)]
pub enum WorldActions<'a> {
    /// Indices into the action table, one per robot.
    Discrete(&'a [i64]),
    /// Angular speeds, radians per step, one per robot.
    Continuous(&'a [f64]),
}

/// A simulation and its episode state.
pub struct WorldEnv {
    sim: Simulation<SelectedSensors>,
    turns: Vec<f32>,
    /// Each robot's reward of the last step.
    robot_rewards: Vec<f64>,
    /// The `per-robot` reward's scratch space.
    touching: Vec<u32>,
    /// The reward signal (Eval or Eval') of the world before the next step.
    signal: f64,
    /// The last step ended the episode, and it has not been reset since.
    ended: bool,
    /// Built and neither reset nor stepped since: the first reset starts
    /// the episode the world was built with.
    fresh: bool,
}

impl WorldEnv {
    /// A world seeded with `seed`.
    pub fn new(settings: &EnvSettings, seed: u64) -> Result<WorldEnv, ScenarioError> {
        let sim = settings.prepared.simulation(seed)?;
        let turns = vec![0.0; settings.robots()];
        let mut world = WorldEnv {
            sim,
            turns,
            robot_rewards: vec![0.0; settings.robots()],
            touching: Vec::new(),
            signal: 0.0,
            ended: false,
            fresh: true,
        };
        world.signal = world.measure_signal(settings, None);
        Ok(world)
    }

    /// Starts again from `seed`, as a new world of that seed would, and
    /// counts as its first reset (the seed's first episode has begun).
    pub fn reseed(&mut self, settings: &EnvSettings, seed: u64) -> Result<(), ScenarioError> {
        *self = WorldEnv::new(settings, seed)?;
        self.fresh = false;
        Ok(())
    }

    /// Starts a new episode; the first reset of a world just built starts
    /// the episode its seed laid out (`host run --seed`'s start), every
    /// later one a new episode, stepped or not (`reset(); reset()` gives
    /// two episodes).
    pub fn reset(&mut self, settings: &EnvSettings) {
        if self.fresh {
            self.fresh = false;
        } else {
            self.start_episode(settings);
        }
    }

    /// Resets the world to a new episode's start and reports it as a step
    /// with reward 0.
    pub fn start_episode(&mut self, settings: &EnvSettings) -> WorldStep {
        self.sim.reset_episode();
        self.robot_rewards.fill(0.0);
        self.ended = false;
        self.fresh = false;
        let eval = self.sim.eval();
        self.signal = self.measure_signal(settings, Some(eval));
        WorldStep {
            reset: true,
            eval,
            ..WorldStep::default()
        }
    }

    /// One step with the robots' actions.
    pub fn advance(&mut self, settings: &EnvSettings, actions: WorldActions<'_>) -> WorldStep {
        match actions {
            WorldActions::Discrete(a) => {
                for (turn, &action) in self.turns.iter_mut().zip(a) {
                    // In range: the batch checked every action first.
                    *turn = settings
                        .actions
                        .angular(ActionId(action as u8))
                        .unwrap_or(0.0);
                }
            }
            WorldActions::Continuous(a) => {
                let max = settings.max_turn();
                for (turn, &speed) in self.turns.iter_mut().zip(a) {
                    *turn = (speed as f32).clamp(-max, max);
                }
            }
        }
        self.fresh = false;
        let report = self.sim.advance(&self.turns, true);
        let eval = report.eval.unwrap_or_else(|| self.sim.eval());
        let signal = self.measure_signal(settings, Some(eval));
        let terminated = report.end == Some(EpisodeEnd::Formed);
        let transition = Transition {
            before: self.signal,
            after: signal,
            formed: terminated,
        };
        let reward = settings.reward.reward(transition, settings.gamma);
        if settings.reward.per_robot() {
            robot_credit(
                self.sim.world(),
                self.sim.puck_changes(),
                &mut self.robot_rewards,
                &mut self.touching,
            );
        } else {
            self.robot_rewards.fill(reward);
        }
        self.signal = signal;
        let truncated = !terminated
            && (report.end == Some(EpisodeEnd::Stuck)
                || settings.max_steps.is_some_and(|m| report.episode_step >= m));
        self.ended = terminated || truncated;
        WorldStep {
            reward,
            terminated,
            truncated,
            reset: false,
            eval,
            episode_step: report.episode_step,
            robot_contacts: report.robot_contacts,
        }
    }

    fn measure_signal(&self, settings: &EnvSettings, eval: Option<f64>) -> f64 {
        settings
            .reward
            .signal(self.sim.world(), self.sim.field(), self.sim.config(), eval)
    }

    /// Each robot's reward of the last step (0 after a reset).
    pub fn robot_rewards(&self) -> &[f64] {
        &self.robot_rewards
    }

    /// Whether the last step ended the episode and no reset followed.
    pub fn ended(&self) -> bool {
        self.ended
    }

    /// Every robot's current reading (what the next decision sees).
    pub fn readings(&self) -> &[SensorReading] {
        self.sim.readings()
    }

    /// Counters over the world's life since it was built or reseeded.
    pub fn totals(&self) -> &Totals {
        self.sim.totals()
    }

    /// The simulation, for rendering and inspection.
    pub fn sim(&self) -> &Simulation<SelectedSensors> {
        &self.sim
    }
}
