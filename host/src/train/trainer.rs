//! A training run: a [`Simulation`] driven by a [`QLearner`], with any
//! sensor model, and its complete state for checkpoints.

use super::config::{field_label, TrainConfig, DECAY_PERIOD};
use super::distil::distil_orbital;
use super::selection::{Evaluation, Selected};
use crate::learn::{PendingSteps, QLearner, QTable};
use anyhow::{bail, Context, Result};
use crc::{Crc, CRC_32_ISO_HDLC};
use serde::{Deserialize, Serialize};
use shared::{ActionTable, PolicyBlob, PolicyTable, Provenance};
use sim::{
    episodes::EpisodeEnd, fields::ScalarField, scenario::sensor_setup::SelectedSensors,
    sensors::SensorModel, simulation::Simulation, simulation::SimulationState, simulation::Totals,
};
use std::sync::Arc;

/// Everything that determines a training run's future: its settings, the
/// simulation (world, both generators, episode step, counters, readings)
/// the learner (Q-values, visits, previous reward signal) and, with policy
/// selection, the best policy so far. Saving it and resuming gives the
/// same Q-table, counters, world and policy, bit for bit.
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
    /// With policy selection: the best policy evaluated so far.
    pub selected: Option<Selected>,
    /// With n-step returns: each robot's steps waiting for their update
    /// (none with one-step returns).
    pub pending: PendingSteps,
}

/// Q-learning on a simulation with sensor model `S`.
pub struct Trainer<S: SensorModel> {
    config: TrainConfig,
    field_crc: u32,
    sim: Simulation<S>,
    learner: QLearner,
    /// With policy selection: the evaluation world (of the run's settings
    /// and configured sensor model) and the best policy so far.
    evaluation: Option<Evaluation>,
    selected: Option<Selected>,
}

