//! The robot's Pixy (CMUcam5 v1) camera as the simulator models it: which
//! blocks it reports for the bodies in front of a robot.
//!
//! A pinhole camera on the robot (forward offset, height, tilt down,
//! 75 x 47 degree field of view, 320 x 200 image) sees every other body as
//! a vertical cylinder (pucks and robots have their own heights), coloured
//! with its kind's signature ([`CameraConfig`]: pucks 1, robots 2). Per
//! frame, like the Pixy's own blob pipeline (`docs/robot-sensors.md`):
//! 1. each body's silhouette is the bounding box of 2 x 12 points on its
//!    bottom and top rims, clipped to the image; bodies beyond
//!    `max_range`, or reaching behind the image plane, are not seen;
//! 2. occlusion: nearer bodies' boxes hide what is behind them; a body's
//!    block is the bounding box of its still visible part, its pixel count
//!    the visible area;
//! 3. blobs under `min_area` pixels are dropped (the Pixy's 20), blobs of
//!    one signature closer than `merge_distance` pixels merge (its 5), and
//!    a block inside another block is dropped;
//! 4. order: signature 1's blocks largest first, then signature 2's, as the
//!    Pixy sends them, at most `max_blocks_per_signature` of each (the
//!    Pixy's "max blocks per signature" setting). The firmware reads the
//!    first [`shared::camera::MAX_BLOCKS_PER_PERIOD`]: with the default of
//!    2 per signature that is both kinds' two largest, otherwise distant
//!    pucks would fill the four slots and robots would never be read.
//!
//! Block fields follow the Pixy: `width = right - left`, `x = left + width / 2`
//! (integer), likewise for y, with inclusive pixel bounds.

use crate::validate::{check, positive, ConfigError};
use crate::vec2::Vec2;
use crate::world::World;
use serde::{Deserialize, Serialize};
use shared::camera::{IMAGE_HEIGHT, IMAGE_WIDTH};
use shared::{CameraConfig, PixyBlock};
use std::cmp::Ordering;

/// Where the camera sits, what it sees, and how it forms blocks. Lengths
/// are in millimetres.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct PixyCameraConfig {
    /// Lens position ahead of the robot's centre, mm.
    pub forward_mm: f64,
    /// Lens height above the floor, mm.
    pub height_mm: f64,
    /// Optical axis below the horizontal, degrees.
    pub tilt_deg: f64,
    /// Horizontal field of view, degrees.
    pub fov_h_deg: f64,
    /// Vertical field of view, degrees.
    pub fov_v_deg: f64,
    /// Height of a puck's coloured body, mm.
    pub puck_height_mm: f64,
    /// Height of a robot's coloured marker (from the floor up), mm.
    pub robot_height_mm: f64,
    /// Bodies whose nearest point is farther than this are not seen, mm.
    pub max_range_mm: f64,
    /// Smallest blob the camera reports, pixels.
    pub min_area: u32,
    /// Blobs of one signature this close (pixels) merge into one block.
    pub merge_distance: u16,
    /// Most blocks the camera sends per signature (the Pixy's "max blocks
    /// per signature", set with PixyMon).
    pub max_blocks_per_signature: u16,
    /// Signatures and the classification into puck and obstacle bits (the
    /// firmware's `config::CAMERA`).
    pub classify: CameraConfig,
    /// Periods between a frame's capture and its arrival at the robot: 1
    /// (the Pixy processes a frame while capturing the next, at 50 frames
    /// per second: one 20 ms period), or 0 for an ideal camera.
    pub latency_frames: u8,
}

impl Default for PixyCameraConfig {
    /// A Pixy on a bracket above the Zumo's centre (estimates, to be
    /// measured: `docs/robot-sensors.md`): lens 15 mm ahead of the centre
    /// and 80 mm high, tilted 20 degrees down; pucks 30 mm and robots'
    /// markers 60 mm tall; range 1.25 m; the Pixy's own blob settings (20
    /// pixels, merge at 5); 2 blocks per signature; the firmware's
    /// classification; one frame of latency.
    fn default() -> PixyCameraConfig {
        PixyCameraConfig {
            forward_mm: 15.0,
            height_mm: 80.0,
            tilt_deg: 20.0,
            fov_h_deg: 75.0,
            fov_v_deg: 47.0,
            puck_height_mm: 30.0,
            robot_height_mm: 60.0,
            max_range_mm: 1250.0,
            min_area: 20,
            merge_distance: 5,
            max_blocks_per_signature: 2,
            classify: CameraConfig::DEFAULT,
            latency_frames: 1,
        }
    }
}

