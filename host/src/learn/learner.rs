//! The Q-learning controller: one table, every robot's experience.

use super::qtable::{QParams, QTable};
use super::returns::{PendingSteps, WaitingStep};
use anyhow::{bail, Result};
use serde::{Deserialize, Serialize};
use shared::{ActionId, ActionTable, State, StateHasher};
use sim::base::rng::SimRng;
use sim::episodes::reward::{robot_credit, Reward, Transition};
use sim::episodes::{EpisodeEnd, EpisodeStart, StepOutcome};
use sim::{control::Controller, control::Perception};

/// What the learner is and how it learns.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, clap::Args)]
#[serde(default, deny_unknown_fields)]
pub struct LearnConfig {
    /// State hasher: original, original-obstacle, bits7, bits9 (or 8, 10,
    /// 7, 9), original-role or bits9-role (innies and outies apart: the 8
    /// or 9 bits and the robot's role) [default: original].
    #[arg(long, required = false)]
    pub hasher: StateHasherName,
    /// Angular speeds of the actions, radians per step (2 to 4).
    #[arg(skip)]
    pub actions: Vec<f32>,
    /// Learning rate [default: 0.2].
    #[arg(long, required = false)]
    pub alpha: f64,
    /// Discount [default: 0.9].
    #[arg(long, required = false)]
    pub gamma: f64,
    /// Exploration probability [default: 0].
    #[arg(long, required = false)]
    pub epsilon: f64,
    /// Initial Q-value of every (state, action) [default: 1].
    #[arg(long, required = false)]
    pub initial_q: f64,
    /// Reward: reference, thesis, collision, collision-spread, per-robot
    /// (each robot the Eval change of the pucks it touched), success (1 when
    /// the shape forms), success-shaped (success plus potential-based
    /// shaping on Eval with --gamma) [default: reference].
    #[arg(long, required = false)]
    pub reward: Reward,
    /// Greedy choice among every action within this of the best value,
    /// uniformly at random (0: exact ties only, the author's program; its
    /// unused `m_diffThresh` would be 0.001) [default: 0].
    #[arg(long, required = false)]
    pub tie_tolerance: f64,
    /// How one step's updates are applied: sequential (in robot order, each
    /// seeing the ones before: the author's program) or batched (every
    /// robot's TD error from the table as it was before the step)
    /// [default: sequential].
    #[arg(long, required = false)]
    pub updates: Updates,
}

/// How one step's Q-updates are applied ([`LearnConfig::updates`]).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Updates {
    /// In robot order, each seeing the ones before.
    #[default]
    Sequential,
    /// Every TD error from the table before the step, then applied.
    Batched,
}

impl std::str::FromStr for Updates {
    type Err = String;

    fn from_str(s: &str) -> Result<Updates, String> {
        match s {
            "sequential" => Ok(Updates::Sequential),
            "batched" => Ok(Updates::Batched),
            _ => Err(format!(
                "unknown updates {s:?}: expected sequential or batched"
            )),
        }
    }
}

impl std::fmt::Display for Updates {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Updates::Sequential => "sequential",
            Updates::Batched => "batched",
        })
    }
}

/// A [`StateHasher`] as configs and the CLI name it.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(try_from = "String", into = "String")]
pub struct StateHasherName(pub StateHasher);

impl std::fmt::Display for StateHasherName {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.0.name())
    }
}

sim::text_form!(StateHasherName);

impl std::str::FromStr for StateHasherName {
    type Err = String;

    fn from_str(s: &str) -> Result<StateHasherName, String> {
        StateHasher::from_name(s)
            .map(StateHasherName)
            .ok_or_else(|| format!("unknown hasher {s:?}: expected {}", StateHasher::NAMES))
    }
}

impl Default for LearnConfig {
    /// The thesis' Table 1: Original hasher, alpha 0.2, gamma 0.9, epsilon
    /// 0, initial Q 1.0, the four default actions, the reference reward;
    /// the thesis author's program's exact ties and sequential updates.
    fn default() -> LearnConfig {
        let params = QParams::default();
        LearnConfig {
            hasher: StateHasherName(StateHasher::Original),
            actions: ActionTable::DEFAULT_ANGULAR.to_vec(),
            alpha: params.alpha,
            gamma: params.gamma,
            epsilon: 0.0,
            initial_q: 1.0,
            reward: Reward::Reference,
            tie_tolerance: 0.0,
            updates: Updates::Sequential,
        }
    }
}

