//! The Pixy (CMUcam5) camera as a sensor: its blocks and how they become
//! the puck and obstacle bits of a [`SensorReading`](crate::SensorReading).
//!
//! The firmware parses [`PixyBlock`]s from the camera; the simulator will
//! model the camera by producing the same blocks. Both then classify them
//! with [`CameraConfig::classify`], so robot and simulator agree exactly on
//! what counts as a puck or an obstacle on the left or the right.
//!
//! Classification (integer-only): a block sets the right puck bit if its
//! signature is the puck signature and its centre lies in the right puck
//! region, the left puck bit if it lies in that region's mirror image
//! (about the image's centre column); likewise for robots and the obstacle
//! bits. The camera looks forward and down, so the lower part of the image
//! (large y) is the ground close to the robot, and the sides of the image
//! are the directions beside the heading.

use serde::{Deserialize, Serialize};

/// Width of the Pixy's image in its block coordinates (x is 0..=319).
pub const IMAGE_WIDTH: u16 = 320;
/// Height of the Pixy's image in its block coordinates (y is 0..=199).
pub const IMAGE_HEIGHT: u16 = 200;

/// Most blocks of one camera frame the robot reads per control period: the
/// Pixy sends the largest blocks of each signature first (signature 1, then
/// 2, ...), and each block costs over a millisecond on the bus. The
/// firmware stops reading after this many; the simulator's camera model
/// keeps the same ones.
pub const MAX_BLOCKS_PER_PERIOD: usize = 4;

/// A frame's blocks serve the control period the frame arrives in and, if
/// no new frame comes, the next one: then they are dropped, so that a
/// camera that stops seeing an object (and then sends nothing at all)
/// clears it. The firmware holds blocks this way; the simulator models it.
pub const HOLD_PERIODS: u8 = 2;

/// One detected object as the Pixy reports it.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub struct PixyBlock {
    /// Colour signature 1..=7, or a colour code (octal digits) above 7.
    pub signature: u16,
    /// Centre column, 0..=319, left to right.
    pub x: u16,
    /// Centre row, 0..=199, top to bottom.
    pub y: u16,
    /// Width in pixels.
    pub width: u16,
    /// Height in pixels.
    pub height: u16,
    /// Angle in degrees of a colour-code block; 0 for normal blocks.
    pub angle: i16,
}

/// A rectangle of the image, bounds inclusive.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub struct ImageRegion {
    /// Leftmost column inside.
    pub x_min: u16,
    /// Rightmost column inside.
    pub x_max: u16,
    /// Top row inside.
    pub y_min: u16,
    /// Bottom row inside.
    pub y_max: u16,
}

impl ImageRegion {
    /// Whether a point lies inside.
    pub const fn contains(&self, x: u16, y: u16) -> bool {
        x >= self.x_min && x <= self.x_max && y >= self.y_min && y <= self.y_max
    }

    /// Whether a point at row `y`, column `x` (whose mirror image about the
    /// centre column is `mirrored_x`) lies in this region's mirror image and
    /// in this region.
    #[inline]
    const fn sides(&self, mirrored_x: u16, x: u16, y: u16) -> (bool, bool) {
        if y < self.y_min || y > self.y_max {
            return (false, false);
        }
        (
            mirrored_x >= self.x_min && mirrored_x <= self.x_max,
            x >= self.x_min && x <= self.x_max,
        )
    }

    /// The region's mirror image about the image's centre column.
    pub const fn mirrored(&self) -> ImageRegion {
        let last = IMAGE_WIDTH - 1;
        ImageRegion {
            x_min: last.saturating_sub(self.x_max),
            x_max: last.saturating_sub(self.x_min),
            y_min: self.y_min,
            y_max: self.y_max,
        }
    }
}

/// What the camera reports as sensor bits: the puck and obstacle sensors
/// of the thesis, on each side.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub struct BlobSummary {
    /// A puck in the left puck region.
    pub puck_left: bool,
    /// A puck in the right puck region.
    pub puck_right: bool,
    /// A robot in the left obstacle region.
    pub obstacle_left: bool,
    /// A robot in the right obstacle region.
    pub obstacle_right: bool,
}

/// How the camera's blocks are classified.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Serialize, Deserialize)]
pub struct CameraConfig {
    /// Signature taught to the Pixy for pucks.
    pub puck_signature: u16,
    /// Signature taught to the Pixy for robots (obstacles); may be a
    /// colour code.
    pub robot_signature: u16,
    /// Where a puck block's centre sets the right puck bit (its mirror
    /// image sets the left one).
    pub puck_right: ImageRegion,
    /// Where a robot block's centre sets the right obstacle bit (its
    /// mirror image sets the left one).
    pub obstacle_right: ImageRegion,
}

