//! A greedy table learned in Python as a policy blob (`shared`'s encoder),
//! and a blob's contents for Python.

use crate::settings::ArgumentError;
use shared::{ActionId, ActionTable, PolicyBlob, PolicyTable, Provenance, State, StateHasher};

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
}

/// Encodes `table` (the action of every state, in state order) as a blob.
pub fn encode(table: &[i64], header: &PolicyHeader<'_>) -> Result<Vec<u8>, ArgumentError> {
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
    if table.len() != hasher.num_states() {
        return Err(ArgumentError::new(
            "table",
            format!("<{} entries>", table.len()),
            format!(
                "hasher {} has {} states: give one action per state",
                hasher.name(),
                hasher.num_states()
            ),
        ));
    }
    let mut policy = PolicyTable::new(hasher);
    for (state, &action) in table.iter().enumerate() {
        if !(0..actions.len() as i64).contains(&action) {
            return Err(ArgumentError::new(
                &format!("table[{state}]"),
                action,
                format!("must be an action index in 0..{}", actions.len()),
            ));
        }
        policy.set(State(state as u16), ActionId(action as u8));
    }
    let provenance = Provenance::new(header.field, header.name, header.trainer_steps, header.seed)
        .map_err(|e| {
            ArgumentError::new(
                "field, name",
                format!("{:?}, {:?}", header.field, header.name),
                e.to_string(),
            )
        })?;
    let blob = PolicyBlob::new(actions, policy, provenance)
        .map_err(|e| ArgumentError::new("table", "<table>", e.to_string()))?;
    Ok(blob.encode().to_vec())
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
    };

    #[test]
    fn a_table_round_trips_through_a_blob() {
        let table: Vec<i64> = (0..128).map(|s| s % 4).collect();
        let bytes = encode(&table, &HEADER).unwrap();
        let blob = PolicyBlob::decode(&bytes).unwrap();
        assert_eq!(table_of(&blob), table);
        assert_eq!(blob.hasher(), StateHasher::Bits7);
        assert_eq!(blob.provenance().name.as_str(), "python");
    }

    #[test]
    fn a_wrong_table_is_refused_with_the_entry_named() {
        let e = encode(&[0; 10], &HEADER).unwrap_err().to_string();
        assert!(
            e.starts_with("table = <10 entries>: hasher bits7 has 128 states"),
            "{e}"
        );
        let mut table = vec![0; 128];
        table[5] = 4;
        assert_eq!(
            encode(&table, &HEADER).unwrap_err().to_string(),
            "table[5] = 4: must be an action index in 0..4"
        );
        let long = "x".repeat(40);
        let e = encode(
            &[0; 128],
            &PolicyHeader {
                name: &long,
                ..HEADER
            },
        )
        .unwrap_err()
        .to_string();
        assert!(e.starts_with("field, name = "), "{e}");
    }
}