impl LearnConfig {
    /// Checks ranges before a run; errors name the setting.
    pub fn validate(&self) -> Result<()> {
        if let Err(e) = ActionTable::new(&self.actions, 1.0) {
            bail!("learn.actions = {:?}: {e}", self.actions);
        }
        for (name, value) in [
            ("learn.alpha", self.alpha),
            ("learn.gamma", self.gamma),
            ("learn.epsilon", self.epsilon),
        ] {
            sim::base::ranges::FRACTION.check_as(name, value)?;
        }
        sim::base::ranges::TIE_TOLERANCE.check(self.tie_tolerance)?;
        if !self.initial_q.is_finite() {
            bail!(
                "learn.initial_q = {}: must be a finite number",
                self.initial_q
            );
        }
        Ok(())
    }

    /// The Q-update's parameters.
    pub fn params(&self) -> QParams {
        QParams {
            alpha: self.alpha,
            gamma: self.gamma,
        }
    }
}

/// Tabular Q-learning as a [`Controller`]: each step every robot hashes its
/// reading and picks an epsilon-greedy action from the one shared table;
/// after the physics step every robot's (s, a, r, s') is applied in robot
/// order with the same global reward, each update seeing the ones before.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct QLearner {
    config: LearnConfig,
    q: QTable,
    /// Each robot's (state, action) of the step in flight; refilled by
    /// every decision, so not part of a checkpoint.
    #[serde(skip)]
    chosen: Vec<(State, ActionId)>,
    /// The reward signal (Eval or Eval') of the world before the step in
    /// flight; set at every episode start.
    last_signal: f64,
    /// Batched updates' TD errors of the step in flight.
    #[serde(skip)]
    errors: Vec<f64>,
    /// Each robot's reward of the step in flight, and the `per-robot`
    /// reward's scratch space: derived every step.
    #[serde(skip)]
    rewards: Vec<f64>,
    #[serde(skip)]
    touching: Vec<u32>,
    /// The exploration probability of a decaying schedule, set by the
    /// trainer from the run's step count ([`QLearner::set_exploration`]);
    /// `None` for the config's `epsilon`. Derived, so not part of a
    /// checkpoint.
    #[serde(skip)]
    exploration: Option<f64>,
    /// Rewards per update target: 0 or 1 for one-step Q-learning (the
    /// thesis'), more for n-step returns ([`super::returns`]). A run's
    /// setting, given again on every start and resume
    /// ([`QLearner::with_n_step`]), so not part of the learner's layout.
    #[serde(skip)]
    n_step: usize,
    /// Each robot's steps waiting for their n-step update: a checkpoint
    /// holds them beside the learner ([`QLearner::pending`]), so that the
    /// formats of one-step runs keep their layout.
    #[serde(skip)]
    pending: PendingSteps,
    /// Batched n-step updates of the step in flight.
    #[serde(skip)]
    due: Vec<(WaitingStep, f64)>,
}

impl QLearner {
    /// A learner with every Q-value at `config.initial_q`.
    pub fn new(config: LearnConfig) -> Result<QLearner> {
        config.validate()?;
        let q = QTable::new(config.hasher.0, config.actions.len(), config.initial_q);
        Ok(QLearner::saved(config, q, 0.0))
    }

    /// A learner that starts from another run's table (the thesis' RL2 and
    /// the transfer experiment). The table must have this config's hasher
    /// and action count.
    pub fn with_table(config: LearnConfig, q: QTable) -> Result<QLearner> {
        let mut learner = QLearner::new(config)?;
        if !learner.q.same_shape(&q) {
            bail!(
                "the seed Q-table is for hasher {} with {} actions, but this run uses hasher {} with {} actions",
                q.hasher(),
                q.num_actions(),
                learner.q.hasher(),
                learner.q.num_actions()
            );
        }
        learner.q = q;
        Ok(learner)
    }

    /// This learner with n-step returns of `n` rewards (1: one-step
    /// Q-learning) and the steps a checkpoint left waiting (none for a new
    /// run).
    pub fn with_n_step(mut self, n: usize, pending: PendingSteps) -> QLearner {
        self.n_step = n;
        self.pending = pending;
        self
    }

    /// Each robot's steps waiting for their n-step update (none with
    /// one-step returns).
    pub fn pending(&self) -> &PendingSteps {
        &self.pending
    }

