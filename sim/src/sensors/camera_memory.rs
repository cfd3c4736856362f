//! What a robot's camera link remembers from one control period to the
//! next, as the Pixy and the firmware behave: the frame captured in the
//! last period (the Pixy reports a frame one period after capturing it),
//! and the blocks the firmware holds (a frame's blocks serve the period it
//! arrives in and, if no new frame comes, one more:
//! [`shared::camera::HOLD_PERIODS`]; a camera that sees nothing sends
//! nothing). Part of a simulation's state, so a checkpoint resumes it.

use serde::{Deserialize, Serialize};
use shared::camera::HOLD_PERIODS;
use shared::PixyBlock;

/// One robot's camera link.
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
pub struct CameraMemory {
    /// The episode it belongs to (a new episode starts afresh).
    pub episode: u64,
    /// The frame captured in the last period, not yet reported.
    pub captured: Vec<PixyBlock>,
    /// The blocks the firmware holds.
    pub held: Vec<PixyBlock>,
    /// Periods since the held blocks' frame arrived.
    pub age: u8,
}

impl CameraMemory {
    /// One period: `delivered` is the frame reaching the robot now (empty
    /// if none does); returns the blocks the firmware then holds.
    pub fn period(&mut self, delivered: &[PixyBlock]) -> &[PixyBlock] {
        self.age = self.age.saturating_add(1);
        if !delivered.is_empty() {
            self.held.clear();
            self.held.extend_from_slice(delivered);
            self.age = 0;
        }
        if self.age >= HOLD_PERIODS {
            self.held.clear();
        }
        &self.held
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_frame_serves_two_periods_when_no_new_one_comes() {
        let block = PixyBlock {
            signature: 1,
            x: 1,
            y: 2,
            width: 3,
            height: 4,
            angle: 0,
        };
        let mut m = CameraMemory::default();
        assert!(m.period(&[]).is_empty());
        assert_eq!(m.period(&[block]), [block]);
        assert_eq!(m.period(&[]), [block], "held for one more period");
        assert!(m.period(&[]).is_empty(), "then cleared");
        let other = PixyBlock { x: 9, ..block };
        assert_eq!(m.period(&[block]), [block]);
        assert_eq!(
            m.period(&[other]),
            [other],
            "a new frame replaces the held one"
        );
    }
}
