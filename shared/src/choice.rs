//! The robot's choice among a state's best actions: a small seeded
//! generator, the same on the robot and in the simulator, so that a log
//! (which carries the generator's state) rechecks every sampled decision.

use crate::action::ActionId;

/// Xorshift16 (shifts 7, 9, 8): 16 bits of state, never 0, period
/// 2^16 - 1; small enough that the robot logs it in 3 bytes. Drawn only
/// when a state has two or more best actions, so single-action policies
/// never advance it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ChoiceRng(u16);

impl ChoiceRng {
    /// The generator of robot `robot_id` (the firmware's, `host flash
    /// --robot-id`): a fixed mix of the id, never 0.
    pub const fn for_robot(robot_id: u8) -> ChoiceRng {
        let mixed = (robot_id as u16 + 1).wrapping_mul(0x9E37);
        ChoiceRng::from_state(mixed ^ 0x2545)
    }

    /// A generator in a logged state; 0 (which xorshift never leaves) is
    /// read as 1.
    pub const fn from_state(state: u16) -> ChoiceRng {
        ChoiceRng(if state == 0 { 1 } else { state })
    }

    /// The state, for the log.
    pub const fn state(&self) -> u16 {
        self.0
    }

    /// The next 16 random bits.
    pub fn next_u16(&mut self) -> u16 {
        let mut x = self.0;
        x ^= x << 7;
        x ^= x >> 9;
        x ^= x << 8;
        self.0 = x;
        x
    }

    /// One action of `mask` (bit `a`: action `a`; only the low four bits
    /// count): the only one without drawing, otherwise the `k`-th set bit
    /// with `k = (draw x count) >> 16`, uniform to within `count / 65536`
    /// per action. An empty mask gives action 0, undrawn.
    pub fn pick(&mut self, mask: u8) -> ActionId {
        let mask = mask & 0x0f;
        let count = mask.count_ones();
        if count == 0 {
            return ActionId(0);
        }
        if count == 1 {
            return ActionId(mask.trailing_zeros() as u8);
        }
        let k = (u32::from(self.next_u16()) * count) >> 16;
        let mut left = mask;
        for _ in 0..k {
            left &= left - 1;
        }
        ActionId(left.trailing_zeros() as u8)
    }
}

#[cfg(test)]
mod tests {
    extern crate std;
    use super::*;

    #[test]
    fn a_single_action_is_taken_without_drawing() {
        let mut rng = ChoiceRng::for_robot(3);
        let before = rng;
        for a in 0..4u8 {
            assert_eq!(rng.pick(1 << a), ActionId(a));
        }
        assert_eq!(rng.pick(0), ActionId(0));
        assert_eq!(rng, before);
    }

    #[test]
    fn every_pick_is_in_the_set_and_uniform_within_one_percent() {
        let mut rng = ChoiceRng::for_robot(0);
        for mask in 1..16u8 {
            let mut counts = [0u32; 4];
            let draws = 60_000;
            for _ in 0..draws {
                let a = rng.pick(mask);
                assert!(mask & (1 << a.0) != 0, "mask {mask:04b} gave {a:?}");
                counts[a.index()] += 1;
            }
            let n = mask.count_ones();
            for a in 0..4 {
                if mask & (1 << a) != 0 {
                    let share = f64::from(counts[a]) / f64::from(draws);
                    assert!(
                        (share - 1.0 / f64::from(n)).abs() < 0.01,
                        "{mask:04b} {counts:?}"
                    );
                }
            }
        }
    }

    #[test]
    fn robots_start_apart_and_never_at_zero() {
        let states: std::vec::Vec<u16> = (0..=255u8)
            .map(|id| ChoiceRng::for_robot(id).state())
            .collect();
        let mut sorted = states.clone();
        sorted.sort_unstable();
        sorted.dedup();
        assert_eq!(sorted.len(), 256);
        assert!(!states.contains(&0));
        assert_eq!(ChoiceRng::from_state(0).state(), 1);
    }
}
