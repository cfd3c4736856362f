//! `host train --view`: a training run on the live view's page
//! (`docs/view.md`, "Watching training").
//!
//! Two views. The world the learner learns in is followed at the training
//! loop's chunk boundaries, with the learner's progress (states visited,
//! exploration, the step of the greedy table shown beside it); a browser
//! sees it jump between snapshots, since training runs far faster than a
//! page paints. Beside it, a second world of the run's own settings
//! (seeded with the run's seed mixed with [`VIEW_STREAM`]) acts with the
//! policy `host train` would export at that moment, refreshed every
//! [`REFRESH_STEPS`] training steps without resetting that world. Its own
//! thread steps it at [`GREEDY_STEPS_PER_SECOND`] while a browser watches
//! it and sleeps otherwise; the training world is never stepped by the
//! view, so training gives the same results with and without it.

use super::trainer::Trainer;
use anyhow::{anyhow, Context, Result};
use shared::PolicyBlob;
use sim::control::greedy::GreedyPolicy;
use sim::scenario::sensor_setup::SelectedSensors;
use std::net::SocketAddr;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::{channel, Sender};
use std::sync::Arc;
use std::thread::JoinHandle;
use std::time::{Duration, Instant};
use view::{Companion, Follower, Learning, View};

/// Mixed into the run's seed for the greedy table's world.
pub const VIEW_STREAM: u64 = 0x5E1E_C7ED_0000_0002;

/// Training steps between refreshes of the greedy table's world.
pub const REFRESH_STEPS: u64 = 100_000;

/// Steps a second of the greedy table's world (10x the robot's 20 ms period).
pub const GREEDY_STEPS_PER_SECOND: u64 = 500;

/// The two views of a training run.
pub struct TrainingView {
    learning: Follower,
    greedy: GreedyWorld,
    /// The training step of the policy the greedy world has.
    greedy_step: Option<u64>,
}

/// The greedy table's world, stepped by its own thread.
struct GreedyWorld {
    policies: Sender<PolicyBlob>,
    stop: Arc<AtomicBool>,
    thread: Option<JoinHandle<()>>,
    url: String,
}

impl TrainingView {
    /// Serves the learning world of `trainer` on `bind` (port 0: any free
    /// one) and the greedy table's world on the same IP, any free port.
    pub fn start(bind: SocketAddr, trainer: &Trainer<SelectedSensors>) -> Result<TrainingView> {
        let greedy = GreedyWorld::start(SocketAddr::new(bind.ip(), 0), trainer)?;
        let companion = Companion {
            label: format!(
                "The exported policy acting (refreshed every {REFRESH_STEPS} training steps)"
            ),
            url: greedy.url.clone(),
        };
        let learning = View::follow_beside(bind, trainer.simulation(), Some(companion))
            .map_err(|e| anyhow!(e))
            .context("host train --view")?;
        let mut view = TrainingView {
            learning,
            greedy,
            greedy_step: None,
        };
        view.update(trainer)?;
        Ok(view)
    }

    /// The learning world's page.
    pub fn url(&self) -> String {
        self.learning.url()
    }

    /// The greedy table's world's page.
    pub fn greedy_url(&self) -> &str {
        &self.greedy.url
    }

    /// After a chunk of training: the learning world's frame and, when a
    /// refresh is due, the policy the greedy world acts with.
    pub fn update(&mut self, trainer: &Trainer<SelectedSensors>) -> Result<()> {
        let step = trainer.totals().steps;
        if self
            .greedy_step
            .is_none_or(|last| step >= last + REFRESH_STEPS)
        {
            self.greedy.refresh(trainer.policy()?)?;
            self.greedy_step = Some(step);
        }
        let learner = trainer.learner();
        let table = learner.table();
        self.learning.step_learning(
            trainer.simulation(),
            Learning {
                states_visited: table.states_visited() as u64,
                states_total: table.hasher().num_states() as u64,
                exploration: learner.exploration(),
                greedy_step: self.greedy_step,
            },
        );
        Ok(())
    }
}

impl GreedyWorld {
    fn start(bind: SocketAddr, trainer: &Trainer<SelectedSensors>) -> Result<GreedyWorld> {
        let config = trainer.config();
        let mut sim = config
            .prepare()?
            .simulation(config.world.seed ^ VIEW_STREAM)
            .context("cannot build the greedy table's world")?;
        let follower = View::follow(bind, &sim)
            .map_err(|e| anyhow!(e))
            .context("host train --view")?;
        let url = follower.url();
        let (policies, received) = channel::<PolicyBlob>();
        let stop = Arc::new(AtomicBool::new(false));
        let stopped = stop.clone();
        let thread = std::thread::Builder::new()
            .name("view-greedy".into())
            .spawn(move || {
                let gap = Duration::from_secs(1) / GREEDY_STEPS_PER_SECOND as u32;
                let mut policy: Option<GreedyPolicy> = None;
                let mut next = Instant::now();
                while !stopped.load(Ordering::SeqCst) {
                    if let Some(blob) = received.try_iter().last() {
                        policy = Some(GreedyPolicy::new(blob));
                    }
                    match policy.as_mut() {
                        Some(p) if follower.viewers() > 0 => {
                            sim.step(p);
                            follower.step(&sim);
                            next += gap;
                            let now = Instant::now();
                            if next > now {
                                std::thread::sleep(next - now);
                            } else {
                                next = now;
                            }
                        }
                        _ => {
                            std::thread::sleep(Duration::from_millis(50));
                            next = Instant::now();
                        }
                    }
                }
            })
            .context("cannot start the greedy table's thread")?;
        Ok(GreedyWorld {
            policies,
            stop,
            thread: Some(thread),
            url,
        })
    }

    fn refresh(&self, policy: PolicyBlob) -> Result<()> {
        self.policies
            .send(policy)
            .map_err(|_| anyhow!("the greedy table's world stopped"))
    }
}

impl Drop for GreedyWorld {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::SeqCst);
        if let Some(thread) = self.thread.take() {
            let _ = thread.join();
        }
    }
}
