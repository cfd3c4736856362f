//! The run's state, `DIR/NAME.shape.json` (JSON, written atomically after
//! every step and every generation): what the run is (`run`, so that
//! another run of the same name is refused rather than resumed), the
//! budget turned into generations (`budget`), the start chosen (`start`,
//! its table packed) and every finished generation (`generations`, the
//! search log's entries). A rerun of the same command reads it and goes
//! on from there: the recorded count and start, the finished generations
//! replayed from their scores ([`crate::search::command::run_from`]), so
//! that a resumed run ends with the table an unbroken one does.

use crate::search::command::Generation;
use crate::search::fitness::Score;
use crate::train::TrainConfig;
use anyhow::{bail, Context, Result};
use serde::{Deserialize, Serialize};
use std::path::Path;

/// The state file's format.
pub const FORMAT: u32 = 2;

/// What a run is: a rerun resumes only a state of the same.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct RunKey {
    /// The image as given.
    pub image: String,
    /// Whether it is inverted.
    pub invert: bool,
    /// The world searched in (the field checked, the puck count set).
    pub world: TrainConfig,
    /// The fraction of the step counts (`--scale`).
    pub scale: f64,
    /// `--budget-minutes`.
    pub budget_minutes: f64,
    /// `--generations`, if given.
    pub generations: Option<u64>,
}

/// The budget turned into generations, once, at the run's start.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Budget {
    /// Steps simulated per second of wall time, measured on this machine
    /// for this shape (none with `--generations`).
    pub steps_per_second: Option<f64>,
    /// The search's generations.
    pub generations: u64,
}

/// The start chosen: the best on the shape of the general table and
/// orbital construction distilled into the general table's hasher and
/// into the role hasher.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct StartChoice {
    /// `general`, `oc` or `oc-role`.
    pub chosen: String,
    /// The general table's score on the start worlds.
    pub general: Score,
    /// Distilled orbital construction's score on them.
    pub oc: Score,
    /// Orbital construction distilled into the role hasher's score on them.
    pub oc_role: Score,
    /// The seeds of the start worlds.
    pub seeds: Vec<u64>,
    /// The chosen table's hasher, by name.
    pub hasher: String,
    /// The chosen table, packed.
    pub table: Vec<u8>,
}

/// The state file's contents.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct ShapeState {
    /// [`FORMAT`].
    pub format: u32,
    /// What the run is.
    pub run: RunKey,
    /// The budget.
    pub budget: Budget,
    /// The start, once chosen.
    pub start: Option<StartChoice>,
    /// The finished generations.
    pub generations: Vec<Generation>,
}

impl ShapeState {
    /// The state at `path` if there is one; an error when it is of
    /// another run or cannot be read.
    pub fn resume(path: &Path, run: &RunKey) -> Result<Option<ShapeState>> {
        if !path.exists() {
            return Ok(None);
        }
        let bytes = sim::base::ranges::read_file(path, &sim::base::ranges::CHECKPOINT_FILE)
            .with_context(|| format!("cannot read state file {}", path.display()))?;
        let state: ShapeState = serde_json::from_slice(&bytes)
            .with_context(|| format!("state file {} is not a host shape state", path.display()))?;
        if state.format != FORMAT {
            bail!(
                "state file {}: format {}, expected {FORMAT}",
                path.display(),
                state.format
            );
        }
        let (was, now) = (
            serde_json::to_value(&state.run)?,
            serde_json::to_value(run)?,
        );
        if was != now {
            bail!(
                "state file {} is of another run (another image, world, scale or budget): \
                 remove it to start again, or give another --name",
                path.display()
            );
        }
        Ok(Some(state))
    }

    /// Writes the state to `path` atomically.
    pub fn write(&self, path: &Path) -> Result<()> {
        let json = serde_json::to_vec_pretty(self).context("cannot encode the state")?;
        crate::atomic::write(path, &json)
    }
}