    /// Explores with probability `epsilon` instead of the config's (a
    /// decaying schedule's value at the current step).
    pub fn set_exploration(&mut self, epsilon: f64) {
        self.exploration = Some(epsilon);
    }

    /// The exploration probability in effect.
    pub fn exploration(&self) -> f64 {
        self.exploration.unwrap_or(self.config.epsilon)
    }

    /// The Q-table.
    pub fn table(&self) -> &QTable {
        &self.q
    }

    /// The settings.
    pub fn config(&self) -> &LearnConfig {
        &self.config
    }

    /// The reward signal (Eval, or Eval' for the collision rewards) of the
    /// world after the last step.
    pub fn signal(&self) -> f64 {
        self.last_signal
    }

    /// The learner a checkpoint of an earlier layout saved: its settings,
    /// table and the reward signal of the world after its last step.
    pub fn saved(config: LearnConfig, q: QTable, last_signal: f64) -> QLearner {
        QLearner {
            config,
            q,
            chosen: Vec::new(),
            last_signal,
            errors: Vec::new(),
            rewards: Vec::new(),
            touching: Vec::new(),
            exploration: None,
            n_step: 1,
            pending: PendingSteps::default(),
            due: Vec::new(),
        }
    }
}

impl Controller for QLearner {
    fn decide(&mut self, perception: &Perception<'_>, turns: &mut [f32], rng: &mut SimRng) {
        let hasher = self.q.hasher();
        let epsilon = self.exploration();
        self.chosen.clear();
        for ((reading, turn), robot) in perception
            .readings
            .iter()
            .zip(turns.iter_mut())
            .zip(perception.robots)
        {
            let state = hasher.hash_as(reading, robot.kind.role());
            let action = self
                .q
                .select(state, epsilon, self.config.tie_tolerance, rng);
            *turn = self.config.actions[action.index()];
            self.chosen.push((state, action));
        }
    }

    fn wants_eval_every_step(&self) -> bool {
        true
    }

    fn episode_start(&mut self, start: &EpisodeStart<'_>) {
        self.last_signal = self
            .config
            .reward
            .signal(start.world, start.field, start.config, None);
    }

    fn observe(&mut self, outcome: &StepOutcome<'_>) {
        let signal =
            self.config
                .reward
                .signal(outcome.world, outcome.field, outcome.config, outcome.eval);
        let reward = self.config.reward;
        let step = Transition {
            before: self.last_signal,
            after: signal,
            formed: outcome.end == Some(EpisodeEnd::Formed),
        };
        self.rewards.clear();
        self.rewards.resize(outcome.readings.len(), 0.0);
        if reward.per_robot() {
            robot_credit(
                outcome.world,
                outcome.puck_changes,
                &mut self.rewards,
                &mut self.touching,
            );
        } else {
            self.rewards.fill(reward.reward(step, self.config.gamma));
        }
        let hasher = self.q.hasher();
        let params = self.config.params();
        let robots = outcome.world.robots();
        let next = outcome
            .readings
            .iter()
            .zip(robots)
            .map(|(reading, robot)| hasher.hash_as(reading, robot.kind.role()));
        if self.n_step > 1 {
            self.update_n_step(next, outcome.end.is_some(), params);
            self.last_signal = signal;
            return;
        }
        match self.config.updates {
            Updates::Sequential => {
                for ((&(s, a), s2), &r) in self.chosen.iter().zip(next).zip(&self.rewards) {
                    self.q.update(s, a, r, s2, params);
                }
            }
            Updates::Batched => {
                self.errors.clear();
                for ((&(s, a), s2), &r) in self.chosen.iter().zip(next).zip(&self.rewards) {
                    self.errors.push(self.q.td_error(s, a, r, s2, params));
                }
                for (&(s, a), &error) in self.chosen.iter().zip(&self.errors) {
                    self.q.apply(s, a, error, params);
                }
            }
        }
        self.last_signal = signal;
    }
}

