//! How often training visited each state: `host replay` compares the states
//! a robot met with these, to show where the robot ran on states the policy
//! never learned (their action is the table's default).
//!
//! `--visits FILE` takes either a training checkpoint (`host train`'s
//! `.ckpt`: its Q-table's visit counts) or a JSON file
//! `{"hasher": "original", "visits": [n0, n1, ...]}`, one count per state
//! (`2^bits` of them), a state's visits summed over its actions.

use crate::learn::QTable;
use anyhow::{bail, Context, Result};
use serde::{Deserialize, Serialize};
use shared::{ActionId, State, StateHasher};
use sim::base::ranges;
use std::path::Path;

/// Training visit counts per state of one hasher.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct TrainingVisits {
    hasher: StateHasher,
    visits: Vec<u64>,
}

#[derive(Serialize, Deserialize)]
struct VisitsFile {
    hasher: String,
    visits: Vec<u64>,
}

impl TrainingVisits {
    /// Counts for `hasher`; fails unless there is one per state.
    pub fn new(hasher: StateHasher, visits: Vec<u64>) -> Result<TrainingVisits> {
        if visits.len() != hasher.num_states() {
            bail!(
                "{} visit counts given, but hasher {hasher} has {} states",
                visits.len(),
                hasher.num_states()
            );
        }
        Ok(TrainingVisits { hasher, visits })
    }

    /// A Q-table's visits, summed over each state's actions.
    pub fn from_qtable(q: &QTable) -> TrainingVisits {
        let visits = (0..q.hasher().num_states() as u16)
            .map(|s| {
                (0..q.num_actions() as u8)
                    .map(|a| q.visits(State(s), ActionId(a)))
                    .sum()
            })
            .collect();
        TrainingVisits {
            hasher: q.hasher(),
            visits,
        }
    }

    /// The hasher the counts are for.
    pub fn hasher(&self) -> StateHasher {
        self.hasher
    }

    /// Training visits of `state` (0 outside the hasher's range).
    pub fn of(&self, state: State) -> u64 {
        self.visits.get(state.index()).copied().unwrap_or(0)
    }

    /// Reads a training checkpoint's visit counts, or a visits file; errors
    /// name the file and the problem.
    pub fn read(path: &Path) -> Result<TrainingVisits> {
        // a checkpoint or a small JSON file
        let bytes = ranges::read_file(path, &ranges::CHECKPOINT_FILE)
            .with_context(|| format!("cannot read visits file {}", path.display()))?;
        if bytes.starts_with(&crate::train::checkpoint::MAGIC) {
            let state = crate::train::checkpoint::decode(&bytes)
                .with_context(|| format!("training checkpoint {}", path.display()))?;
            return Ok(TrainingVisits::from_qtable(state.learner.table()));
        }
        let text = String::from_utf8(bytes).with_context(|| {
            format!(
                "visits file {} is neither a training checkpoint nor JSON",
                path.display()
            )
        })?;
        let file: VisitsFile = serde_json::from_str(&text).with_context(|| {
            format!(
                "visits file {} is not valid JSON of the visits format",
                path.display()
            )
        })?;
        let hasher = StateHasher::from_name(&file.hasher).with_context(|| {
            format!(
                "visits file {}: unknown hasher {:?} (expected {})",
                path.display(),
                file.hasher,
                StateHasher::NAMES
            )
        })?;
        TrainingVisits::new(hasher, file.visits)
            .with_context(|| format!("visits file {}", path.display()))
    }

    /// Writes a visits file atomically.
    pub fn write(&self, path: &Path) -> Result<()> {
        let file = VisitsFile {
            hasher: self.hasher.name().to_string(),
            visits: self.visits.clone(),
        };
        let json = serde_json::to_vec(&file).context("cannot encode visit counts")?;
        crate::atomic::write(path, &json)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::learn::QParams;

    #[test]
    fn from_a_qtable_and_through_a_file() {
        let mut q = QTable::new(StateHasher::Bits7, 3, 1.0);
        let params = QParams {
            alpha: 0.1,
            gamma: 0.9,
        };
        q.update(State(5), ActionId(0), 1.0, State(6), params);
        q.update(State(5), ActionId(2), 1.0, State(6), params);
        q.update(State(127), ActionId(1), 1.0, State(0), params);
        let v = TrainingVisits::from_qtable(&q);
        assert_eq!(
            (
                v.of(State(5)),
                v.of(State(127)),
                v.of(State(6)),
                v.of(State(999))
            ),
            (2, 1, 0, 0)
        );

        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("v.json");
        v.write(&path).unwrap();
        assert_eq!(TrainingVisits::read(&path).unwrap(), v);

        std::fs::write(&path, r#"{"hasher": "original", "visits": [1, 2]}"#).unwrap();
        let e = format!("{:#}", TrainingVisits::read(&path).unwrap_err());
        assert!(
            e.contains("v.json") && e.contains("2 visit counts") && e.contains("256 states"),
            "{e}"
        );
        std::fs::write(&path, r#"{"hasher": "twelve", "visits": []}"#).unwrap();
        assert!(format!("{:#}", TrainingVisits::read(&path).unwrap_err()).contains("\"twelve\""));
    }

    #[test]
    fn from_a_training_checkpoint() {
        use crate::train::{checkpoint, TrainConfig, Trainer};
        let config = TrainConfig {
            world: sim::scenario::choices::WorldChoices {
                robots: Some(2),
                pucks: Some(40),
                ..Default::default()
            },
            ..TrainConfig::default()
        };
        let mut trainer = Trainer::start(config, None).unwrap();
        trainer.run(500);
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("run.ckpt");
        checkpoint::save(&path, &trainer.state()).unwrap();
        let v = TrainingVisits::read(&path).unwrap();
        assert_eq!(
            v,
            TrainingVisits::from_qtable(trainer.state().learner.table())
        );
        assert_eq!(
            (0..256).map(|s| v.of(State(s))).sum::<u64>(),
            1000,
            "2 robots x 500 updates"
        );

        let mut bytes = std::fs::read(&path).unwrap();
        bytes.truncate(bytes.len() - 3);
        std::fs::write(&path, &bytes).unwrap();
        let e = format!("{:#}", TrainingVisits::read(&path).unwrap_err());
        assert!(e.contains("run.ckpt"), "{e}");
    }
}
