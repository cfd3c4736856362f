//! Stand-in policies for the equivalence tests, until policies trained with
//! the robot sensor model (`host train --sensors robot`) are shipped in
//! `policies/`.
//!
//! They are hand-written, not trained: the puck and field bits map as in
//! `policies/oc-heuristic.policy` (outie orbital construction as far as
//! the 8-bit state expresses it); the 10-bit one adds obstacle avoidance
//! (a robot on the left: hard right; on the right: hard left; both: hard
//! right). `cargo run -p tests --bin standin-policies` writes them.

use anyhow::{bail, Context, Result};
use shared::{ActionId, PolicyBlob, PolicyTable, Provenance, State, StateHasher};

/// The 8-bit stand-in's file name in `policies/`.
pub const POLICY_8BIT: &str = "robot-annulus-8bit.policy";
/// The 10-bit stand-in's file name in `policies/`.
pub const POLICY_10BIT: &str = "robot-annulus-10bit.policy";

/// Hard right (+0.3 rad/step) and hard left (-0.3) in the thesis' action table.
const HARD_RIGHT: ActionId = ActionId(0);
const HARD_LEFT: ActionId = ActionId(3);

/// The stand-in for `hasher` (`Original` or `OriginalObstacle`), built from
/// the 8-bit orbital-construction heuristic `oc`.
pub fn standin(oc: &PolicyBlob, hasher: StateHasher) -> Result<PolicyBlob> {
    if oc.hasher() != StateHasher::Original {
        bail!("the heuristic must use the original (8-bit) hasher, not {}", oc.hasher());
    }
    let mut table = PolicyTable::new(hasher);
    for s in 0..hasher.num_states() as u16 {
        let inputs = hasher.unpack(State(s)).context("state in range")?;
        let action = match (inputs.obstacle_left, inputs.obstacle_right) {
            (true, _) => HARD_RIGHT,
            (false, true) => HARD_LEFT,
            (false, false) => oc.table().action(State(s & 0xFF)),
        };
        table.set(State(s), action);
    }
    let name = format!("stand-in {}-bit (oc-heuristic)", hasher.bits());
    let provenance = Provenance::new("annulus", &name, 0, 0).map_err(|e| anyhow::anyhow!("{e:?}"))?;
    PolicyBlob::new(*oc.actions(), table, provenance).map_err(|e| anyhow::anyhow!("{e}"))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn oc() -> PolicyBlob {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("../policies/oc-heuristic.policy");
        PolicyBlob::decode(&std::fs::read(path).unwrap()).unwrap()
    }

    #[test]
    fn the_8bit_stand_in_is_the_heuristic_and_the_10bit_one_avoids_robots() {
        let oc = oc();
        let eight = standin(&oc, StateHasher::Original).unwrap();
        assert_eq!(eight.table().packed(), oc.table().packed());
        let ten = standin(&oc, StateHasher::OriginalObstacle).unwrap();
        assert_eq!(ten.hasher(), StateHasher::OriginalObstacle);
        for s in 0..256u16 {
            assert_eq!(ten.table().action(State(s)), oc.table().action(State(s)));
            assert_eq!(ten.table().action(State(s | 256)), HARD_RIGHT);
            assert_eq!(ten.table().action(State(s | 512)), HARD_LEFT);
            assert_eq!(ten.table().action(State(s | 768)), HARD_RIGHT);
        }
    }
}
