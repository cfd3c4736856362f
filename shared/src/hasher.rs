//! State hashers: a [`SensorReading`] -> a small integer [`State`].
//!
//! Canonical bit layout (bit 0 first), the same for every hasher:
//!
//! | bits            | value      | meaning                                        |
//! |-----------------|------------|------------------------------------------------|
//! | 0               | 1          | left puck sensor sees a puck                   |
//! | 1               | 2          | right puck sensor sees a puck                  |
//! | 2               | 4          | left field value < mid field value (strict)    |
//! | 3               | 8          | right field value < mid field value (strict)   |
//! | 4 .. 4+k-1      | 16 x m     | m = floor(mid x 2^k), clamped to 2^k - 1       |
//! | 8 (10-bit only) | 256        | left obstacle sensor sees a robot              |
//! | 9 (10-bit only) | 512        | right obstacle sensor sees a robot             |
//! | 4+k (role only) | 2^(4+k)    | the robot is an innie ([`Role`])               |
//!
//! k = 3, 4, 5 for the 7-, 8- and 9-bit hashers; the 10-bit hasher is the
//! 8-bit one plus the obstacle bits, the role hashers the 8- and 9-bit ones
//! plus the robot's role (bit 8 and bit 9). 1 always means "sensed". Comparisons and the bin are
//! computed on the Q1.15 [`FieldValue`]s, so they are exact on both the host
//! and the AVR.
//!
//! Worked example (thesis section 3.2): left puck on, right off, mid 0.4,
//! left 0.35, right 0.45, 8-bit hash: 1 + 4 + 6 x 16 = 101.
//!
//! Hashing is marked inline for the host, whose learner hashes every
//! robot's reading twice a step, but not for the AVR, which hashes once a
//! period and has little flash to spare.

use crate::reading::SensorReading;
use core::fmt;
use serde::{Deserialize, Serialize};

/// A hashed state, `0 .. hasher.num_states()`.
#[derive(
    Clone, Copy, Debug, Default, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize,
)]
pub struct State(pub u16);

impl State {
    /// The state as a table index.
    pub const fn index(self) -> usize {
        self.0 as usize
    }
}

impl fmt::Display for State {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.0)
    }
}

/// A robot's role in the swarm, as orbital construction's innies and
/// outies: a robot knows it from its build (the firmware: an odd robot id
/// is an innie, [`Role::of_robot_id`]) and only the role hasher reads it.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum Role {
    /// Pushes pucks outwards (orbital construction's outie), the default.
    #[default]
    Outie,
    /// Keeps the inside free (orbital construction's innie).
    Innie,
}

impl Role {
    /// The role of the robot with this id: odd ids are innies, even ones
    /// (and 0, no id) outies.
    pub const fn of_robot_id(id: u8) -> Role {
        if id % 2 == 1 {
            Role::Innie
        } else {
            Role::Outie
        }
    }
}

/// The four state representations of the thesis and the two role layouts,
/// one type.
///
/// The wire id of each (in policy blobs) is its bit count for the thesis'
/// four, and `0x80 |` its bit count for a role hasher ([`StateHasher::id`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub enum StateHasher {
    /// 7 bits: 3-bit mid bin (8 field divisions). 128 states.
    Bits7,
    /// 8 bits, the thesis' "Original": 4-bit mid bin (16 divisions). 256 states.
    Original,
    /// 9 bits: 5-bit mid bin (32 divisions). 512 states.
    Bits9,
    /// 10 bits, "Original_Obstacle": Original plus two obstacle bits. 1024 states.
    OriginalObstacle,
    /// 9 bits, ours: Original plus the robot's [`Role`] (bit 8 set for an
    /// innie), so that one shared table can hold both of orbital
    /// construction's behaviours. 512 states.
    OriginalRole,
    /// 10 bits, ours: Bits9 plus the robot's [`Role`] (bit 9 set for an
    /// innie): the 9-bit state's finer field bins with both roles. 1024
    /// states.
    Bits9Role,
}