impl PixyCameraConfig {
    /// Checks the pose, field of view, heights and range.
    pub fn validate(&self) -> Result<(), ConfigError> {
        check("camera.forward_mm", self.forward_mm, true, "must be a finite number")?;
        positive("camera.height_mm", self.height_mm)?;
        for (name, fov) in [("camera.fov_h_deg", self.fov_h_deg), ("camera.fov_v_deg", self.fov_v_deg)] {
            check(name, fov, fov > 0.0 && fov < 180.0, "must be between 0 and 180 degrees")?;
        }
        let half = self.fov_v_deg / 2.0;
        check(
            "camera.tilt_deg",
            self.tilt_deg,
            self.tilt_deg + half < 90.0 && self.tilt_deg - half > -90.0,
            "with half the vertical field of view must stay within +-90 degrees",
        )?;
        positive("camera.puck_height_mm", self.puck_height_mm)?;
        positive("camera.robot_height_mm", self.robot_height_mm)?;
        positive("camera.max_range_mm", self.max_range_mm)?;
        let l = f64::from(self.latency_frames);
        check("camera.latency_frames", l, self.latency_frames <= 1, "must be 0 or 1")
    }
}

/// A rectangle of pixels, bounds inclusive.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
struct Rect {
    left: i32,
    top: i32,
    right: i32,
    bottom: i32,
}

impl Rect {
    fn area(&self) -> u32 {
        ((self.right - self.left + 1) * (self.bottom - self.top + 1)) as u32
    }

    fn overlaps(&self, o: &Rect) -> bool {
        self.left <= o.right && o.left <= self.right && self.top <= o.bottom && o.top <= self.bottom
    }

    fn contains(&self, o: &Rect) -> bool {
        self.left <= o.left && self.right >= o.right && self.top <= o.top && self.bottom >= o.bottom
    }

    fn union(&self, o: &Rect) -> Rect {
        Rect {
            left: self.left.min(o.left),
            top: self.top.min(o.top),
            right: self.right.max(o.right),
            bottom: self.bottom.max(o.bottom),
        }
    }

    /// Pixels between the two along x (0 or less if their columns overlap).
    fn gap_x(&self, o: &Rect) -> i32 {
        self.left.max(o.left) - self.right.min(o.right)
    }

    fn gap_y(&self, o: &Rect) -> i32 {
        self.top.max(o.top) - self.bottom.min(o.bottom)
    }

    /// Appends the parts of `self` outside `cut` (up to four rectangles).
    fn subtract_into(&self, cut: &Rect, out: &mut Vec<Rect>) {
        if !self.overlaps(cut) {
            out.push(*self);
            return;
        }
        if self.top < cut.top {
            out.push(Rect { bottom: cut.top - 1, ..*self });
        }
        if self.bottom > cut.bottom {
            out.push(Rect { top: cut.bottom + 1, ..*self });
        }
        let (top, bottom) = (self.top.max(cut.top), self.bottom.min(cut.bottom));
        if self.left < cut.left {
            out.push(Rect { top, bottom, right: cut.left - 1, ..*self });
        }
        if self.right > cut.right {
            out.push(Rect { top, bottom, left: cut.right + 1, ..*self });
        }
    }
}

/// A body in view: its distance for occlusion and its full silhouette.
#[derive(Clone, Copy, Debug)]
struct InView {
    distance: f64,
    index: usize,
    signature: u16,
    rect: Rect,
}

/// A blob after occlusion: bounding box and pixel count.
#[derive(Clone, Copy, Debug)]
struct Blob {
    signature: u16,
    rect: Rect,
    area: u32,
}

/// Rim points sampled per circle of a body's cylinder.
const RIM_POINTS: usize = 12;

