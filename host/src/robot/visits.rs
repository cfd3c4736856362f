//! How often training visited each state: `host replay` compares the states
//! a robot met with these, to show where the robot ran on states the policy
//! never learned (their action is the table's default).
//!
//! File format (JSON, `--visits FILE`):
//! `{"hasher": "original", "visits": [n0, n1, ...]}`, one count per state
//! (`2^bits` of them), a state's visits summed over its actions. A Q-table
//! gives one with [`TrainingVisits::from_qtable`]; a trainer checkpoint
//! that holds a Q-table plugs in through it.

use crate::learn::QTable;
use anyhow::{bail, Context, Result};
use serde::{Deserialize, Serialize};
use shared::{ActionId, State, StateHasher};
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
            bail!("{} visit counts given, but hasher {hasher} has {} states", visits.len(), hasher.num_states());
        }
        Ok(TrainingVisits { hasher, visits })
    }

    /// A Q-table's visits, summed over each state's actions.
    pub fn from_qtable(q: &QTable) -> TrainingVisits {
        let visits = (0..q.hasher().num_states() as u16)
            .map(|s| (0..q.num_actions() as u8).map(|a| q.visits(State(s), ActionId(a))).sum())
            .collect();
        TrainingVisits { hasher: q.hasher(), visits }
    }

    /// The hasher the counts are for.
    pub fn hasher(&self) -> StateHasher {
        self.hasher
    }

    /// Training visits of `state` (0 outside the hasher's range).
    pub fn of(&self, state: State) -> u64 {
        self.visits.get(state.index()).copied().unwrap_or(0)
    }

    /// Reads a visits file; errors name the file and the problem.
    pub fn read(path: &Path) -> Result<TrainingVisits> {
        let text = std::fs::read_to_string(path).with_context(|| format!("cannot read visits file {}", path.display()))?;
        let file: VisitsFile =
            serde_json::from_str(&text).with_context(|| format!("visits file {} is not valid JSON of the visits format", path.display()))?;
        let hasher = StateHasher::from_name(&file.hasher).with_context(|| {
            format!("visits file {}: unknown hasher {:?} (original, original-obstacle, bits7, bits9)", path.display(), file.hasher)
        })?;
        TrainingVisits::new(hasher, file.visits).with_context(|| format!("visits file {}", path.display()))
    }

    /// Writes a visits file atomically.
    pub fn write(&self, path: &Path) -> Result<()> {
        let file = VisitsFile { hasher: self.hasher.name().to_string(), visits: self.visits.clone() };
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
        let params = QParams { alpha: 0.1, gamma: 0.9 };
        q.update(State(5), ActionId(0), 1.0, State(6), params);
        q.update(State(5), ActionId(2), 1.0, State(6), params);
        q.update(State(127), ActionId(1), 1.0, State(0), params);
        let v = TrainingVisits::from_qtable(&q);
        assert_eq!((v.of(State(5)), v.of(State(127)), v.of(State(6)), v.of(State(999))), (2, 1, 0, 0));

        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("v.json");
        v.write(&path).unwrap();
        assert_eq!(TrainingVisits::read(&path).unwrap(), v);

        std::fs::write(&path, r#"{"hasher": "original", "visits": [1, 2]}"#).unwrap();
        let e = format!("{:#}", TrainingVisits::read(&path).unwrap_err());
        assert!(e.contains("v.json") && e.contains("2 visit counts") && e.contains("256 states"), "{e}");
        std::fs::write(&path, r#"{"hasher": "twelve", "visits": []}"#).unwrap();
        assert!(format!("{:#}", TrainingVisits::read(&path).unwrap_err()).contains("\"twelve\""));
    }
}
