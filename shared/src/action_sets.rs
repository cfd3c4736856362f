//! Per-state sets of best actions: the learner's choice among equal
//! actions, kept for the robot.

use crate::action::ActionId;
use crate::hasher::{State, StateHasher};
use crate::policy::PolicyTable;

/// One bit per action (bit `a` set: action `a` is among the state's best),
/// four bits per state, two states per byte: state `s` in bits
/// `4 (s % 2) .. 4 (s % 2) + 3` of byte `s / 2`. 64 to 512 bytes.
///
/// Like [`PolicyTable`], a lookup is a shift and a mask, and states beyond
/// the table wrap into it.
#[derive(Clone, PartialEq, Eq)]
pub struct ActionSets {
    hasher: StateHasher,
    packed: [u8; ActionSets::MAX_BYTES],
}

impl ActionSets {
    /// Bytes of the largest table (1024 states).
    pub const MAX_BYTES: usize = 512;

    /// A table of `hasher`'s size with every set empty.
    pub const fn new(hasher: StateHasher) -> ActionSets {
        ActionSets {
            hasher,
            packed: [0; Self::MAX_BYTES],
        }
    }

    /// Every state's set the single action of `table`: what a greedy
    /// table without ties means.
    pub fn of_table(table: &PolicyTable) -> ActionSets {
        let mut sets = ActionSets::new(table.hasher());
        for (state, action) in table.entries() {
            sets.set(state, 1 << action.0);
        }
        sets
    }

    /// Sets from their packed bytes, or `None` if their count is not
    /// `hasher.num_states() / 2`.
    pub fn from_packed(hasher: StateHasher, packed: &[u8]) -> Option<ActionSets> {
        if packed.len() != Self::packed_len(hasher) {
            return None;
        }
        let mut sets = ActionSets::new(hasher);
        sets.packed[..packed.len()].copy_from_slice(packed);
        Some(sets)
    }

    /// Packed size for `hasher`, in bytes.
    pub const fn packed_len(hasher: StateHasher) -> usize {
        hasher.num_states() / 2
    }

    /// The hasher whose states index the sets.
    pub const fn hasher(&self) -> StateHasher {
        self.hasher
    }

    /// The packed bytes.
    pub fn packed(&self) -> &[u8] {
        &self.packed[..Self::packed_len(self.hasher)]
    }

    /// The byte that holds a state's set.
    pub const fn byte_index(state: State) -> usize {
        state.index() >> 1
    }

    /// A state's set within the byte [`ActionSets::byte_index`] names.
    pub const fn mask_in_byte(byte: u8, state: State) -> u8 {
        (byte >> ((state.0 & 1) * 4)) & 0x0f
    }

    /// A state's set as a bit mask (bit `a`: action `a`).
    pub fn mask(&self, state: State) -> u8 {
        let masked = self.wrap(state);
        Self::mask_in_byte(self.packed[Self::byte_index(masked)], masked)
    }

    /// Sets a state's set (only the low four bits of `mask` are kept).
    pub fn set(&mut self, state: State, mask: u8) {
        let masked = self.wrap(state);
        let shift = (masked.0 & 1) * 4;
        let byte = &mut self.packed[Self::byte_index(masked)];
        *byte = (*byte & !(0x0f << shift)) | ((mask & 0x0f) << shift);
    }

    /// Each state's lowest action: the greedy table that breaks every tie
    /// towards action 0 (empty sets give action 0).
    pub fn lowest(&self) -> PolicyTable {
        let mut table = PolicyTable::new(self.hasher);
        for s in 0..self.hasher.num_states() as u16 {
            let mask = self.mask(State(s));
            table.set(State(s), ActionId(mask.trailing_zeros().min(3) as u8));
        }
        table
    }

    /// Whether some state has two or more best actions.
    pub fn has_ties(&self) -> bool {
        self.masks().any(|(_, m)| m.count_ones() > 1)
    }

    /// Every (state, mask) in state order.
    pub fn masks(&self) -> impl Iterator<Item = (State, u8)> + '_ {
        (0..self.hasher.num_states() as u16).map(move |s| (State(s), self.mask(State(s))))
    }

    fn wrap(&self, state: State) -> State {
        State(state.0 & (self.hasher.num_states() as u16 - 1))
    }
}

impl core::fmt::Debug for ActionSets {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        f.debug_struct("ActionSets")
            .field("hasher", &self.hasher)
            .field("packed", &self.packed())
            .finish()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn set_then_get_every_state_of_every_hasher() {
        for h in StateHasher::ALL {
            let mut sets = ActionSets::new(h);
            for s in 0..h.num_states() as u16 {
                sets.set(State(s), (s % 15 + 1) as u8);
            }
            for s in 0..h.num_states() as u16 {
                assert_eq!(sets.mask(State(s)), (s % 15 + 1) as u8);
            }
            assert_eq!(sets.packed().len(), h.num_states() / 2);
        }
    }

    #[test]
    fn the_low_nibble_holds_the_even_state() {
        let mut sets = ActionSets::new(StateHasher::Bits7);
        sets.set(State(0), 0b0101);
        sets.set(State(1), 0b1000);
        assert_eq!(sets.packed()[0], 0b1000_0101);
        assert_eq!(ActionSets::mask_in_byte(0b1000_0101, State(3)), 0b1000);
    }

    #[test]
    fn a_table_becomes_single_action_sets_and_lowest_gives_it_back() {
        let mut table = PolicyTable::new(StateHasher::Original);
        for s in 0..256u16 {
            table.set(State(s), ActionId((s % 4) as u8));
        }
        let sets = ActionSets::of_table(&table);
        assert!(!sets.has_ties());
        assert_eq!(sets.lowest(), table);
        let mut tied = sets.clone();
        tied.set(State(7), 0b1010);
        assert!(tied.has_ties());
        assert_eq!(tied.lowest().action(State(7)), ActionId(1));
    }
}