/// The camera of a robot of a given radius, with scratch space so that a
/// frame allocates nothing once warmed up.
#[derive(Clone, Debug)]
pub struct PixyCamera {
    forward: f64,
    height: f64,
    cos_tilt: f64,
    sin_tilt: f64,
    /// Focal lengths in pixels.
    fx: f64,
    fy: f64,
    /// tan(half the horizontal field of view), for culling.
    tan_half_h: f64,
    puck_height: f64,
    robot_height: f64,
    max_range: f64,
    /// Points nearer than this to the image plane (units) make a body unseen.
    near: f64,
    min_area: u32,
    merge_distance: i32,
    per_signature: usize,
    classify: CameraConfig,
    rim: [Vec2; RIM_POINTS],
    in_view: Vec<InView>,
    pieces: Vec<Rect>,
    scratch: Vec<Rect>,
    blobs: Vec<Blob>,
}

impl PixyCamera {
    /// The camera of `config` in a world of `unit_mm` millimetres per unit.
    pub fn new(config: &PixyCameraConfig, unit_mm: f64) -> PixyCamera {
        let tilt = config.tilt_deg.to_radians();
        let half_h = (config.fov_h_deg / 2.0).to_radians();
        let half_v = (config.fov_v_deg / 2.0).to_radians();
        PixyCamera {
            forward: config.forward_mm / unit_mm,
            height: config.height_mm / unit_mm,
            cos_tilt: tilt.cos(),
            sin_tilt: tilt.sin(),
            fx: f64::from(IMAGE_WIDTH) / 2.0 / half_h.tan(),
            fy: f64::from(IMAGE_HEIGHT) / 2.0 / half_v.tan(),
            tan_half_h: half_h.tan(),
            puck_height: config.puck_height_mm / unit_mm,
            robot_height: config.robot_height_mm / unit_mm,
            max_range: config.max_range_mm / unit_mm,
            near: 0.5 / unit_mm,
            min_area: config.min_area,
            merge_distance: i32::from(config.merge_distance),
            per_signature: usize::from(config.max_blocks_per_signature),
            classify: config.classify,
            rim: std::array::from_fn(|k| Vec2::from_angle(std::f64::consts::TAU * k as f64 / RIM_POINTS as f64)),
            in_view: Vec::new(),
            pieces: Vec::new(),
            scratch: Vec::new(),
            blobs: Vec::new(),
        }
    }

    /// The classification the firmware applies to the blocks.
    pub fn classify(&self) -> &CameraConfig {
        &self.classify
    }

    /// The frame robot `robot` sees: every block, in the order the Pixy
    /// sends them (replaces `out`'s contents). The four stages of the
    /// module docs, in order.
    pub fn frame(&mut self, world: &World, robot: usize, out: &mut Vec<PixyBlock>) {
        self.gather_in_view(world, robot);
        self.occlude();
        self.merge_and_prune();
        self.emit_blocks(out);
    }

    /// Stage 1: every other body in range and in front of the lens, with its
    /// silhouette, nearest first (ties by body index).
    fn gather_in_view(&mut self, world: &World, robot: usize) {
        let bodies = world.bodies();
        let robots = world.robots().len();
        let (pos, dir) = (bodies[robot].pos, world.robots()[robot].direction);
        let right = Vec2::new(-dir.y, dir.x);
        let lens = pos + dir * self.forward;

        let mut in_view = std::mem::take(&mut self.in_view);
        in_view.clear();
        world.any_body_near(lens, self.max_range, |row| {
            for b in row {
                let j = b.body as usize;
                if j == robot {
                    continue;
                }
                let rel = b.pos - lens;
                let f = rel.dot(dir);
                // Cheap culls before projecting: behind the lens, far outside the
                // horizontal field of view, or out of range.
                if f + b.radius < 0.0 {
                    continue;
                }
                let (height, signature) = if j < robots {
                    (self.robot_height, self.classify.robot_signature)
                } else {
                    (self.puck_height, self.classify.puck_signature)
                };
                let s = rel.dot(right);
                if s.abs() > (f + b.radius + self.height + height) * self.tan_half_h + b.radius {
                    continue;
                }
                let reach = self.max_range + b.radius;
                let distance_squared = f * f + s * s;
                if distance_squared > reach * reach {
                    continue;
                }
                if let Some(rect) = self.silhouette(f, s, b.radius, height) {
                    in_view.push(InView { distance: distance_squared.sqrt(), index: j, signature, rect });
                }
            }
            false
        });
        in_view
            .sort_by(|a, b| a.distance.partial_cmp(&b.distance).unwrap_or(Ordering::Equal).then(a.index.cmp(&b.index)));
        self.in_view = in_view;
    }

