//! Many worlds of one configuration stepped together, in parallel threads:
//! the engine under every Python environment (a single environment is a
//! batch of one world).
//!
//! Every call checks all of its input before any world moves, so a bad
//! action leaves every world as it was.

use crate::observation::{write_all, ObservationValue, Observations};
use crate::settings::{ActionKind, Autoreset, EnvSettings, ObservationKind};
use crate::world_env::{WorldActions, WorldEnv, WorldStep};
use rayon::prelude::*;
use sim::scenario::ScenarioError;
use std::fmt;

/// Every world's actions of one step, world after world, robot after robot.
#[derive(Clone, Copy, Debug)]
pub enum Actions<'a> {
    /// Action-table indices.
    Discrete(&'a [i64]),
    /// Angular speeds, radians per step.
    Continuous(&'a [f64]),
}

/// Why a step was refused (no world moved).
#[derive(Clone, Debug, PartialEq)]
pub enum StepError {
    /// The actions are of the other kind than the environment's.
    WrongKind {
        /// The environment's kind.
        expected: ActionKind,
    },
    /// Not one action per robot of every world.
    WrongCount {
        /// Worlds x robots.
        expected: usize,
        /// Actions given.
        found: usize,
    },
    /// An action outside the action space.
    Invalid {
        /// Its world.
        world: usize,
        /// Its robot.
        robot: usize,
        /// The value, as given.
        value: String,
        /// What it must be.
        expected: String,
    },
    /// Without autoreset, a world whose episode ended must be reset first.
    Ended {
        /// The world.
        world: usize,
    },
}

impl fmt::Display for StepError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            StepError::WrongKind { expected: ActionKind::Discrete } => {
                f.write_str("actions must be integers (action-table indices) for action=\"discrete\"")
            }
            StepError::WrongKind { expected: ActionKind::Continuous } => {
                f.write_str("actions must be floats (angular speeds) for action=\"continuous\"")
            }
            StepError::WrongCount { expected, found } => {
                write!(f, "actions: expected {expected} actions (one per robot of every world), got {found}")
            }
            StepError::Invalid { world, robot, value, expected } => {
                write!(f, "actions[{world}, {robot}] = {value}: {expected}")
            }
            StepError::Ended { world } => write!(
                f,
                "the episode of world {world} has ended (terminated or truncated): call reset() before step()"
            ),
        }
    }
}

impl std::error::Error for StepError {}

/// What a step returns.
#[derive(Clone, Debug, PartialEq)]
pub struct StepOutput {
    /// Every world's observations after the step.
    pub observations: Observations,
    /// Every world's step.
    pub steps: Vec<WorldStep>,
    /// Every robot's reward, world after world.
    pub robot_rewards: Vec<f64>,
    /// With same-step autoreset, when an episode ended in this step: the
    /// last observations of the worlds whose episode ended (zeros for the
    /// others; the new episode's first are in `observations`).
    pub final_observations: Option<Observations>,
    /// Which worlds' episodes ended with same-step autoreset.
    pub final_mask: Vec<bool>,
}

/// The worlds, their settings and the threads that step them.
pub struct Batch {
    settings: EnvSettings,
    autoreset: Autoreset,
    worlds: Vec<WorldEnv>,
    pool: Option<rayon::ThreadPool>,
}

/// Why a batch cannot be built.
#[derive(Debug)]
pub enum BatchError {
    /// A world cannot be built.
    Scenario(ScenarioError),
    /// The threads cannot be started.
    Threads(rayon::ThreadPoolBuildError),
}

impl fmt::Display for BatchError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            BatchError::Scenario(e) => e.fmt(f),
            BatchError::Threads(e) => write!(f, "cannot start the worker threads: {e}"),
        }
    }
}

impl std::error::Error for BatchError {}

