//! A greedy table carried into a finer state: every state of the finer
//! hasher takes the action of the state the same reading hashes to under
//! the table's own, so the lifted table acts exactly as the original on
//! every reading, for a robot of either role. A search or a learning run
//! then refines what the finer state tells apart (the shipped general
//! table lifted into the role hasher gives innies a rule of their own to
//! learn, starting from the outies').
//!
//! A hasher lifts into another ([`can_lift`]) when its field bins are no
//! finer and every bit it reads (the obstacle bits, the role) the other
//! reads too: the finer bin's top bits are the coarser bin (both are the
//! Q1.15 value shifted right, clamped at the top), and the other bits are
//! the same inputs.

use shared::{PolicyTable, State, StateHasher};

/// Whether a table of `from` lifts into `to` ([`lift`]).
pub fn can_lift(from: StateHasher, to: StateHasher) -> bool {
    from.mid_bits() <= to.mid_bits()
        && (!from.has_obstacle_bits() || to.has_obstacle_bits())
        && (!from.has_role_bit() || to.has_role_bit())
}

/// `table` as a table of `to` that acts as it on every reading, or `None`
/// when its hasher does not lift into `to`.
pub fn lift(table: &PolicyTable, to: StateHasher) -> Option<PolicyTable> {
    let from = table.hasher();
    if !can_lift(from, to) {
        return None;
    }
    let finer = to.mid_bits() - from.mid_bits();
    let mut lifted = PolicyTable::new(to);
    for s in 0..to.num_states() {
        let state = State(s as u16);
        let mut inputs = to.unpack(state)?;
        inputs.mid_bin >>= finer;
        lifted.set(state, table.action(from.pack(&inputs)));
    }
    Some(lifted)
}

#[cfg(test)]
mod tests {
    use super::*;
    use shared::{ActionId, FieldValue, Role, SensorReading};

    /// A table of `hasher` whose every state has an action of its own
    /// pattern, so that a wrong state shows.
    fn patterned(hasher: StateHasher) -> PolicyTable {
        let mut t = PolicyTable::new(hasher);
        for s in 0..hasher.num_states() {
            t.set(State(s as u16), ActionId(((s * 7 + s / 16) % 4) as u8));
        }
        t
    }

    #[test]
    fn a_lifted_table_acts_as_its_original_on_every_reading_and_role() {
        for from in StateHasher::ALL {
            for to in StateHasher::ALL {
                let Some(lifted) = lift(&patterned(from), to) else {
                    assert!(!can_lift(from, to));
                    continue;
                };
                assert_eq!(lifted.hasher(), to);
                let original = patterned(from);
                for raw in (0..=32768u16).step_by(97).chain([32767, 32768]) {
                    for bits in 0..64u16 {
                        let value = |shift: u16| FieldValue::from_raw(raw.saturating_add(shift));
                        let reading = SensorReading {
                            left: value(if bits & 1 != 0 { 0 } else { 500 }),
                            mid: value(250),
                            right: value(if bits & 2 != 0 { 0 } else { 500 }),
                            puck_left: bits & 4 != 0,
                            puck_right: bits & 8 != 0,
                            obstacle_left: bits & 16 != 0,
                            obstacle_right: bits & 32 != 0,
                        };
                        for role in [Role::Outie, Role::Innie] {
                            assert_eq!(
                                lifted.action(to.hash_as(&reading, role)),
                                original.action(from.hash_as(&reading, role)),
                                "{from} into {to}"
                            );
                        }
                    }
                }
            }
        }
    }

    #[test]
    fn a_table_lifts_only_into_a_state_that_reads_all_it_reads() {
        use StateHasher::*;
        assert!(can_lift(Original, OriginalRole));
        assert!(can_lift(Original, Bits9Role));
        assert!(can_lift(OriginalRole, Bits9Role));
        assert!(can_lift(Original, OriginalObstacle));
        assert!(!can_lift(Bits9, Original), "coarser bins");
        assert!(!can_lift(OriginalRole, Bits9), "the role dropped");
        assert!(
            !can_lift(OriginalObstacle, Bits9Role),
            "the obstacles dropped"
        );
    }
}