    /// Stage 2: each body's still visible part after the nearer ones'
    /// silhouettes are cut away, as a blob (bounding box, pixel count) if it
    /// has at least `min_area` pixels.
    fn occlude(&mut self) {
        self.blobs.clear();
        for (k, body) in self.in_view.iter().enumerate() {
            self.pieces.clear();
            self.pieces.push(body.rect);
            for nearer in &self.in_view[..k] {
                if !nearer.rect.overlaps(&body.rect) {
                    continue;
                }
                self.scratch.clear();
                for piece in &self.pieces {
                    piece.subtract_into(&nearer.rect, &mut self.scratch);
                }
                std::mem::swap(&mut self.pieces, &mut self.scratch);
                if self.pieces.is_empty() {
                    break;
                }
            }
            let Some(first) = self.pieces.first() else { continue };
            let rect = self.pieces.iter().fold(*first, |r, p| r.union(p));
            let area = self.pieces.iter().map(Rect::area).sum();
            if area >= self.min_area {
                self.blobs.push(Blob { signature: body.signature, rect, area });
            }
        }
    }

    /// Stage 4: the blobs as Pixy blocks, signature 1 first, largest first,
    /// at most `max_blocks_per_signature` of each.
    fn emit_blocks(&mut self, out: &mut Vec<PixyBlock>) {
        out.clear();
        self.blobs.sort_by(|a, b| {
            a.signature
                .cmp(&b.signature)
                .then(b.area.cmp(&a.area))
                .then(a.rect.left.cmp(&b.rect.left))
                .then(a.rect.top.cmp(&b.rect.top))
        });
        let per_signature = self.per_signature;
        let mut kept = 0;
        out.extend(
            self.blobs
                .iter()
                .enumerate()
                .filter_map(|(i, b)| {
                    // Blobs are grouped by signature: count within the group.
                    kept = if i > 0 && self.blobs[i - 1].signature == b.signature { kept + 1 } else { 1 };
                    (kept <= per_signature).then_some(b)
                })
                .map(|b| {
                    let (width, height) = ((b.rect.right - b.rect.left) as u16, (b.rect.bottom - b.rect.top) as u16);
                    PixyBlock {
                        signature: b.signature,
                        x: b.rect.left as u16 + width / 2,
                        y: b.rect.top as u16 + height / 2,
                        width,
                        height,
                        angle: 0,
                    }
                }),
        );
    }

    /// The clipped pixel box of a cylinder of `radius` and `height` whose
    /// axis is `f` ahead of and `s` right of the lens; `None` if it is out
    /// of the image or reaches behind the image plane.
    fn silhouette(&self, f: f64, s: f64, radius: f64, height: f64) -> Option<Rect> {
        let (mut min_x, mut max_x, mut min_y, mut max_y) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
        for z in [0.0, height] {
            let up = z - self.height;
            for p in &self.rim {
                let (pf, ps) = (f + radius * p.x, s + radius * p.y);
                let depth = pf * self.cos_tilt - up * self.sin_tilt;
                if depth < self.near {
                    return None;
                }
                let down = -pf * self.sin_tilt - up * self.cos_tilt;
                let inverse = 1.0 / depth;
                let x = f64::from(IMAGE_WIDTH) / 2.0 + self.fx * ps * inverse;
                let y = f64::from(IMAGE_HEIGHT) / 2.0 + self.fy * down * inverse;
                // Plain comparisons: no NaN can occur (depth >= near > 0).
                if x < min_x {
                    min_x = x;
                }
                if x > max_x {
                    max_x = x;
                }
                if y < min_y {
                    min_y = y;
                }
                if y > max_y {
                    max_y = y;
                }
            }
        }
        let clip = |v: f64, hi: u16| v.clamp(-1.0, f64::from(hi)) as i32;
        let rect = Rect {
            left: clip(min_x.floor(), IMAGE_WIDTH).max(0),
            right: clip(max_x.ceil() - 1.0, IMAGE_WIDTH).min(i32::from(IMAGE_WIDTH) - 1),
            top: clip(min_y.floor(), IMAGE_HEIGHT).max(0),
            bottom: clip(max_y.ceil() - 1.0, IMAGE_HEIGHT).min(i32::from(IMAGE_HEIGHT) - 1),
        };
        (rect.left <= rect.right && rect.top <= rect.bottom).then_some(rect)
    }

