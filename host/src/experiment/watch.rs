//! `host experiment --view`: the trials, one at a time, on the live view's
//! page (`docs/view.md`, "Watching training"). One server for the whole
//! run: each trial's world replaces the last one's, under a caption naming
//! the experiment, arm and trial, and is shown every
//! [`trial::WATCH_STEPS`](super::trial::WATCH_STEPS) steps, with the
//! learner's progress on a learning arm. The view only looks, so a trial
//! gives the same result with and without it.

use super::trial::Running;
use anyhow::{anyhow, Context, Result};
use std::net::SocketAddr;
use view::{Follower, Learning, View};

/// The page the trials are shown on, started with the first trial.
pub struct TrialView {
    bind: SocketAddr,
    follower: Option<Follower>,
}

impl TrialView {
    /// A view to serve on `bind` (port 0: any free one).
    pub fn new(bind: SocketAddr) -> TrialView {
        TrialView {
            bind,
            follower: None,
        }
    }

    /// A trial starts: its world, under `caption`. The first starts the
    /// server and returns its page's address.
    pub fn start(&mut self, running: &Running, caption: String) -> Result<Option<String>> {
        let sim = running.simulation();
        let url = match &mut self.follower {
            Some(follower) => {
                follower.switch(sim, caption).map_err(|e| anyhow!(e))?;
                None
            }
            None => {
                let mut follower = View::follow(self.bind, sim)
                    .map_err(|e| anyhow!(e))
                    .context("host experiment --view")?;
                follower.switch(sim, caption).map_err(|e| anyhow!(e))?;
                let url = follower.url();
                self.follower = Some(follower);
                Some(url)
            }
        };
        Ok(url)
    }

    /// The trial's world now, with the learner's progress on a learning arm.
    pub fn show(&self, running: &Running) {
        let Some(follower) = &self.follower else {
            return;
        };
        match running {
            Running::Learn(trainer) => {
                let learner = trainer.learner();
                let table = learner.table();
                follower.step_learning(
                    trainer.simulation(),
                    Learning {
                        states_visited: table.states_visited() as u64,
                        states_total: table.hasher().num_states() as u64,
                        exploration: learner.exploration(),
                        greedy_step: None,
                    },
                );
            }
            other => follower.step(other.simulation()),
        }
    }
}
