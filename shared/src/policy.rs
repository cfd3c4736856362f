//! The greedy policy: one action per state, packed at 2 bits per action.

use crate::action::ActionId;
use crate::hasher::{State, StateHasher};

/// A greedy policy table for one hasher: `2^bits` entries of 2 bits each,
/// four per byte, state `s` in bits `2 (s % 4) .. 2 (s % 4) + 1` of byte
/// `s / 4`. 32 to 256 bytes.
///
/// Lookup is a shift and a mask; the firmware keeps the bytes in flash and
/// uses [`PolicyTable::byte_index`] and [`PolicyTable::action_in_byte`] on
/// the byte it loads.
#[derive(Clone, PartialEq, Eq)]
pub struct PolicyTable {
    hasher: StateHasher,
    packed: [u8; PolicyTable::MAX_BYTES],
}

impl PolicyTable {
    /// Bytes of the largest table (1024 states).
    pub const MAX_BYTES: usize = 256;

    /// A table of `hasher`'s size with every state mapped to action 0.
    pub const fn new(hasher: StateHasher) -> PolicyTable {
        PolicyTable {
            hasher,
            packed: [0; Self::MAX_BYTES],
        }
    }

    /// A table from its packed bytes, or `None` if their count is not
    /// `hasher.num_states() / 4`.
    pub fn from_packed(hasher: StateHasher, packed: &[u8]) -> Option<PolicyTable> {
        if packed.len() != Self::packed_len(hasher) {
            return None;
        }
        let mut table = PolicyTable::new(hasher);
        table.packed[..packed.len()].copy_from_slice(packed);
        Some(table)
    }

    /// Packed size of a table for `hasher`, in bytes.
    pub const fn packed_len(hasher: StateHasher) -> usize {
        hasher.num_states() / 4
    }

    /// The hasher whose states index this table.
    pub const fn hasher(&self) -> StateHasher {
        self.hasher
    }

    /// Number of states.
    pub const fn num_states(&self) -> usize {
        self.hasher.num_states()
    }

    /// The packed bytes.
    pub fn packed(&self) -> &[u8] {
        &self.packed[..Self::packed_len(self.hasher)]
    }

    /// The byte that holds a state's entry.
    pub const fn byte_index(state: State) -> usize {
        state.index() >> 2
    }

    /// A state's entry within the byte [`PolicyTable::byte_index`] names.
    pub const fn action_in_byte(byte: u8, state: State) -> ActionId {
        ActionId((byte >> ((state.0 & 3) * 2)) & 3)
    }

    /// The action for a state. States beyond the table wrap into it (the
    /// index is masked), so a lookup can never fail or read out of bounds.
    pub fn action(&self, state: State) -> ActionId {
        let masked = State(state.0 & (self.num_states() as u16 - 1));
        Self::action_in_byte(self.packed[Self::byte_index(masked)], masked)
    }

    /// Sets a state's action. Out-of-range states and action ids above 3 are
    /// masked like in [`PolicyTable::action`].
    pub fn set(&mut self, state: State, action: ActionId) {
        let masked = State(state.0 & (self.num_states() as u16 - 1));
        let shift = (masked.0 & 3) * 2;
        let byte = &mut self.packed[Self::byte_index(masked)];
        *byte = (*byte & !(3 << shift)) | ((action.0 & 3) << shift);
    }

    /// Every (state, action) entry in state order.
    pub fn entries(&self) -> impl Iterator<Item = (State, ActionId)> + '_ {
        (0..self.num_states() as u16).map(move |s| (State(s), self.action(State(s))))
    }
}

impl core::fmt::Debug for PolicyTable {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_struct("PolicyTable")
            .field("hasher", &self.hasher)
            .field("packed", &self.packed())
            .finish()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn set_then_get_every_state() {
        for h in StateHasher::ALL {
            let mut t = PolicyTable::new(h);
            for s in 0..h.num_states() as u16 {
                t.set(State(s), ActionId((s % 4) as u8 ^ (s / 7 % 4) as u8));
            }
            for s in 0..h.num_states() as u16 {
                assert_eq!(
                    t.action(State(s)),
                    ActionId((s % 4) as u8 ^ (s / 7 % 4) as u8)
                );
            }
            assert_eq!(t.packed().len(), h.num_states() / 4);
        }
    }

    #[test]
    fn packing_layout_is_little_end_first() {
        let mut t = PolicyTable::new(StateHasher::Bits7);
        t.set(State(0), ActionId(1));
        t.set(State(1), ActionId(2));
        t.set(State(2), ActionId(3));
        t.set(State(5), ActionId(3));
        assert_eq!(t.packed()[0], 0b11_10_01);
        assert_eq!(t.packed()[1], 0b11_00);
        assert_eq!(PolicyTable::byte_index(State(5)), 1);
        assert_eq!(PolicyTable::action_in_byte(0b11_00, State(5)), ActionId(3));
    }

    #[test]
    fn from_packed_checks_the_length() {
        assert!(PolicyTable::from_packed(StateHasher::Original, &[0; 64]).is_some());
        assert!(PolicyTable::from_packed(StateHasher::Original, &[0; 63]).is_none());
        assert!(PolicyTable::from_packed(StateHasher::OriginalObstacle, &[0; 256]).is_some());
    }

    #[test]
    fn out_of_range_states_never_read_out_of_bounds() {
        let t = PolicyTable::new(StateHasher::Bits7);
        assert_eq!(t.action(State(u16::MAX)), ActionId(0));
    }
}