impl Batch {
    /// `num_worlds` worlds seeded `settings.seed`, `seed + 1`, ...;
    /// stepped by `threads` threads (one thread: the caller's).
    pub fn new(
        settings: EnvSettings,
        num_worlds: usize,
        autoreset: Autoreset,
        threads: usize,
    ) -> Result<Batch, BatchError> {
        let worlds = (0..num_worlds as u64)
            .map(|i| WorldEnv::new(&settings, settings.seed.wrapping_add(i)))
            .collect::<Result<Vec<_>, _>>()
            .map_err(BatchError::Scenario)?;
        let threads = threads.min(num_worlds).max(1);
        let pool = if threads > 1 {
            Some(
                rayon::ThreadPoolBuilder::new()
                    .num_threads(threads)
                    .build()
                    .map_err(BatchError::Threads)?,
            )
        } else {
            None
        };
        Ok(Batch {
            settings,
            autoreset,
            worlds,
            pool,
        })
    }

    /// The settings.
    pub fn settings(&self) -> &EnvSettings {
        &self.settings
    }

    /// The worlds.
    pub fn worlds(&self) -> &[WorldEnv] {
        &self.worlds
    }

    /// Threads that step the worlds.
    pub fn threads(&self) -> usize {
        self.pool.as_ref().map_or(1, |p| p.current_num_threads())
    }

    /// Starts every world's next episode; with `seeds` (one per world),
    /// each world starts afresh from its seed instead.
    pub fn reset(&mut self, seeds: Option<&[u64]>) -> Result<Observations, ScenarioError> {
        match seeds {
            Some(seeds) => {
                for (world, &seed) in self.worlds.iter_mut().zip(seeds) {
                    world.reseed(&self.settings, seed)?;
                }
            }
            None => {
                for world in &mut self.worlds {
                    world.reset(&self.settings);
                }
            }
        }
        Ok(self.observations())
    }

    /// Every world's current observations.
    pub fn observations(&self) -> Observations {
        match self.settings.observation {
            ObservationKind::Reading => self.observations_of::<f32>(),
            ObservationKind::State(_) => self.observations_of::<i64>(),
        }
    }

    fn observations_of<T: ObservationValue>(&self) -> Observations {
        let per_world = T::per_robot(self.settings.observation) * self.settings.robots();
        let mut out = vec![T::default(); per_world * self.worlds.len()];
        for (world, chunk) in self.worlds.iter().zip(out.chunks_exact_mut(per_world)) {
            write_all(self.settings.observation, world.readings(), chunk);
        }
        T::wrap(out)
    }

    /// One step of every world: checks every action, then steps the worlds
    /// in parallel (an ended world is reset instead, per the autoreset
    /// mode) and observes them.
    pub fn step(&mut self, actions: Actions<'_>) -> Result<StepOutput, StepError> {
        self.check(actions)?;
        Ok(match self.settings.observation {
            ObservationKind::Reading => self.step_with::<f32>(actions),
            ObservationKind::State(_) => self.step_with::<i64>(actions),
        })
    }

    fn check(&self, actions: Actions<'_>) -> Result<(), StepError> {
        let robots = self.settings.robots();
        let expected = robots * self.worlds.len();
        let found = match (self.settings.action, actions) {
            (ActionKind::Discrete, Actions::Discrete(a)) => {
                let n = self.settings.actions.len() as i64;
                if let Some(i) = a.iter().position(|&x| !(0..n).contains(&x)) {
                    return Err(StepError::Invalid {
                        world: i / robots,
                        robot: i % robots,
                        value: a[i].to_string(),
                        expected: format!("must be an action index in 0..{n}"),
                    });
                }
                a.len()
            }
            (ActionKind::Continuous, Actions::Continuous(a)) => {
                if let Some(i) = a.iter().position(|x| !x.is_finite()) {
                    return Err(StepError::Invalid {
                        world: i / robots,
                        robot: i % robots,
                        value: a[i].to_string(),
                        expected: "must be a finite angular speed (radians per step)".into(),
                    });
                }
                a.len()
            }
            (expected, _) => return Err(StepError::WrongKind { expected }),
        };
        if found != expected {
            return Err(StepError::WrongCount { expected, found });
        }
        if self.autoreset == Autoreset::Off {
            if let Some(world) = self.worlds.iter().position(WorldEnv::ended) {
                return Err(StepError::Ended { world });
            }
        }
        Ok(())
    }

