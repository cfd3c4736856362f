//! A recorded log as `host view --log` plays it: every decoded frame
//! checked against the policy stage by stage, as `host replay` checks it
//! ([`DecisionCheck`]), with the robot's pose dead-reckoned from its wheel
//! encoders ([`PlaybackFrame`], one at a time as the log is read: the
//! caller writes each into the page's document), and what the page needs
//! besides the frames ([`Playback`]).
//!
//! The pose: a log carries no position, so each robot's track starts at
//! the arena's centre facing +x and adds each frame's encoder travel
//! ([`OdometrySettings::travel`]: the period before the frame; a lost frame
//! loses its period's travel). It drifts as any dead reckoning does.

use super::decisions::DecisionCheck;
use super::odometry::OdometrySettings;
use super::report::FrameCheck;
use crate::robot::log_file::Entry;
use serde::Serialize;
use shared::camera::{ImageRegion, IMAGE_HEIGHT, IMAGE_WIDTH};
use shared::{CameraConfig, Faults, PolicyBlob};
use std::collections::BTreeMap;

/// The checked log, but its frames.
#[derive(Clone, Debug, Serialize)]
pub struct Playback {
    /// The policy's hasher.
    pub hasher: String,
    /// Actions of the policy.
    pub actions: usize,
    /// Frames that decoded (the document's `frames` is their list).
    #[serde(skip)]
    pub frames: usize,
    /// Frames with a divergent stage.
    pub diverged: u64,
    /// Records or frames that did not decode (skipped).
    pub damaged: u64,
    /// The camera's regions, as the firmware classifies blocks.
    pub camera: CameraRegions,
    /// Each fault flag's bit and name.
    pub faults: Vec<(u8, &'static str)>,
}

/// One frame: its check and where the robot was.
#[derive(Clone, Debug, Serialize)]
pub struct PlaybackFrame {
    /// What it logged beside what each stage should have produced.
    #[serde(flatten)]
    pub check: FrameCheck,
    /// The robot's id.
    pub robot_id: u8,
    /// Dead-reckoned position (units) and heading (radians, clockwise on
    /// screen from +x).
    pub pose: [f64; 3],
}

/// The camera image and the regions whose blocks set the blob bits, each
/// `[x_min, x_max, y_min, y_max]` in pixels, bounds inclusive.
#[derive(Clone, Debug, Serialize)]
pub struct CameraRegions {
    /// Image width and height, pixels.
    pub image: [u16; 2],
    /// Where a puck sets the left bit.
    pub puck_left: [u16; 4],
    /// Where a puck sets the right bit.
    pub puck_right: [u16; 4],
    /// Where a robot sets the left obstacle bit.
    pub obstacle_left: [u16; 4],
    /// Where a robot sets the right obstacle bit.
    pub obstacle_right: [u16; 4],
}

impl CameraRegions {
    /// The regions of `config`.
    pub fn of(config: &CameraConfig) -> CameraRegions {
        let r = |g: ImageRegion| [g.x_min, g.x_max, g.y_min, g.y_max];
        CameraRegions {
            image: [IMAGE_WIDTH, IMAGE_HEIGHT],
            puck_left: r(config.puck_right.mirrored()),
            puck_right: r(config.puck_right),
            obstacle_left: r(config.obstacle_right.mirrored()),
            obstacle_right: r(config.obstacle_right),
        }
    }
}

/// Checks frame after frame against a policy and tracks each robot from
/// the centre of the arena.
pub struct Player<'a> {
    policy: &'a PolicyBlob,
    check: DecisionCheck<'a>,
    odometry: OdometrySettings,
    arena: [f64; 2],
    poses: BTreeMap<u8, [f64; 3]>,
    frames: usize,
    damaged: u64,
}

impl<'a> Player<'a> {
    /// A player of `policy`'s robots on an arena of `arena` units (width,
    /// height).
    pub fn new(policy: &'a PolicyBlob, odometry: OdometrySettings, arena: [f64; 2]) -> Player<'a> {
        Player {
            policy,
            check: DecisionCheck::new(policy),
            odometry,
            arena,
            poses: BTreeMap::new(),
            frames: 0,
            damaged: 0,
        }
    }

    /// The next entry of the log, checked: `None` for one that does not
    /// decode (counted as damaged).
    pub fn entry(&mut self, entry: &Entry) -> Option<PlaybackFrame> {
        let Some(frame) = entry.log_frame() else {
            self.damaged += 1;
            return None;
        };
        self.frames += 1;
        let arena = self.arena;
        let pose =
            self.poses
                .entry(frame.robot_id)
                .or_insert([arena[0] / 2.0, arena[1] / 2.0, 0.0]);
        let (forward, turn) = self.odometry.travel(frame.encoder_counts);
        // the period's heading: half its turn before and half after
        let heading = pose[2] + turn / 2.0;
        *pose = [
            pose[0] + forward * heading.cos(),
            pose[1] + forward * heading.sin(),
            pose[2] + turn,
        ];
        Some(PlaybackFrame {
            check: self.check.frame(entry.offset, &frame),
            robot_id: frame.robot_id,
            pose: *pose,
        })
    }

    /// What the page needs besides the frames.
    pub fn finish(self) -> Playback {
        Playback {
            hasher: self.policy.hasher().to_string(),
            actions: self.policy.actions().len(),
            frames: self.frames,
            diverged: self.check.diverged,
            damaged: self.damaged,
            camera: CameraRegions::of(&CameraConfig::DEFAULT),
            faults: Faults::NAMED.iter().map(|(f, name)| (f.0, *name)).collect(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_left_regions_mirror_the_right_ones_about_the_centre_column() {
        let c = CameraRegions::of(&CameraConfig::DEFAULT);
        assert_eq!(c.image, [320, 200]);
        assert_eq!(c.puck_right, [80, 319, 0, 199]);
        assert_eq!(c.puck_left, [0, 239, 0, 199]);
        assert_eq!(c.obstacle_right, [100, 319, 150, 199]);
        assert_eq!(c.obstacle_left, [0, 219, 150, 199]);
    }
}