/// The quantised inputs a state encodes: what a hash keeps of a reading.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct StateInputs {
    /// Bit 0: left puck.
    pub puck_left: bool,
    /// Bit 1: right puck.
    pub puck_right: bool,
    /// Bit 2: left field value strictly below mid.
    pub left_below_mid: bool,
    /// Bit 3: right field value strictly below mid.
    pub right_below_mid: bool,
    /// Bits 4..: the mid field value's bin.
    pub mid_bin: u16,
    /// Bit 8 of the 10-bit hash: left obstacle (always false otherwise).
    pub obstacle_left: bool,
    /// Bit 9 of the 10-bit hash: right obstacle (always false otherwise).
    pub obstacle_right: bool,
    /// The role bit of a role hash: the robot is an innie (always false
    /// otherwise).
    pub innie: bool,
}

impl StateHasher {
    /// Every hasher, the thesis' four smallest first, then the role hashers.
    pub const ALL: [StateHasher; 6] = [
        StateHasher::Bits7,
        StateHasher::Original,
        StateHasher::Bits9,
        StateHasher::OriginalObstacle,
        StateHasher::OriginalRole,
        StateHasher::Bits9Role,
    ];

    /// The hasher of a wire id ([`StateHasher::id`]).
    pub const fn from_id(id: u8) -> Option<StateHasher> {
        match id {
            7 => Some(StateHasher::Bits7),
            8 => Some(StateHasher::Original),
            9 => Some(StateHasher::Bits9),
            10 => Some(StateHasher::OriginalObstacle),
            0x89 => Some(StateHasher::OriginalRole),
            0x8A => Some(StateHasher::Bits9Role),
            _ => None,
        }
    }

    /// The wire id in policy blobs: the bit count of the thesis' four;
    /// the high bit ("with the role") and the bit count for a role hasher:
    /// `0x89`, `0x8A`.
    pub const fn id(self) -> u8 {
        if self.has_role_bit() {
            0x80 | self.bits()
        } else {
            self.bits()
        }
    }

    /// Number of state bits.
    pub const fn bits(self) -> u8 {
        match self {
            StateHasher::Bits7 => 7,
            StateHasher::Original => 8,
            StateHasher::Bits9 | StateHasher::OriginalRole => 9,
            StateHasher::OriginalObstacle | StateHasher::Bits9Role => 10,
        }
    }

    /// Number of states, `2^bits`.
    pub const fn num_states(self) -> usize {
        1 << self.bits()
    }

    /// Bits of the mid field bin (k): 3, 4, 5, or 4 for the 10-bit hasher
    /// and the 9-bit role hasher, 5 for the 10-bit role hasher.
    pub const fn mid_bits(self) -> u32 {
        match self {
            StateHasher::Bits7 => 3,
            StateHasher::Original | StateHasher::OriginalObstacle | StateHasher::OriginalRole => 4,
            StateHasher::Bits9 | StateHasher::Bits9Role => 5,
        }
    }

    /// Whether the hash carries the two obstacle bits.
    pub const fn has_obstacle_bits(self) -> bool {
        matches!(self, StateHasher::OriginalObstacle)
    }

    /// Whether the hash carries the robot's role.
    pub const fn has_role_bit(self) -> bool {
        matches!(self, StateHasher::OriginalRole | StateHasher::Bits9Role)
    }

    /// The bit of the robot's role in a role hash (bit 4 + k, above the
    /// field bin), or 0 for a hasher without it: a state's other role is
    /// `state ^ role_mask`.
    pub const fn role_mask(self) -> u16 {
        // constants, not a shift by mid_bits: the AVR shifts bit by bit
        match self {
            StateHasher::OriginalRole => 1 << 8,
            StateHasher::Bits9Role => 1 << 9,
            _ => 0,
        }
    }

