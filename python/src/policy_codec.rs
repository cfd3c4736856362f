//! A greedy table learned in Python as a policy blob (`shared`'s encoder),
//! and a blob's contents for Python.

use crate::settings::ArgumentError;
use shared::{
    ActionId, ActionSets, ActionTable, PolicyBlob, PolicyTable, Provenance, State, StateHasher,
    TrainedFor,
};

/// What a policy blob carries besides its table: the hasher, the actions
/// and where it came from.
#[derive(Clone, Debug, PartialEq)]
pub struct PolicyHeader<'a> {
    /// A hasher name (`original`, `original-obstacle`, `bits7`, `bits9`).
    pub hasher: &'a str,
    /// The actions' angular speeds, radians per step.
    pub actions: &'a [f32],
    /// The forward speed, units per step.
    pub forward_speed: f32,
    /// The field trained on.
    pub field: &'a str,
    /// A free-text name.
    pub name: &'a str,
    /// Steps of training.
    pub trainer_steps: u64,
    /// The training's seed.
    pub seed: u64,
    /// The sensor model and arena trained for, if known.
    pub trained_for: Option<(&'a str, &'a str)>,
}

/// What a blob says each state does.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Choices<'a> {
    /// One action per state, in state order.
    Table(&'a [i64]),
    /// Each state's best actions as a bit mask (bit `a`: action `a`), in
    /// state order: the learner's choice among equals, kept.
    Sets(&'a [i64]),
}

/// Encodes `choices` as a blob: format version 1 for one action per state
/// and nothing trained for, else version 2 (`shared`'s rule).
pub fn encode(choices: Choices<'_>, header: &PolicyHeader<'_>) -> Result<Vec<u8>, ArgumentError> {
    let hasher = StateHasher::from_name(header.hasher).ok_or_else(|| {
        ArgumentError::new(
            "hasher",
            format!("{:?}", header.hasher),
            format!("unknown hasher; expected {}", StateHasher::NAMES),
        )
    })?;
    let actions = ActionTable::new(header.actions, header.forward_speed).map_err(|e| {
        ArgumentError::new("actions", format!("{:?}", header.actions), e.to_string())
    })?;
    let (Choices::Table(entries) | Choices::Sets(entries)) = choices;
    if entries.len() != hasher.num_states() {
        return Err(ArgumentError::new(
            "table",
            format!("<{} entries>", entries.len()),
            format!(
                "hasher {} has {} states: give one action per state",
                hasher.name(),
                hasher.num_states()
            ),
        ));
    }
    let provenance = Provenance::new(header.field, header.name, header.trainer_steps, header.seed)
        .map_err(|e| {
            ArgumentError::new(
                "field, name",
                format!("{:?}, {:?}", header.field, header.name),
                e.to_string(),
            )
        })?;
    let count = actions.len() as i64;
    let blob = match choices {
        Choices::Table(table) => {
            let mut policy = PolicyTable::new(hasher);
            for (state, &action) in table.iter().enumerate() {
                if !(0..count).contains(&action) {
                    return Err(ArgumentError::new(
                        &format!("table[{state}]"),
                        action,
                        format!("must be an action index in 0..{count}"),
                    ));
                }
                policy.set(State(state as u16), ActionId(action as u8));
            }
            PolicyBlob::new(actions, policy, provenance)
        }
        Choices::Sets(masks) => {
            let mut sets = ActionSets::new(hasher);
            for (state, &mask) in masks.iter().enumerate() {
                if !(1..1 << count).contains(&mask) {
                    return Err(ArgumentError::new(
                        &format!("sets[{state}]"),
                        mask,
                        format!("must be a non-empty set of actions 0..{count}, as bits"),
                    ));
                }
                sets.set(State(state as u16), mask as u8);
            }
            PolicyBlob::with_sets(actions, sets, provenance)
        }
    }
    .map_err(|e| ArgumentError::new("table", "<table>", e.to_string()))?;
    let blob = match header.trained_for {
        Some((sensors, arena)) => {
            let trained_for = TrainedFor::new(sensors, arena).map_err(|e| {
                ArgumentError::new(
                    "sensors, arena",
                    format!("{sensors:?}, {arena:?}"),
                    e.to_string(),
                )
            })?;
            blob.with_trained_for(trained_for)
        }
        None => blob,
    };
    Ok(blob.encode().to_vec())
}

/// Each state's best actions of a decoded blob as bit masks, in state
/// order (one bit per state for a blob of version 1).
pub fn sets_of(blob: &PolicyBlob) -> Vec<i64> {
    blob.sets().masks().map(|(_, m)| i64::from(m)).collect()
}

/// The action of every state of a decoded blob, in state order.
pub fn table_of(blob: &PolicyBlob) -> Vec<i64> {
    blob.table()
        .entries()
        .map(|(_, a)| i64::from(a.0))
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    const HEADER: PolicyHeader<'static> = PolicyHeader {
        hasher: "bits7",
        actions: &ActionTable::DEFAULT_ANGULAR,
        forward_speed: 2.0,
        field: "annulus",
        name: "python",
        trainer_steps: 1000,
        seed: 3,
        trained_for: None,
    };

    #[test]
    fn a_table_round_trips_through_a_blob() {
        let table: Vec<i64> = (0..128).map(|s| s % 4).collect();
        let bytes = encode(Choices::Table(&table), &HEADER).unwrap();
        let blob = PolicyBlob::decode(&bytes).unwrap();
        assert_eq!(table_of(&blob), table);
        assert_eq!(blob.hasher(), StateHasher::Bits7);
        assert_eq!(blob.provenance().name.as_str(), "python");
    }

    #[test]
    fn a_wrong_table_is_refused_with_the_entry_named() {
        let e = encode(Choices::Table(&[0; 10]), &HEADER)
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with("table = <10 entries>: hasher bits7 has 128 states"),
            "{e}"
        );
        let mut table = vec![0; 128];
        table[5] = 4;
        assert_eq!(
            encode(Choices::Table(&table), &HEADER)
                .unwrap_err()
                .to_string(),
            "table[5] = 4: must be an action index in 0..4"
        );
        let long = "x".repeat(40);
        let e = encode(
            Choices::Table(&[0; 128]),
            &PolicyHeader {
                name: &long,
                ..HEADER
            },
        )
        .unwrap_err()
        .to_string();
        assert!(e.starts_with("field, name = "), "{e}");
    }

    #[test]
    fn best_action_sets_and_what_was_trained_for_round_trip_in_version_2() {
        // every state ties between actions 0 and 2 except state 3 (action 1 alone)
        let mut masks = vec![0b0101; 128];
        masks[3] = 0b0010;
        let header = PolicyHeader {
            trained_for: Some(("robot", "tv75")),
            ..HEADER
        };
        let blob = PolicyBlob::decode(&encode(Choices::Sets(&masks), &header).unwrap()).unwrap();
        assert_eq!(blob.version(), 2);
        assert_eq!(sets_of(&blob), masks);
        assert_eq!(
            table_of(&blob)[..4],
            [0, 0, 0, 1],
            "each set's lowest action"
        );
        let trained = blob.trained_for().unwrap();
        assert_eq!(
            (trained.sensors.as_str(), trained.arena.as_str()),
            ("robot", "tv75")
        );
        // no ties and nothing trained for: version 1, as before
        let single: Vec<i64> = (0..128).map(|s| 1 << (s % 4)).collect();
        let blob = PolicyBlob::decode(&encode(Choices::Sets(&single), &HEADER).unwrap()).unwrap();
        assert_eq!(blob.version(), 1);
        let mut empty = single.clone();
        empty[9] = 0;
        assert_eq!(
            encode(Choices::Sets(&empty), &HEADER)
                .unwrap_err()
                .to_string(),
            "sets[9] = 0: must be a non-empty set of actions 0..4, as bits"
        );
    }
}
