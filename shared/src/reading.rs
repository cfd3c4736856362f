//! One robot's perception in one control step.

use crate::camera::BlobSummary;
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

impl SensorReading {
    /// The reading of the robot's sensors: calibrated left, mid and right
    /// field values and the camera's blob summary. The firmware and the
    /// simulator's robot sensor model both build their readings here.
    pub const fn from_parts(values: [FieldValue; 3], blobs: BlobSummary) -> SensorReading {
        SensorReading {
            left: values[0],
            mid: values[1],
            right: values[2],
            puck_left: blobs.puck_left,
            puck_right: blobs.puck_right,
            obstacle_left: blobs.obstacle_left,
            obstacle_right: blobs.obstacle_right,
        }
    }
}