    /// The thesis' name for the hasher.
    pub const fn name(self) -> &'static str {
        match self {
            StateHasher::Bits7 => "bits7",
            StateHasher::Original => "original",
            StateHasher::Bits9 => "bits9",
            StateHasher::OriginalObstacle => "original-obstacle",
            StateHasher::OriginalRole => "original-role",
            StateHasher::Bits9Role => "bits9-role",
        }
    }

    /// Every name [`StateHasher::from_name`] takes, as messages list them.
    pub const NAMES: &'static str =
        "original, original-obstacle, bits7, bits9 (or their bit counts 8, 10, 7, 9), original-role, bits9-role";

    /// Parses a name (`original`, `original-obstacle`, `bits7`, `bits9`,
    /// `original-role`, `bits9-role`) or a bit count of the thesis' four
    /// (`7`, `8`, `9`, `10`).
    pub fn from_name(name: &str) -> Option<StateHasher> {
        match name {
            "7" | "bits7" => Some(StateHasher::Bits7),
            "8" | "original" => Some(StateHasher::Original),
            "9" | "bits9" => Some(StateHasher::Bits9),
            "10" | "original-obstacle" => Some(StateHasher::OriginalObstacle),
            "original-role" => Some(StateHasher::OriginalRole),
            "bits9-role" => Some(StateHasher::Bits9Role),
            _ => None,
        }
    }

    /// What this hasher keeps of an outie's reading.
    pub fn quantise(self, reading: &SensorReading) -> StateInputs {
        self.quantise_as(reading, Role::Outie)
    }

    /// What this hasher keeps of the reading of a robot of `role`.
    #[cfg_attr(not(target_arch = "avr"), inline)]
    pub fn quantise_as(self, reading: &SensorReading, role: Role) -> StateInputs {
        let obstacles = self.has_obstacle_bits();
        StateInputs {
            puck_left: reading.puck_left,
            puck_right: reading.puck_right,
            left_below_mid: reading.left < reading.mid,
            right_below_mid: reading.right < reading.mid,
            mid_bin: reading.mid.bin(self.mid_bits()),
            obstacle_left: obstacles && reading.obstacle_left,
            obstacle_right: obstacles && reading.obstacle_right,
            innie: self.has_role_bit() && role == Role::Innie,
        }
    }

    /// Packs quantised inputs into a state with the canonical layout.
    /// Bins above the hasher's range are clamped to its top bin; obstacle
    /// bits are dropped by hashers that do not carry them.
    #[cfg_attr(not(target_arch = "avr"), inline)]
    pub fn pack(self, inputs: &StateInputs) -> State {
        let k = self.mid_bits();
        let top_bin = (1u16 << k) - 1;
        let bin = if inputs.mid_bin > top_bin {
            top_bin
        } else {
            inputs.mid_bin
        };
        let mut s = u16::from(inputs.puck_left)
            | u16::from(inputs.puck_right) << 1
            | u16::from(inputs.left_below_mid) << 2
            | u16::from(inputs.right_below_mid) << 3
            | bin << 4;
        if self.has_obstacle_bits() {
            s |= u16::from(inputs.obstacle_left) << 8 | u16::from(inputs.obstacle_right) << 9;
        }
        if inputs.innie {
            s |= self.role_mask();
        }
        State(s)
    }

    /// Unpacks a state into the inputs it encodes, or `None` if the state is
    /// out of this hasher's range.
    pub fn unpack(self, state: State) -> Option<StateInputs> {
        if state.index() >= self.num_states() {
            return None;
        }
        let s = state.0;
        let k = self.mid_bits();
        let obstacles = self.has_obstacle_bits();
        Some(StateInputs {
            puck_left: s & 1 != 0,
            puck_right: s & 2 != 0,
            left_below_mid: s & 4 != 0,
            right_below_mid: s & 8 != 0,
            mid_bin: (s >> 4) & ((1 << k) - 1),
            obstacle_left: obstacles && s & 256 != 0,
            obstacle_right: obstacles && s & 512 != 0,
            innie: s & self.role_mask() != 0,
        })
    }

    /// Hashes an outie's reading: [`StateHasher::pack`] of
    /// [`StateHasher::quantise`].
    #[cfg_attr(not(target_arch = "avr"), inline)]
    pub fn hash(self, reading: &SensorReading) -> State {
        self.pack(&self.quantise(reading))
    }

    /// Hashes the reading of a robot of `role` (only the role hasher tells
    /// the roles apart).
    #[cfg_attr(not(target_arch = "avr"), inline)]
    pub fn hash_as(self, reading: &SensorReading, role: Role) -> State {
        self.pack(&self.quantise_as(reading, role))
    }
}

impl fmt::Display for StateHasher {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{} ({} bits)", self.name(), self.bits())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::field::FieldValue;
    use proptest::prelude::*;

    fn reading(left: f32, mid: f32, right: f32, pl: bool, pr: bool) -> SensorReading {
        SensorReading {
            left: FieldValue::from_f32(left),
            mid: FieldValue::from_f32(mid),
            right: FieldValue::from_f32(right),
            puck_left: pl,
            puck_right: pr,
            ..SensorReading::default()
        }
    }

    #[test]
    fn thesis_example_is_state_101_with_the_original_hash() {
        let r = reading(0.35, 0.4, 0.45, true, false);
        assert_eq!(StateHasher::Original.hash(&r), State(101));
    }