impl QLearner {
    /// The n-step updates a step makes due ([`super::returns`]): each
    /// robot's step waits; the oldest is updated once `n_step` wait, all
    /// of them when the episode `ended`. In robot order, each update
    /// seeing the ones before, or with batched rules all from the table
    /// before the step.
    fn update_n_step(&mut self, next: impl Iterator<Item = State>, ended: bool, params: QParams) {
        let batched = self.config.updates == Updates::Batched;
        self.due.clear();
        for (robot, ((&(state, action), next), &reward)) in
            self.chosen.iter().zip(next).zip(&self.rewards).enumerate()
        {
            let step = WaitingStep {
                state,
                action,
                reward,
            };
            self.pending.record(robot, step);
            for _ in 0..self.pending.due(robot, self.n_step, ended) {
                let Some((step, error)) =
                    self.pending
                        .complete_oldest(robot, next, params.gamma, &self.q)
                else {
                    break;
                };
                if batched {
                    self.due.push((step, error));
                } else {
                    self.q.apply(step.state, step.action, error, params);
                }
            }
        }
        for &(step, error) in &self.due {
            self.q.apply(step.state, step.action, error, params);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;
    use shared::{PolicyTable, SensorReading};
    use sim::{
        base::vec2::Vec2, config::SimConfig, fields::ScalarField, physics::body::RobotKind,
        world::World,
    };

    /// Two robots in the same state with action 0 greedy (Q 2, the other
    /// actions 1), one step with no pucks (the reference reward is -1):
    /// the turns they chose and the learner after the step.
    fn two_robots_one_step(updates: Updates) -> ([f32; 2], QLearner, State) {
        let config = SimConfig::default();
        let robots = [
            (Vec2::new(100.0, 100.0), 0.0, RobotKind::Outie),
            (Vec2::new(300.0, 300.0), 0.0, RobotKind::Outie),
        ];
        let world = World::scene(&config, &robots, &[], 1);
        let field = ScalarField::annulus();
        let mut policy = PolicyTable::new(StateHasher::Original);
        let reading = SensorReading {
            puck_left: true,
            ..SensorReading::default()
        };
        let s = StateHasher::Original.hash(&reading);
        policy.set(s, ActionId(0));
        let learn = LearnConfig {
            updates,
            ..LearnConfig::default()
        };
        let mut learner =
            QLearner::with_table(learn, QTable::from_policy(&policy, 4, 1.0)).unwrap();
        // no pucks: Eval stays 1, so the reference reward is 0 - 1 = -1
        learner.episode_start(&EpisodeStart {
            world: &world,
            field: &field,
            config: &config,
        });
        let readings = [reading; 2];
        let mut turns = [0.0; 2];
        let perception = Perception {
            readings: &readings,
            robots: world.robots(),
            episode_step: 0,
        };
        learner.decide(&perception, &mut turns, &mut SimRng::seed_from_u64(1));
        learner.observe(&StepOutcome {
            episode_step: 1,
            eval: Some(1.0),
            end: None,
            robot_contacts: 0,
            world: &world,
            field: &field,
            config: &config,
            readings: &readings,
            puck_changes: &[],
        });
        (turns, learner, s)
    }

    /// Two robots in the same state take the same action and reach the
    /// same state: the second update sees the first.
    #[test]
    fn updates_are_applied_in_robot_order_each_seeing_the_last() {
        let (turns, learner, s) = two_robots_one_step(Updates::Sequential);
        assert_eq!(turns, [LearnConfig::default().actions[0]; 2]);
        // first: 2 + 0.2 (-1 + 0.9 x 2 - 2) = 1.76; second sees it:
        // 1.76 + 0.2 (-1 + 0.9 x 1.76 - 1.76) = 1.5248
        let q = learner.table();
        assert!(
            (q.value(s, ActionId(0)) - 1.5248).abs() < 1e-12,
            "{}",
            q.value(s, ActionId(0))
        );
        assert_eq!(q.visits(s, ActionId(0)), 2);
        assert_eq!(learner.signal(), 1.0);
    }

    /// The same step as above, batched: both TD errors come from the table
    /// before the step.
    #[test]
    fn batched_updates_take_every_td_error_from_the_table_before_the_step() {
        let (_, learner, s) = two_robots_one_step(Updates::Batched);
        // each error -1 + 0.9 x 2 - 2 = -1.2; 2 + 0.2 (-1.2) x 2 = 1.52
        let q = learner.table().value(s, ActionId(0));
        assert!((q - 1.52).abs() < 1e-12, "{q}");
    }

    #[test]
    fn a_seed_table_of_another_shape_is_refused() {
        let q = QTable::new(StateHasher::Bits9, 4, 1.0);
        let e = QLearner::with_table(LearnConfig::default(), q)
            .unwrap_err()
            .to_string();
        assert!(e.contains("bits9") && e.contains("original"), "{e}");
    }
}