impl Trainer<SelectedSensors> {
    /// A new run of `config` with the sensor model it names, from
    /// `seed_table` or, with `distil_oc`, from orbital construction.
    pub fn start(config: TrainConfig, seed_table: Option<QTable>) -> Result<Self> {
        let seed_table = match (config.distil_oc, seed_table) {
            (Some(_), Some(_)) => bail!(
                "distil_oc and --init-from both give the table the run starts from: choose one"
            ),
            (Some(steps), None) => {
                let table = distil_orbital(&config, steps)?;
                Some(QTable::from_policy(
                    &table,
                    config.learn.actions.len(),
                    config.learn.initial_q,
                ))
            }
            (None, table) => table,
        };
        // the scenario's errors say what kind of setting is wrong
        let sim = config.prepare()?.simulation(config.world.seed)?;
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
    pub fn new(
        config: TrainConfig,
        sim: Simulation<S>,
        seed_table: Option<QTable>,
    ) -> Result<Self> {
        config.validate()?;
        let learner = match seed_table {
            Some(q) => QLearner::with_table(config.learn.clone(), q)?,
            None => QLearner::new(config.learn.clone())?,
        }
        .with_n_step(config.rewards_per_update(), PendingSteps::default());
        let field_crc = field_fingerprint(sim.field());
        let evaluation = evaluation_of(&config)?;
        let mut trainer = Trainer {
            config,
            field_crc,
            sim,
            learner,
            evaluation,
            selected: None,
        };
        trainer.greedy_policy()?;
        // with selection the starting policy is evaluated too (step 0)
        trainer.evaluate_if_due();
        Ok(trainer)
    }

    /// Continues a saved run on `field`, which must be the field it
    /// trained on.
    pub fn resume(state: TrainingState, field: Arc<ScalarField>, sensors: S) -> Result<Self> {
        state.config.validate()?;
        let crc = field_fingerprint(&field);
        if crc != state.field_crc {
            bail!(
                "the field {} differs from the one the checkpoint trained on (CRC-32 {crc:#010x}, checkpoint {:#010x})",
                state.config.world.field,
                state.field_crc
            );
        }
        let sim = Simulation::resume(state.sim, field, sensors);
        let evaluation = evaluation_of(&state.config)?;
        let learner = state
            .learner
            .with_n_step(state.config.rewards_per_update(), state.pending);
        let (config, field_crc, selected) = (state.config, state.field_crc, state.selected);
        let trainer = Trainer {
            config,
            field_crc,
            sim,
            learner,
            evaluation,
            selected,
        };
        trainer.greedy_policy()?;
        Ok(trainer)
    }

    /// With decaying exploration: sets the learner's exploration for the
    /// current step.
    fn explore_as_scheduled(&mut self) {
        if self.config.epsilon_decay.is_some() {
            let epsilon = self.config.exploration_at(self.totals().steps);
            self.learner.set_exploration(epsilon);
        }
    }

    /// One step of simulation and learning (and an evaluation when due).
    pub fn step(&mut self) -> Option<EpisodeEnd> {
        self.explore_as_scheduled();
        let end = self.sim.step(&mut self.learner);
        self.evaluate_if_due();
        end
    }

    /// Runs `steps` steps.
    pub fn run(&mut self, mut steps: u64) {
        while steps > 0 {
            let step = self.totals().steps;
            let mut chunk = match &self.evaluation {
                Some(e) => e.steps_to_next(step).min(steps),
                None => steps,
            };
            if self.config.epsilon_decay.is_some() {
                chunk = chunk.min(DECAY_PERIOD - step % DECAY_PERIOD);
            }
            self.explore_as_scheduled();
            self.sim.run(&mut self.learner, chunk);
            self.evaluate_if_due();
            steps -= chunk;
        }
    }

    /// With selection, at an evaluation step: evaluates the greedy policy
    /// and keeps it if it formed more than the best so far.
    fn evaluate_if_due(&mut self) {
        let step = self.totals().steps;
        let Some(evaluation) = self.evaluation.as_ref().filter(|e| e.due(step)) else {
            return;
        };
        // a run starts only if its policy exports (`new`, `resume`)
        let Ok(policy) = self.greedy_policy() else {
            return;
        };
        let packed = policy.table().packed().to_vec();
        let formations = evaluation.formations(policy);
        if self
            .selected
            .as_ref()
            .is_none_or(|best| formations > best.formations)
        {
            self.selected = Some(Selected {
                step,
                formations,
                packed,
            });
        }
    }

    /// With selection: the best policy so far.
    pub fn selected(&self) -> Option<&Selected> {
        self.selected.as_ref()
    }

    /// A copy of the complete state, for a checkpoint.
    pub fn state(&self) -> TrainingState {
        TrainingState {
            config: self.config.clone(),
            field_crc: self.field_crc,
            sim: self.sim.snapshot(),
            learner: self.learner.clone(),
            selected: self.selected.clone(),
            pending: self.learner.pending().clone(),
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

    /// The run's policy as a blob for the firmware, recording the sensor
    /// model and arena it was trained for: with selection the best
    /// evaluated so far (the current greedy one before the first
    /// evaluation; one action per state, as selection evaluated it), else
    /// each state's best actions now ([`QTable::best_sets`] with the run's
    /// tie tolerance: the learner's own choice among equal actions, which
    /// the robot samples). Its provenance names the field, the run's name,
    /// the training steps it had and the seed.
    pub fn policy(&self) -> Result<PolicyBlob> {
        let hasher = self.learner.table().hasher();
        let blob = match self.selected.as_ref().filter(|_| self.evaluation.is_some()) {
            Some(best) => {
                let table = best
                    .table(hasher)
                    .context("the selected policy does not fit the run's hasher")?;
                self.blob(table, best.step)?
            }
            None => {
                let sets = self
                    .learner
                    .table()
                    .best_sets(self.config.learn.tie_tolerance);
                let (actions, provenance) = self.blob_parts(self.totals().steps)?;
                PolicyBlob::with_sets(actions, sets, provenance)
                    .context("cannot export the policy")?
            }
        };
        Ok(blob.with_trained_for(self.config.trained_for()))
    }

    /// The current greedy policy as a blob, ties broken towards the lowest
    /// action (what policy selection evaluates).
    pub fn greedy_policy(&self) -> Result<PolicyBlob> {
        self.blob(self.learner.table().greedy_policy(), self.totals().steps)
    }

    fn blob(&self, table: PolicyTable, steps: u64) -> Result<PolicyBlob> {
        let (actions, provenance) = self.blob_parts(steps)?;
        PolicyBlob::new(actions, table, provenance).context("cannot export the policy")
    }

    /// The actions and provenance of an exported blob.
    fn blob_parts(&self, steps: u64) -> Result<(ActionTable, Provenance)> {
        let c = &self.config;
        let actions = ActionTable::new(
            &c.learn.actions,
            self.sim.config().world.forward_speed as f32,
        )
        .context("cannot export the policy")?;
        let provenance =
            Provenance::new(&field_label(&c.world.field), &c.name(), steps, c.world.seed)
                .context("cannot export the policy")?;
        Ok((actions, provenance))
    }
}

/// The evaluation world of a run with selection.
fn evaluation_of(config: &TrainConfig) -> Result<Option<Evaluation>> {
    config
        .select
        .map(|select| Evaluation::new(select, &config.prepare()?, config.world.seed))
        .transpose()
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