    /// Stage 3: merges close blobs of one signature until none are left,
    /// then drops blocks enclosed by another block (the Pixy's `combine2`,
    /// `combine`).
    fn merge_and_prune(&mut self) {
        let d = self.merge_distance;
        let blobs = &mut self.blobs;
        let mut merged = true;
        while merged {
            merged = false;
            'outer: for i in 0..blobs.len() {
                for j in i + 1..blobs.len() {
                    let (a, b) = (blobs[i], blobs[j]);
                    let (gx, gy) = (a.rect.gap_x(&b.rect), a.rect.gap_y(&b.rect));
                    if a.signature == b.signature && ((gx <= d && gy <= 0) || (gy <= d && gx <= 0)) {
                        blobs[i] = Blob { signature: a.signature, rect: a.rect.union(&b.rect), area: a.area + b.area };
                        blobs.remove(j);
                        merged = true;
                        break 'outer;
                    }
                }
            }
        }
        let mut k = 0;
        while k < blobs.len() {
            let enclosed = (0..blobs.len())
                .any(|o| o != k && blobs[o].rect.contains(&blobs[k].rect) && (blobs[o].rect != blobs[k].rect || o < k));
            if enclosed {
                blobs.remove(k);
            } else {
                k += 1;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::body::RobotKind;
    use crate::config::SimConfig;
    use shared::ImageRegion;

    const R: f64 = 10.0;

    /// Robot 0 at (400, 400) facing +x (its right is +y), plus other robots
    /// and pucks at offsets (ahead, right) in robot radii.
    fn frame_of(robots: &[(f64, f64)], pucks: &[(f64, f64)]) -> Vec<PixyBlock> {
        frame_with(&PixyCameraConfig::default(), robots, pucks)
    }

    fn frame_with(camera: &PixyCameraConfig, robots: &[(f64, f64)], pucks: &[(f64, f64)]) -> Vec<PixyBlock> {
        let mut config = SimConfig::default();
        config.world.robots = 1 + robots.len();
        config.world.pucks = pucks.len();
        let at = |(f, s): (f64, f64)| Vec2::new(400.0 + f * R, 400.0 + s * R);
        let mut scene = vec![(Vec2::new(400.0, 400.0), 0.0, RobotKind::Outie)];
        scene.extend(robots.iter().map(|&p| (at(p), 0.0, RobotKind::Outie)));
        let pucks: Vec<Vec2> = pucks.iter().map(|&p| at(p)).collect();
        let world = World::scene(&config, &scene, &pucks, 1);
        let mut camera = PixyCamera::new(camera, 5.0);
        let mut out = Vec::new();
        camera.frame(&world, 0, &mut out);
        out
    }

    #[test]
    fn a_puck_straight_ahead_is_one_centred_near_block() {
        let blocks = frame_of(&[], &[(3.0, 0.0)]);
        assert_eq!(blocks.len(), 1, "{blocks:?}");
        let b = blocks[0];
        assert_eq!(b.signature, 1);
        assert!(b.x.abs_diff(160) <= 1, "{b:?}");
        assert!(b.y >= 100, "a puck 3 radii ahead is in the lower half: {b:?}");
        let s = CameraConfig::DEFAULT.classify(&blocks);
        assert!(s.puck_left && s.puck_right, "ahead is on both sides");
    }

    #[test]
    fn left_and_right_are_the_robots_left_and_right() {
        let left = frame_of(&[], &[(4.0, -1.5)]);
        let right = frame_of(&[], &[(4.0, 1.5)]);
        assert!(left[0].x < 160 && right[0].x >= 160, "{left:?} {right:?}");
        let s = CameraConfig::DEFAULT.classify(&left);
        assert!(s.puck_left && !s.puck_right);
    }

    #[test]
    fn the_field_of_view_is_75_degrees_so_the_thesis_side_discs_are_blind() {
        // The thesis' outer puck disc at 60 degrees, 7 radii: outside +-37.5.
        let (f, s) = (7.0 * 60f64.to_radians().cos(), 7.0 * 60f64.to_radians().sin());
        assert!(frame_of(&[], &[(f, s), (f, -s)]).is_empty());
        // Behind the robot: nothing.
        assert!(frame_of(&[], &[(-4.0, 0.0)]).is_empty());
        // At 30 degrees it is seen.
        let (f, s) = (7.0 * 30f64.to_radians().cos(), 7.0 * 30f64.to_radians().sin());
        assert_eq!(frame_of(&[], &[(f, s)]).len(), 1);
    }

    #[test]
    fn robots_show_signature_two_after_the_pucks_and_blocks_are_largest_first() {
        let blocks = frame_of(&[(3.0, 2.0)], &[(8.0, -2.0), (3.0, -1.5)]);
        let sigs: Vec<u16> = blocks.iter().map(|b| b.signature).collect();
        assert_eq!(sigs, [1, 1, 2], "{blocks:?}");
        assert!(blocks[0].width * blocks[0].height > blocks[1].width * blocks[1].height);
        let halves = ImageRegion { x_min: 160, x_max: 319, y_min: 100, y_max: 199 };
        let s = CameraConfig { obstacle_right: halves, ..CameraConfig::DEFAULT }.classify(&blocks);
        assert!(s.obstacle_right && !s.obstacle_left);
    }

    #[test]
    fn a_puck_hidden_behind_a_robot_is_not_seen_and_small_far_ones_are_dropped() {
        let blocks = frame_of(&[(3.0, 0.0)], &[(6.0, 0.0)]);
        assert_eq!(blocks.iter().map(|b| b.signature).collect::<Vec<_>>(), [2], "{blocks:?}");
        // The range ends at 25 radii; far blocks are small and high in the image.
        let far = frame_of(&[], &[(24.0, 0.0)]);
        assert!(far.len() == 1 && far[0].y < 100 && far[0].width * far[0].height < 200, "{far:?}");
        assert!(frame_of(&[], &[(27.0, 0.0)]).is_empty());
        // Blobs under the minimum area are dropped.
        let strict = PixyCameraConfig { min_area: 200, ..PixyCameraConfig::default() };
        assert!(frame_with(&strict, &[], &[(24.0, 0.0)]).is_empty());
    }

    #[test]
    fn each_signature_sends_its_largest_blocks_up_to_the_cap() {
        let pucks = [(4.0, -2.5), (7.0, 0.0), (12.0, 3.0), (16.0, -4.0)];
        let blocks = frame_of(&[(10.0, 5.0)], &pucks);
        let sigs: Vec<u16> = blocks.iter().map(|b| b.signature).collect();
        assert_eq!(sigs, [1, 1, 2], "{blocks:?}");
        let all = PixyCameraConfig { max_blocks_per_signature: 10, ..PixyCameraConfig::default() };
        let blocks = frame_with(&all, &[(10.0, 5.0)], &pucks);
        assert!(blocks.iter().filter(|b| b.signature == 1).count() > 2, "{blocks:?}");
        assert_eq!(blocks.last().map(|b| b.signature), Some(2));
    }

    #[test]
    fn touching_pucks_merge_into_one_block() {
        let blocks = frame_of(&[], &[(5.0, -1.0), (5.0, 1.0)]);
        assert_eq!(blocks.len(), 1, "{blocks:?}");
        assert!(blocks[0].x.abs_diff(160) <= 1);
    }

    #[test]
    fn rectangle_subtraction_keeps_exactly_the_uncovered_pixels() {
        let a = Rect { left: 0, top: 0, right: 9, bottom: 9 };
        let cut = Rect { left: 3, top: 4, right: 5, bottom: 20 };
        let mut out = Vec::new();
        a.subtract_into(&cut, &mut out);
        assert_eq!(out.iter().map(Rect::area).sum::<u32>(), 100 - 3 * 6);
        for p in &out {
            assert!(!p.overlaps(&cut) && a.contains(p));
        }
    }

    #[test]
    fn bad_poses_are_named() {
        let c = PixyCameraConfig { tilt_deg: 70.0, ..PixyCameraConfig::default() };
        assert!(c.validate().unwrap_err().to_string().contains("camera.tilt_deg"));
        let c = PixyCameraConfig { height_mm: -1.0, ..PixyCameraConfig::default() };
        assert!(c.validate().unwrap_err().to_string().contains("camera.height_mm"));
        assert!(PixyCameraConfig::default().validate().is_ok());
    }
}