    #[test]
    fn golden_states_for_every_hasher() {
        let r = reading(0.35, 0.4, 0.45, true, false);
        // mid 0.4: bins 3 (k=3), 6 (k=4), 12 (k=5)
        assert_eq!(StateHasher::Bits7.hash(&r), State(1 + 4 + 3 * 16));
        assert_eq!(StateHasher::Bits9.hash(&r), State(1 + 4 + 12 * 16));
        assert_eq!(StateHasher::OriginalObstacle.hash(&r), State(101));

        let mut r = reading(0.9, 0.8, 0.1, false, true);
        r.obstacle_left = true;
        r.obstacle_right = true;
        // mid 0.8 -> bin 12 (k=4); right < mid; obstacles 256 + 512
        assert_eq!(StateHasher::Original.hash(&r), State(2 + 8 + 12 * 16));
        assert_eq!(
            StateHasher::OriginalObstacle.hash(&r),
            State(2 + 8 + 192 + 768)
        );

        let all_on = SensorReading {
            left: FieldValue::ZERO,
            mid: FieldValue::ONE,
            right: FieldValue::ZERO,
            puck_left: true,
            puck_right: true,
            obstacle_left: true,
            obstacle_right: true,
        };
        for h in StateHasher::ALL {
            assert_eq!(
                h.hash_as(&all_on, Role::Innie).index(),
                h.num_states() - 1,
                "{h}"
            );
        }
        for h in StateHasher::ALL {
            assert_eq!(h.hash(&SensorReading::default()), State(0), "{h}");
        }
    }

    #[test]
    fn mid_exactly_on_a_bin_edge_goes_to_the_upper_bin() {
        for h in StateHasher::ALL {
            let k = h.mid_bits();
            for bin in 1..(1u16 << k) {
                let edge = FieldValue::from_raw(bin << (15 - k));
                let below = FieldValue::from_raw(edge.raw() - 1);
                let at = SensorReading {
                    mid: edge,
                    ..SensorReading::default()
                };
                let under = SensorReading {
                    mid: below,
                    ..SensorReading::default()
                };
                assert_eq!(h.quantise(&at).mid_bin, bin, "{h} edge {bin}");
                assert_eq!(h.quantise(&under).mid_bin, bin - 1, "{h} below {bin}");
            }
        }
    }

    #[test]
    fn one_clamps_to_the_top_bin() {
        for h in StateHasher::ALL {
            let r = SensorReading {
                mid: FieldValue::ONE,
                ..SensorReading::default()
            };
            assert_eq!(h.quantise(&r).mid_bin, (1 << h.mid_bits()) - 1);
            let r = SensorReading {
                mid: FieldValue::from_f32(0.999_99),
                ..SensorReading::default()
            };
            assert_eq!(h.quantise(&r).mid_bin, (1 << h.mid_bits()) - 1);
        }
    }

    #[test]
    fn equal_to_mid_is_not_less() {
        let r = reading(0.5, 0.5, 0.5, false, false);
        let q = StateHasher::Original.quantise(&r);
        assert!(!q.left_below_mid && !q.right_below_mid);
        let r = SensorReading {
            left: FieldValue::from_raw(16383),
            mid: FieldValue::from_raw(16384),
            right: FieldValue::from_raw(16384),
            ..SensorReading::default()
        };
        let q = StateHasher::Original.quantise(&r);
        assert!(q.left_below_mid && !q.right_below_mid);
    }

    #[test]
    fn obstacle_bits_only_in_the_10_bit_hash() {
        let r = SensorReading {
            obstacle_left: true,
            obstacle_right: true,
            ..SensorReading::default()
        };
        for h in [
            StateHasher::Bits7,
            StateHasher::Original,
            StateHasher::Bits9,
        ] {
            assert_eq!(h.hash(&r), State(0));
        }
        assert_eq!(StateHasher::OriginalObstacle.hash(&r), State(768));
    }

