//! A training run: a [`Simulation`] driven by a [`QLearner`], with any
//! sensor model, and its complete state for checkpoints.

use super::config::{field_label, TrainConfig};
use crate::learn::{QLearner, QTable};
use sim::{EpisodeEnd, ScalarField, SelectedSensors, SensorModel, Simulation, SimulationState, Totals};
use anyhow::{bail, Context, Result};
use crc::{Crc, CRC_32_ISO_HDLC};
use serde::{Deserialize, Serialize};
use shared::{ActionTable, PolicyBlob, Provenance};
use std::sync::Arc;

/// Everything that determines a training run's future: its settings, the
/// simulation (world, both generators, episode step, counters, readings)
/// and the learner (Q-values, visits, previous reward signal). Saving it
/// and resuming gives the same Q-table, counters and world, bit for bit.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct TrainingState {
    /// The settings the run started with.
    pub config: TrainConfig,
    /// CRC-32 of the field the run trained on, to refuse resuming on a
    /// changed image.
    pub field_crc: u32,
    /// The simulation.
    pub sim: SimulationState,
    /// The learner.
    pub learner: QLearner,
}

/// Q-learning on a simulation with sensor model `S`.
pub struct Trainer<S: SensorModel> {
    config: TrainConfig,
    field_crc: u32,
    sim: Simulation<S>,
    learner: QLearner,
}

impl Trainer<SelectedSensors> {
    /// A new run of `config` with the sensor model it names.
    pub fn start(config: TrainConfig, seed_table: Option<QTable>) -> Result<Self> {
        let sim = config.prepare()?.simulation(config.seed).context("invalid simulation settings")?;
        Trainer::new(config, sim, seed_table)
    }

    /// Continues a saved run, the field and sensor model rebuilt from its
    /// settings.
    pub fn restart(state: TrainingState) -> Result<Self> {
        let prepared = state.config.prepare()?;
        let sensors = prepared.sensors().build(&state.sim.config);
        Trainer::resume(state, prepared.field().clone(), sensors)
    }
}

impl<S: SensorModel> Trainer<S> {
    /// A new run on `sim` (built from `config`, [`TrainConfig::prepare`]);
    /// `seed_table` (the thesis' RL2) replaces the initial Q-values and
    /// must have the run's hasher and action count.
    pub fn new(config: TrainConfig, sim: Simulation<S>, seed_table: Option<QTable>) -> Result<Self> {
        config.validate()?;
        let learner = match seed_table {
            Some(q) => QLearner::with_table(config.learn.clone(), q)?,
            None => QLearner::new(config.learn.clone())?,
        };
        let field_crc = field_fingerprint(sim.field());
        Ok(Trainer { config, field_crc, sim, learner })
    }

    /// Continues a saved run on `field`, which must be the field it
    /// trained on.
    pub fn resume(state: TrainingState, field: Arc<ScalarField>, sensors: S) -> Result<Self> {
        state.config.validate()?;
        let crc = field_fingerprint(&field);
        if crc != state.field_crc {
            bail!(
                "the field {} differs from the one the checkpoint trained on (CRC-32 {crc:#010x}, checkpoint {:#010x})",
                state.config.field,
                state.field_crc
            );
        }
        let sim = Simulation::resume(state.sim, field, sensors);
        Ok(Trainer { config: state.config, field_crc: state.field_crc, sim, learner: state.learner })
    }

    /// One step of simulation and learning.
    pub fn step(&mut self) -> Option<EpisodeEnd> {
        self.sim.step(&mut self.learner)
    }

    /// Runs `steps` steps.
    pub fn run(&mut self, steps: u64) {
        self.sim.run(&mut self.learner, steps);
    }

    /// A copy of the complete state, for a checkpoint.
    pub fn state(&self) -> TrainingState {
        TrainingState {
            config: self.config.clone(),
            field_crc: self.field_crc,
            sim: self.sim.snapshot(),
            learner: self.learner.clone(),
        }
    }

    /// The settings.
    pub fn config(&self) -> &TrainConfig {
        &self.config
    }

    /// Where results go; a resumed run may write elsewhere.
    pub fn output_mut(&mut self) -> &mut super::config::OutputConfig {
        &mut self.config.output
    }

    /// The counters since the run began (resumed runs included).
    pub fn totals(&self) -> &Totals {
        self.sim.totals()
    }

    /// The learner.
    pub fn learner(&self) -> &QLearner {
        &self.learner
    }

    /// The simulation.
    pub fn simulation(&self) -> &Simulation<S> {
        &self.sim
    }

    /// The greedy policy as a blob for the firmware, with provenance: the
    /// field, the run's name, the steps so far and the seed.
    pub fn policy(&self) -> Result<PolicyBlob> {
        let c = &self.config;
        let actions = ActionTable::new(&c.learn.actions, self.sim.config().world.forward_speed as f32)
            .context("cannot export the policy")?;
        let provenance = Provenance::new(&field_label(&c.field), &c.name(), self.totals().steps, c.seed)
            .context("cannot export the policy")?;
        PolicyBlob::new(actions, self.learner.table().greedy_policy(), provenance).context("cannot export the policy")
    }
}

/// CRC-32 of a field's size and values.
pub fn field_fingerprint(field: &ScalarField) -> u32 {
    let crc = Crc::<u32>::new(&CRC_32_ISO_HDLC);
    let mut digest = crc.digest();
    digest.update(&(field.width() as u64).to_le_bytes());
    digest.update(&(field.height() as u64).to_le_bytes());
    for y in 0..field.height() as i64 {
        for x in 0..field.width() as i64 {
            digest.update(&field.cell(x, y).to_le_bytes());
        }
    }
    digest.finalize()
}