    fn step_with<T: ObservationValue>(&mut self, actions: Actions<'_>) -> StepOutput {
        let robots = self.settings.robots();
        let kind = self.settings.observation;
        let per_world = T::per_robot(kind) * robots;
        let mut observations = vec![T::default(); per_world * self.worlds.len()];
        let mut robot_rewards = vec![0.0; robots * self.worlds.len()];
        let (settings, autoreset) = (&self.settings, self.autoreset);
        type Slot<'w, T> = (&'w mut WorldEnv, (&'w mut [T], &'w mut [f64]));
        let one = |(i, (world, (obs, rewards))): (usize, Slot<'_, T>)| {
            let own = match actions {
                Actions::Discrete(a) => WorldActions::Discrete(&a[i * robots..(i + 1) * robots]),
                Actions::Continuous(a) => {
                    WorldActions::Continuous(&a[i * robots..(i + 1) * robots])
                }
            };
            let step = if world.ended() {
                world.start_episode(settings)
            } else {
                world.advance(settings, own)
            };
            rewards.copy_from_slice(world.robot_rewards());
            let ended_now = autoreset == Autoreset::SameStep && step.ended();
            // A world that ended with same-step autoreset leaves its last
            // observation here; it is moved aside and replaced below.
            write_all(kind, world.readings(), obs);
            (step, ended_now)
        };
        let results: Vec<(WorldStep, bool)> = match &self.pool {
            Some(pool) => pool.install(|| {
                self.worlds
                    .par_iter_mut()
                    .zip(
                        observations
                            .par_chunks_exact_mut(per_world)
                            .zip(robot_rewards.par_chunks_exact_mut(robots)),
                    )
                    .enumerate()
                    .map(one)
                    .collect()
            }),
            None => self
                .worlds
                .iter_mut()
                .zip(
                    observations
                        .chunks_exact_mut(per_world)
                        .zip(robot_rewards.chunks_exact_mut(robots)),
                )
                .enumerate()
                .map(one)
                .collect(),
        };
        let (steps, final_mask): (Vec<WorldStep>, Vec<bool>) = results.into_iter().unzip();
        let final_observations = final_mask.contains(&true).then(|| {
            let mut finals = vec![T::default(); observations.len()];
            let chunks = finals
                .chunks_exact_mut(per_world)
                .zip(observations.chunks_exact_mut(per_world));
            for (((last, obs), world), _) in chunks
                .zip(&mut self.worlds)
                .zip(&final_mask)
                .filter(|(_, &ended)| ended)
            {
                last.copy_from_slice(obs);
                world.start_episode(settings);
                write_all(kind, world.readings(), obs);
            }
            T::wrap(finals)
        });
        StepOutput {
            observations: T::wrap(observations),
            steps,
            robot_rewards,
            final_observations,
            final_mask,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::settings::EnvArgs;

    fn batch(worlds: usize, autoreset: Autoreset, threads: usize, max_steps: Option<i64>) -> Batch {
        let args = EnvArgs {
            robots: Some(3),
            pucks: Some(20),
            max_steps,
            observation: "state".into(),
            ..EnvArgs::default()
        };
        Batch::new(args.settings().unwrap(), worlds, autoreset, threads).unwrap()
    }

    fn actions_of(step: usize, n: usize) -> Vec<i64> {
        (0..n).map(|i| ((step * 7 + i * 3) % 4) as i64).collect()
    }

    #[test]
    fn threads_change_nothing_and_the_worlds_follow_their_seeds() {
        let mut one = batch(4, Autoreset::NextStep, 1, Some(30));
        let mut two = batch(4, Autoreset::NextStep, 2, Some(30));
        for step in 0..100 {
            let a = actions_of(step, 12);
            assert_eq!(
                one.step(Actions::Discrete(&a)).unwrap(),
                two.step(Actions::Discrete(&a)).unwrap()
            );
        }
        let positions = |b: &Batch, w: usize| {
            b.worlds()[w]
                .sim()
                .world()
                .bodies()
                .iter()
                .map(|b| b.pos)
                .collect::<Vec<_>>()
        };
        assert_ne!(
            positions(&one, 0),
            positions(&one, 1),
            "worlds of different seeds differ"
        );
    }

    #[test]
    fn next_step_autoreset_returns_the_end_then_a_reset_step_that_ignores_the_actions() {
        let mut b = batch(1, Autoreset::NextStep, 1, Some(5));
        for step in 1..=5 {
            let out = b.step(Actions::Discrete(&[0, 1, 2])).unwrap();
            assert_eq!(out.steps[0].episode_step, step);
            assert_eq!(out.steps[0].truncated, step == 5);
        }
        let out = b.step(Actions::Discrete(&[3, 3, 3])).unwrap();
        let s = out.steps[0];
        assert!(
            s.reset && !s.ended() && s.reward == 0.0 && s.episode_step == 0,
            "{s:?}"
        );
        assert_eq!(out.observations, b.observations());
        assert_eq!(
            b.step(Actions::Discrete(&[0, 0, 0])).unwrap().steps[0].episode_step,
            1
        );
    }

    #[test]
    fn same_step_autoreset_returns_the_new_episode_with_the_last_observation_beside_it() {
        let mut next = batch(1, Autoreset::NextStep, 1, Some(5));
        let mut same = batch(1, Autoreset::SameStep, 1, Some(5));
        for _ in 0..4 {
            next.step(Actions::Discrete(&[1, 1, 1])).unwrap();
            same.step(Actions::Discrete(&[1, 1, 1])).unwrap();
        }
        let ending = next.step(Actions::Discrete(&[1, 1, 1])).unwrap();
        let out = same.step(Actions::Discrete(&[1, 1, 1])).unwrap();
        assert!(out.steps[0].truncated);
        assert_eq!(out.final_observations.as_ref(), Some(&ending.observations));
        assert_eq!(out.final_mask, [true]);
        let reset = next.step(Actions::Discrete(&[1, 1, 1])).unwrap();
        assert_eq!(out.observations, reset.observations);
    }

    #[test]
    fn bad_actions_are_refused_before_any_world_moves() {
        let mut b = batch(2, Autoreset::Off, 2, Some(2));
        let before = b.observations();
        let e = b.step(Actions::Discrete(&[0, 0, 0, 0, 9, 0])).unwrap_err();
        assert_eq!(
            e.to_string(),
            "actions[1, 1] = 9: must be an action index in 0..4"
        );
        assert!(matches!(
            b.step(Actions::Discrete(&[0, 0])),
            Err(StepError::WrongCount {
                expected: 6,
                found: 2
            })
        ));
        assert!(matches!(
            b.step(Actions::Continuous(&[0.0; 6])),
            Err(StepError::WrongKind { .. })
        ));
        assert_eq!(b.observations(), before);
        assert_eq!(b.worlds()[0].totals().steps, 0);
        b.step(Actions::Discrete(&[0; 6])).unwrap();
        b.step(Actions::Discrete(&[0; 6])).unwrap();
        assert_eq!(
            b.step(Actions::Discrete(&[0; 6])).unwrap_err(),
            StepError::Ended { world: 0 }
        );
        b.reset(None).unwrap();
        assert_eq!(
            b.step(Actions::Discrete(&[0; 6])).unwrap().steps[0].episode_step,
            1
        );
    }

    #[test]
    fn a_reseeded_world_starts_as_a_new_world_of_that_seed() {
        let mut b = batch(1, Autoreset::NextStep, 1, None);
        let fresh = batch(1, Autoreset::NextStep, 1, None).observations();
        for step in 0..50 {
            b.step(Actions::Discrete(&actions_of(step, 3))).unwrap();
        }
        assert_eq!(b.reset(Some(&[1])).unwrap(), fresh);
        let reseeded = layout(&b);
        b.reset(None).unwrap();
        assert_ne!(
            layout(&b),
            reseeded,
            "a reset after a reseed starts the next episode"
        );
    }

    /// Every body's position in world 0.
    fn layout(b: &Batch) -> Vec<(f64, f64)> {
        let world = b.worlds()[0].sim().world();
        world.bodies().iter().map(|b| (b.pos.x, b.pos.y)).collect()
    }

    #[test]
    fn every_reset_starts_a_new_episode_and_the_first_is_the_seeds() {
        let mut b = batch(1, Autoreset::NextStep, 1, None);
        let built = layout(&b);
        b.reset(None).unwrap();
        assert_eq!(layout(&b), built, "the first reset keeps the built world");
        b.reset(None).unwrap();
        let second = layout(&b);
        assert_ne!(second, built, "reset(); reset() gives two episodes");
        b.reset(None).unwrap();
        assert_ne!(layout(&b), second);
    }
}
