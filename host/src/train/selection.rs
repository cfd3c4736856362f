//! Policy selection (`[select]`): on-line Q-learning keeps changing its
//! table, and the greedy policy of the last step is often not the best one
//! the run passed through (a frozen table can lose most of what the
//! learning run formed). With selection, every `every` steps the current
//! greedy policy drives a fresh evaluation world of the run's own settings
//! for `steps` steps without learning; the policy that formed the most
//! shapes (the earliest on a tie) is the run's policy.
//!
//! The evaluation world is seeded with the run's seed mixed with
//! [`EVALUATION_STREAM`], the same world at every evaluation, so that
//! policies are compared on equal terms and a run selects the same policy
//! every time; its generators are not the training world's, which runs on
//! exactly as without selection. Report a selected policy's figures on
//! other seeds (the robustness experiments do).

use anyhow::{Context, Result};
use serde::{Deserialize, Serialize};
use shared::{PolicyBlob, PolicyTable, StateHasher};
use sim::control::greedy::GreedyPolicy;
use sim::scenario::sensor_setup::SensorSetup;
use sim::{
    fields::ScalarField, scenario::PreparedScenario, simulation::Simulation,
    simulation::SimulationState,
};
use std::sync::Arc;

/// Mixed into the run's seed for the evaluation world.
pub const EVALUATION_STREAM: u64 = 0x5E1E_C7ED_0000_0001;

/// `select = { every = 1_000_000, steps = 200_000 }`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize, clap::Args)]
#[serde(deny_unknown_fields)]
pub struct SelectConfig {
    /// Policy selection: every N training steps (counted over the whole
    /// run), evaluate the greedy policy on a fixed evaluation world and keep
    /// the best as the run's policy (docs/training.md).
    #[arg(
        long = "select-every",
        id = "select_every",
        value_name = "STEPS",
        requires = "select_steps",
        required = false
    )]
    pub every: u64,
    /// Steps of each evaluation of --select-every.
    #[arg(
        long = "select-steps",
        id = "select_steps",
        value_name = "STEPS",
        requires = "select_every",
        required = false
    )]
    pub steps: u64,
}

/// The best policy evaluated so far.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
pub struct Selected {
    /// Training steps when it was evaluated.
    pub step: u64,
    /// Formations in its evaluation.
    pub formations: u64,
    /// Its packed table ([`PolicyTable::packed`]).
    pub packed: Vec<u8>,
}

impl Selected {
    /// Its table.
    pub fn table(&self, hasher: StateHasher) -> Option<PolicyTable> {
        PolicyTable::from_packed(hasher, &self.packed)
    }
}

/// The evaluation world of a run with selection, at its start.
pub struct Evaluation {
    select: SelectConfig,
    start: SimulationState,
    field: Arc<ScalarField>,
    sensors: SensorSetup,
}

impl Evaluation {
    /// The evaluation of a run of `prepared`'s settings seeded with `seed`.
    pub fn new(select: SelectConfig, prepared: &PreparedScenario, seed: u64) -> Result<Evaluation> {
        if select.every == 0 || select.steps == 0 {
            anyhow::bail!(
                "select = {{ every = {}, steps = {} }}: both must be positive",
                select.every,
                select.steps
            );
        }
        let sim = prepared
            .simulation(seed ^ EVALUATION_STREAM)
            .context("cannot build the evaluation world")?;
        Ok(Evaluation {
            select,
            start: sim.snapshot(),
            field: prepared.field().clone(),
            sensors: prepared.sensors().clone(),
        })
    }

    /// Whether the run evaluates after training step `step`.
    pub fn due(&self, step: u64) -> bool {
        step % self.select.every == 0
    }

    /// Training steps from `step` to the next evaluation.
    pub fn steps_to_next(&self, step: u64) -> u64 {
        self.select.every - step % self.select.every
    }

    /// Formations of `policy` driving the evaluation world for its steps.
    pub fn formations(&self, policy: PolicyBlob) -> u64 {
        let sensors = self.sensors.build(&self.start.config);
        let mut sim = Simulation::resume(self.start.clone(), self.field.clone(), sensors);
        sim.run(&mut GreedyPolicy::new(policy), self.select.steps);
        sim.totals().formations
    }
}