impl CameraConfig {
    /// The defaults: pucks are signature 1, robots signature 2; a puck
    /// anywhere in the image's columns 80..=319 sets the right puck bit,
    /// one in columns 0..=239 the left one (so one ahead, in 80..=239, sets
    /// both, as the thesis' two puck discs both cover the ground ahead);
    /// a robot in the bottom quarter (rows 150..=199: close) of columns
    /// 100..=319 sets the right obstacle bit, of 0..=219 the left one.
    /// Chosen by a sweep with the robot sensor model on the TV
    /// (`docs/robot-sensors.md`).
    pub const DEFAULT: CameraConfig = CameraConfig {
        puck_signature: 1,
        robot_signature: 2,
        puck_right: ImageRegion {
            x_min: 80,
            x_max: IMAGE_WIDTH - 1,
            y_min: 0,
            y_max: IMAGE_HEIGHT - 1,
        },
        obstacle_right: ImageRegion {
            x_min: 100,
            x_max: IMAGE_WIDTH - 1,
            y_min: 150,
            y_max: IMAGE_HEIGHT - 1,
        },
    };

    /// The sensor bits of a set of blocks (any number, any order).
    pub fn classify(&self, blocks: &[PixyBlock]) -> BlobSummary {
        let mut s = BlobSummary::default();
        for b in blocks {
            // A block is in the left region when its mirror image is in the
            // right one: one row test and two column tests per region.
            let mirrored_x = (IMAGE_WIDTH - 1).saturating_sub(b.x);
            if b.signature == self.puck_signature {
                let (left, right) = self.puck_right.sides(mirrored_x, b.x, b.y);
                s.puck_left |= left;
                s.puck_right |= right;
            }
            if b.signature == self.robot_signature {
                let (left, right) = self.obstacle_right.sides(mirrored_x, b.x, b.y);
                s.obstacle_left |= left;
                s.obstacle_right |= right;
            }
        }
        s
    }
}

impl Default for CameraConfig {
    /// [`CameraConfig::DEFAULT`].
    fn default() -> CameraConfig {
        CameraConfig::DEFAULT
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn block(signature: u16, x: u16, y: u16) -> PixyBlock {
        PixyBlock {
            signature,
            x,
            y,
            width: 10,
            height: 10,
            angle: 0,
        }
    }

    #[test]
    fn nothing_seen_is_all_false() {
        assert_eq!(CameraConfig::DEFAULT.classify(&[]), BlobSummary::default());
    }

    #[test]
    fn sides_signatures_and_the_regions() {
        let c = CameraConfig::DEFAULT;
        let s = c.classify(&[block(1, 79, 20), block(2, 250, 199)]);
        assert_eq!(
            s,
            BlobSummary {
                puck_left: true,
                puck_right: false,
                obstacle_left: false,
                obstacle_right: true
            }
        );
        // A puck ahead is on both sides; a far robot and unknown signatures are ignored.
        let s = c.classify(&[block(1, 160, 5)]);
        assert!(s.puck_left && s.puck_right);
        assert_eq!(
            c.classify(&[block(3, 10, 150), block(2, 300, 149)]),
            BlobSummary::default()
        );
        // Region edges are inclusive.
        assert!(
            c.classify(&[block(1, 0, 199)]).puck_left
                && !c.classify(&[block(1, 0, 199)]).puck_right
        );
        assert!(c.classify(&[block(1, 80, 0)]).puck_right);
        assert!(c.classify(&[block(2, 219, 150)]).obstacle_left);
    }

    #[test]
    fn regions_with_a_gap_in_the_middle_and_their_mirror_images() {
        let sides = ImageRegion {
            x_min: 220,
            x_max: 319,
            y_min: 0,
            y_max: 199,
        };
        assert_eq!(
            sides.mirrored(),
            ImageRegion {
                x_min: 0,
                x_max: 99,
                y_min: 0,
                y_max: 199
            }
        );
        let c = CameraConfig {
            puck_right: sides,
            ..CameraConfig::DEFAULT
        };
        assert_eq!(
            c.classify(&[block(1, 160, 50)]),
            BlobSummary::default(),
            "straight ahead is in neither"
        );
        let s = c.classify(&[block(1, 99, 10), block(1, 220, 190)]);
        assert!(s.puck_left && s.puck_right && !s.obstacle_left);
        // Overlapping regions set both bits.
        let wide = CameraConfig {
            puck_right: ImageRegion {
                x_min: 100,
                ..sides
            },
            ..CameraConfig::DEFAULT
        };
        let s = wide.classify(&[block(1, 160, 50)]);
        assert!(s.puck_left && s.puck_right);
    }

    #[test]
    fn a_colour_code_can_be_the_robot_signature() {
        let c = CameraConfig {
            robot_signature: 0o12,
            ..CameraConfig::DEFAULT
        };
        let s = c.classify(&[PixyBlock {
            angle: -45,
            ..block(0o12, 20, 180)
        }]);
        assert!(s.obstacle_left && !s.obstacle_right && !s.puck_left);
    }
}
