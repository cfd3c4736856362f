//! One robot's perception in one control step.

use crate::field::FieldValue;
use serde::{Deserialize, Serialize};

/// Everything a state hasher may use: three field values and four binary
/// detections. The simulator's sensor models and the firmware both produce
/// this type, and both hash it with the same [`crate::StateHasher`].
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub struct SensorReading {
    /// Field value under the left field sensor.
    pub left: FieldValue,
    /// Field value under the middle field sensor.
    pub mid: FieldValue,
    /// Field value under the right field sensor.
    pub right: FieldValue,
    /// The left puck sensor sees a puck.
    pub puck_left: bool,
    /// The right puck sensor sees a puck.
    pub puck_right: bool,
    /// The left obstacle sensor sees an obstacle (a robot, by default).
    pub obstacle_left: bool,
    /// The right obstacle sensor sees an obstacle.
    pub obstacle_right: bool,
}