    #[test]
    fn the_role_hash_is_the_original_one_plus_bit_8_for_an_innie() {
        let r = reading(0.35, 0.4, 0.45, true, false);
        assert_eq!(StateHasher::OriginalRole.hash(&r), State(101));
        assert_eq!(
            StateHasher::OriginalRole.hash_as(&r, Role::Outie),
            State(101)
        );
        assert_eq!(
            StateHasher::OriginalRole.hash_as(&r, Role::Innie),
            State(101 + 256)
        );
        let mut seen = SensorReading {
            obstacle_left: true,
            obstacle_right: true,
            ..r
        };
        seen.mid = FieldValue::ONE;
        // obstacles are not in the role layout; mid 1.0 is the top bin
        assert_eq!(
            StateHasher::OriginalRole.hash_as(&seen, Role::Innie),
            State(1 + 4 + 8 + 15 * 16 + 256)
        );
        for h in [
            StateHasher::Bits7,
            StateHasher::Original,
            StateHasher::Bits9,
            StateHasher::OriginalObstacle,
        ] {
            assert_eq!(
                h.hash_as(&r, Role::Innie),
                h.hash(&r),
                "{h} ignores the role"
            );
        }
        assert_eq!(
            (
                Role::of_robot_id(0),
                Role::of_robot_id(1),
                Role::of_robot_id(2),
                Role::of_robot_id(255)
            ),
            (Role::Outie, Role::Innie, Role::Outie, Role::Innie)
        );
    }

    #[test]
    fn names_and_wire_ids_round_trip() {
        for h in StateHasher::ALL {
            assert_eq!(StateHasher::from_id(h.id()), Some(h));
            assert_eq!(StateHasher::from_name(h.name()), Some(h));
            assert!(
                StateHasher::NAMES.contains(h.name()),
                "{h} missing from NAMES"
            );
        }
        for h in [
            StateHasher::Bits7,
            StateHasher::Original,
            StateHasher::Bits9,
            StateHasher::OriginalObstacle,
        ] {
            assert_eq!(
                h.id(),
                h.bits(),
                "the thesis' hashers keep their bit counts as ids"
            );
            assert!(
                StateHasher::NAMES.contains(alloc_free_digits(h.bits()).as_str()),
                "{h}'s bits missing from NAMES"
            );
        }
        assert_eq!(StateHasher::from_id(11), None);
        assert_eq!(StateHasher::from_name("nine"), None);
        assert!(StateHasher::Original.unpack(State(256)).is_none());
        assert!(StateHasher::OriginalRole.unpack(State(512)).is_none());
    }

    /// A bit count as text, without an allocator.
    fn alloc_free_digits(bits: u8) -> heapless::String<3> {
        let mut s = heapless::String::new();
        if bits >= 10 {
            let _ = s.push(char::from(b'0' + bits / 10));
        }
        let _ = s.push(char::from(b'0' + bits % 10));
        s
    }

    fn arb_reading() -> impl Strategy<Value = SensorReading> {
        (0u16..=32768, 0u16..=32768, 0u16..=32768, any::<[bool; 4]>()).prop_map(|(l, m, r, b)| {
            SensorReading {
                left: FieldValue::from_raw(l),
                mid: FieldValue::from_raw(m),
                right: FieldValue::from_raw(r),
                puck_left: b[0],
                puck_right: b[1],
                obstacle_left: b[2],
                obstacle_right: b[3],
            }
        })
    }

    proptest! {
        #[test]
        fn unpacking_a_hash_gives_back_the_quantised_inputs(r in arb_reading(), innie in any::<bool>()) {
            let role = if innie { Role::Innie } else { Role::Outie };
            for h in StateHasher::ALL {
                let s = h.hash_as(&r, role);
                prop_assert!(s.index() < h.num_states());
                prop_assert_eq!(h.unpack(s), Some(h.quantise_as(&r, role)));
            }
        }

        #[test]
        fn mid_bin_is_floor_of_mid_times_divisions(m in 0u16..32768) {
            // Exact arithmetic reference: floor(m / 32768 * 2^k) == (m * 2^k) / 32768.
            for h in StateHasher::ALL {
                let k = h.mid_bits();
                let r = SensorReading { mid: FieldValue::from_raw(m), ..SensorReading::default() };
                let expected = ((u32::from(m) << k) / 32768) as u16;
                prop_assert_eq!(h.quantise(&r).mid_bin, expected);
            }
        }

        #[test]
        fn every_state_unpacks_and_repacks(s in 0u16..1024) {
            for h in StateHasher::ALL {
                match h.unpack(State(s)) {
                    Some(inputs) => prop_assert_eq!(h.pack(&inputs), State(s)),
                    None => prop_assert!(usize::from(s) >= h.num_states()),
                }
            }
        }
    }
}
