//! The robot's Pixy (CMUcam5 v1) camera as the simulator models it: which
//! blocks it reports for the bodies in front of a robot.
//!
//! A pinhole camera on the robot (forward offset, height, tilt down,
//! 75 x 47 degree field of view, 320 x 200 image) sees every other body as
//! a vertical cylinder (pucks and robots have their own heights), coloured
//! with its kind's signature ([`CameraConfig`]: pucks 1, robots 2). Per
//! frame, like the Pixy's own blob pipeline (`docs/robot-sensors.md`):
//! 1. each body's silhouette is the bounding box of 2 x 12 points on its
//!    bottom and top rims, clipped to the image (a wedge-fronted robot,
//!    `crate::config::robot_shape::RobotShape::Wedge`, is a prism on its
//!    outline: the rim points of its round back, its tangent points and
//!    its tip, at the bottom and the top, [`PixyCamera::outline_silhouette`]); bodies beyond
//!    `max_range`, or reaching behind the image plane, are not seen (only
//!    the bodies in a box around the view cone are visited, and cheap
//!    culls come before projecting);
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
//! The stages are written for speed; `pixy_camera/reference.rs` (tests
//! only) keeps them as first written, and the tests check that both give
//! the same frames, block for block. On x86-64 processors with AVX2 the
//! projection runs four lanes wide (chosen at run time); it rounds every
//! operation as the two-lane one does, so frames do not depend on the
//! processor.
//!
//! Block fields follow the Pixy: `width = right - left`, `x = left + width / 2`
//! (integer), likewise for y, with inclusive pixel bounds.

use crate::base::ranges;
use crate::base::vec2::Vec2;
use crate::config::robot_shape::RobotShape;
use crate::config::validate::{check, ConfigError};
use crate::config::WorldConfig;
use crate::physics::grid::Neighbour;
use crate::physics::outline::Outline;
use crate::world::World;
use serde::{Deserialize, Serialize};
use shared::camera::{IMAGE_HEIGHT, IMAGE_WIDTH};
use shared::{CameraConfig, PixyBlock};
use std::cmp::Reverse;

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
    /// Checks the pose, field of view, heights, range and blob settings.
    pub fn validate(&self) -> Result<(), ConfigError> {
        ranges::MOUNT_MM.check_as("camera.forward_mm", self.forward_mm)?;
        ranges::HEIGHT_MM.check(self.height_mm)?;
        ranges::FOV_DEG.check(self.fov_h_deg)?;
        ranges::FOV_DEG.check_as("camera.fov_v_deg", self.fov_v_deg)?;
        ranges::TILT_DEG.check(self.tilt_deg)?;
        let half = self.fov_v_deg / 2.0;
        check(
            "camera.tilt_deg",
            self.tilt_deg,
            self.tilt_deg + half < 90.0 && self.tilt_deg - half > -90.0,
            "with half the vertical field of view must stay within +-90 degrees",
        )?;
        ranges::HEIGHT_MM.check_as("camera.puck_height_mm", self.puck_height_mm)?;
        ranges::HEIGHT_MM.check_as("camera.robot_height_mm", self.robot_height_mm)?;
        ranges::CAMERA_RANGE_MM.check(self.max_range_mm)?;
        ranges::MIN_AREA_PX.check_count("camera.min_area", u64::from(self.min_area))?;
        ranges::IMAGE_PX.check_count("camera.merge_distance", u64::from(self.merge_distance))?;
        ranges::BLOCKS_PER_SIGNATURE.check_count(
            "camera.max_blocks_per_signature",
            u64::from(self.max_blocks_per_signature),
        )?;
        ranges::LATENCY_FRAMES
            .check_count("camera.latency_frames", u64::from(self.latency_frames))?;
        Ok(())
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

    /// The bounding box and pixel count of the part of `self` outside
    /// `cut`, which overlaps it; `None` if `cut` covers it. The box is
    /// `self`'s, but narrower where `cut` spans all its rows from one side
    /// (lower where it spans all its columns from one side).
    fn without(&self, cut: &Rect) -> Option<(Rect, u32)> {
        let c = Rect {
            left: self.left.max(cut.left),
            top: self.top.max(cut.top),
            right: self.right.min(cut.right),
            bottom: self.bottom.min(cut.bottom),
        };
        if c == *self {
            return None;
        }
        let mut rect = *self;
        if c.top == self.top && c.bottom == self.bottom {
            if c.left == self.left {
                rect.left = c.right + 1;
            }
            if c.right == self.right {
                rect.right = c.left - 1;
            }
        } else if c.left == self.left && c.right == self.right {
            if c.top == self.top {
                rect.top = c.bottom + 1;
            }
            if c.bottom == self.bottom {
                rect.bottom = c.top - 1;
            }
        }
        Some((rect, self.area() - c.area()))
    }

    /// Appends the parts of `self` outside `cut` (up to four rectangles).
    fn subtract_into(&self, cut: &Rect, out: &mut Vec<Rect>) {
        if !self.overlaps(cut) {
            out.push(*self);
            return;
        }
        if self.top < cut.top {
            out.push(Rect {
                bottom: cut.top - 1,
                ..*self
            });
        }
        if self.bottom > cut.bottom {
            out.push(Rect {
                top: cut.bottom + 1,
                ..*self
            });
        }
        let (top, bottom) = (self.top.max(cut.top), self.bottom.min(cut.bottom));
        if self.left < cut.left {
            out.push(Rect {
                top,
                bottom,
                right: cut.left - 1,
                ..*self
            });
        }
        if self.right > cut.right {
            out.push(Rect {
                top,
                bottom,
                left: cut.right + 1,
                ..*self
            });
        }
    }
}

/// A body in view: its distance for occlusion and its full silhouette.
#[derive(Clone, Copy, Debug)]
struct InView {
    distance: f64,
    index: u32,
    signature: u16,
    rect: Rect,
}

/// A blob after occlusion: bounding box and pixel count.
#[derive(Clone, Copy, Debug, PartialEq)]
struct Blob {
    signature: u16,
    rect: Rect,
    area: u32,
}

impl Blob {
    /// Whether the two merge into one block: the same signature, and apart
    /// by at most `merge_distance` pixels along one axis while their
    /// spans overlap along the other.
    fn merges_with(&self, o: &Blob, merge_distance: i32) -> bool {
        if self.signature != o.signature {
            return false;
        }
        let (gx, gy) = (self.rect.gap_x(&o.rect), self.rect.gap_y(&o.rect));
        (gx <= merge_distance && gy <= 0) || (gy <= merge_distance && gx <= 0)
    }

    /// The two as one blob: the union of their boxes, the sum of their pixels.
    fn merged(&self, o: &Blob) -> Blob {
        Blob {
            signature: self.signature,
            rect: self.rect.union(&o.rect),
            area: self.area + o.area,
        }
    }
}

/// Where a robot's lens is and where it looks, in the world's frame.
#[derive(Clone, Copy, Debug)]
struct Lens {
    pos: Vec2,
    /// Unit vector along the robot's heading.
    ahead: Vec2,
    /// Unit vector to the robot's right.
    right: Vec2,
}

/// A body that passed the culls of [`PixyCamera::candidate`]: where it is
/// seen from, before its silhouette is projected.
#[derive(Clone, Copy, Debug)]
struct Candidate {
    index: usize,
    signature: u16,
    /// Its centre's distance ahead of the lens and to the right of it.
    ahead: f64,
    side: f64,
    radius: f64,
    height: f64,
    /// `ahead^2 + side^2`.
    distance_squared: f64,
}

/// Rim points sampled per circle of a body's cylinder.
const RIM_POINTS: usize = 12;
const _: () = assert!(RIM_POINTS == 12, "`halving` halves 12 lanes");

/// The camera of a robot of a given radius, with scratch space so that a
/// frame allocates nothing once warmed up.
#[derive(Clone, Debug)]
pub(crate) struct PixyCamera {
    forward: f64,
    height: f64,
    cos_tilt: f64,
    sin_tilt: f64,
    /// Focal lengths in pixels.
    fx: f64,
    fy: f64,
    /// tan(half the horizontal field of view), for culling.
    tan_half_h: f64,
    /// The side cull's bound, `|side| - slope ahead > per_radius radius +
    /// offset` ([`PixyCamera::beside_view`]), found once.
    beside: BesideBound,
    puck_height: f64,
    robot_height: f64,
    max_range: f64,
    /// Points nearer than this to the image plane (units) make a body unseen.
    near: f64,
    min_area: u32,
    merge_distance: i32,
    per_signature: usize,
    classify: CameraConfig,
    /// The rim points on a unit circle: ahead (cos) and right (sin) parts.
    rim_ahead: [f64; RIM_POINTS],
    /// The rim point farthest back (least `rim_ahead`): the nearest to the
    /// image plane of every rim ([`PixyCamera::silhouette`]).
    rim_back: usize,
    rim_right: [f64; RIM_POINTS],
    in_view: Vec<InView>,
    /// The nearer boxes that overlap the body being occluded.
    cuts: Vec<Rect>,
    pieces: Vec<Rect>,
    scratch: Vec<Rect>,
    blobs: Vec<Blob>,
    /// The blobs merged so far (stage 3's output before it replaces `blobs`).
    merged: Vec<Blob>,
    /// Whether the processor has AVX2 ([`PixyCamera::silhouette`]).
    avx2: bool,
    /// What the last world's bodies' shapes give the camera.
    shapes: Option<BodyShapes>,
}

/// What the camera derives from a world's bodies' shapes, found once per
/// world rather than every frame.
#[derive(Clone, Debug)]
struct BodyShapes {
    /// The robots' shape and radius and the pucks' radius they are of.
    of: (RobotShape, f64, f64),
    /// The wedge-fronted robots' points (none for discs).
    wedge: Option<WedgePoints>,
    /// The search box's sizes.
    span: SearchSpan,
}

impl BodyShapes {
    /// The shapes of `world`'s bodies as `camera` sees them.
    fn new(camera: &PixyCamera, world: &WorldConfig) -> BodyShapes {
        let outline = Outline::of(world.robot_shape, world.robot_radius);
        BodyShapes {
            of: (world.robot_shape, world.robot_radius, world.puck_radius),
            wedge: outline.map(|o| WedgePoints::new(&o, &camera.rim_ahead, &camera.rim_right)),
            span: SearchSpan::new(camera, world.max_radius()),
        }
    }
}

/// The sizes of [`PixyCamera::search_box`] that depend on the camera and
/// the bodies' largest radius alone (found once, not every frame).
#[derive(Clone, Copy, Debug)]
struct SearchSpan {
    /// How far behind the lens the culls' `ahead >= -r` cuts the cone off
    /// (ahead of it if negative).
    back: f64,
    /// How far behind the lens the view cone's apex lies (ahead of it if
    /// negative).
    behind: f64,
    /// How far from the lens a body the culls keep can lie.
    reach: f64,
    /// The sector's radius from the apex.
    radius: f64,
    /// The box's padding.
    pad: f64,
    /// Half the cone's width where it is cut off.
    half_width: f64,
    /// cos and sin of the cone's half angle.
    cos_half: f64,
    sin_half: f64,
}

impl SearchSpan {
    /// The sizes for `camera` and bodies up to `max_radius`.
    fn new(camera: &PixyCamera, max_radius: f64) -> SearchSpan {
        // The side cull keeps |side| <= slope ahead + per_radius r + offset,
        // which for every r <= max_radius lies inside the cone from the
        // apex, of half angle atan(slope) ...
        let bound = &camera.beside;
        let widest = max_radius * bound.per_radius + bound.offset;
        let behind = widest / bound.slope;
        // ... cut off where ahead >= -r stops it, or at the apex ...
        let back = max_radius.min(behind);
        // ... and ahead^2 + side^2 <= (max_range + r)^2 within `reach` of
        // the lens, so within `reach + |behind|` of the apex.
        let reach = camera.max_range + max_radius;
        let radius = reach + behind.abs();
        let hypotenuse = (1.0 + bound.slope * bound.slope).sqrt();
        SearchSpan {
            back,
            behind,
            reach,
            radius,
            pad: radius * 1e-6,
            half_width: (widest - bound.slope * back).max(0.0),
            cos_half: 1.0 / hypotenuse,
            sin_half: bound.slope / hypotenuse,
        }
    }
}

/// [`PixyCamera::beside_view`]'s bound, `|side| - slope ahead >
/// per_radius radius + offset`: with `spread = sqrt(1 + (tan_half_h
/// cos_tilt)^2)`, how much a point at most a unit from a body's centre can
/// bring `|side| - tan_half_h depth` below the centre's, and `lift`, the
/// most a point's height adds to its depth (`-up sin_tilt`, for points
/// between the floor and the tallest body), it is `|side| - tan_half_h
/// (ahead cos_tilt + lift) - radius spread > pad`. The pad, a billionth of
/// the farthest a body in view can be (`max_range + radius`), keeps the
/// decision far from rounding: the projection, and this bound's terms,
/// round within a few units in the last place of the range.
#[derive(Clone, Copy, Debug)]
struct BesideBound {
    /// `tan_half_h cos_tilt`.
    slope: f64,
    /// `spread` and the pad's part per unit of radius.
    per_radius: f64,
    /// `tan_half_h lift` and the pad's part for the range.
    offset: f64,
}

impl BesideBound {
    /// The bound of a camera of `config` in a world of `unit_mm`
    /// millimetres per unit.
    fn new(config: &PixyCameraConfig, unit_mm: f64) -> BesideBound {
        const PAD: f64 = 1e-9;
        let tilt = config.tilt_deg.to_radians();
        let tan_half_h = (config.fov_h_deg / 2.0).to_radians().tan();
        let (height, sin) = (config.height_mm / unit_mm, tilt.sin());
        let tallest = config.puck_height_mm.max(config.robot_height_mm) / unit_mm;
        let lift = (height * sin).max((height - tallest) * sin);
        let slope = tan_half_h * tilt.cos();
        BesideBound {
            slope,
            per_radius: (1.0 + slope * slope).sqrt() + PAD,
            offset: tan_half_h * lift + config.max_range_mm / unit_mm * PAD,
        }
    }
}

/// Lanes of a wedge's outline points the camera projects
/// ([`PixyCamera::outline_silhouette`]): at most `RIM_POINTS + 3` points,
/// in a power of two for [`halving_16`]. Outlines of at most
/// [`RIM_POINTS`] points (tips between `r / cos 30` and `r / cos 60` from
/// the centre, as on `tv75`) are projected in that many lanes.
const WEDGE_POINTS: usize = 16;
const _: () = assert!(RIM_POINTS + 3 <= WEDGE_POINTS);

/// The points of a wedge's outline that bound its silhouette, in the
/// robot's frame (ahead, right): its tip, its tangent points and the rim
/// points that lie on its round back, then the tip again in the lanes left.
#[derive(Clone, Copy, Debug)]
struct WedgePoints {
    ahead: [f64; WEDGE_POINTS],
    right: [f64; WEDGE_POINTS],
    /// Whether the points fit in the first [`RIM_POINTS`] lanes (the
    /// others then repeat the tip, which adds nothing to a silhouette).
    fit_rim_lanes: bool,
}

impl WedgePoints {
    /// The points of `outline`, with the camera's rim points on a unit
    /// circle (`rim_ahead`, `rim_right`).
    fn new(
        outline: &Outline,
        rim_ahead: &[f64; RIM_POINTS],
        rim_right: &[f64; RIM_POINTS],
    ) -> WedgePoints {
        let r = outline.radius();
        let t = outline.tangent_point();
        let mut points = WedgePoints {
            ahead: [outline.tip(); WEDGE_POINTS],
            right: [0.0; WEDGE_POINTS],
            fit_rim_lanes: false,
        };
        let on_back = (0..RIM_POINTS)
            .filter(|&k| rim_ahead[k] * r < t.x)
            .map(|k| Vec2::new(rim_ahead[k], rim_right[k]) * r);
        // after the tip in lane 0
        let sides = [t, Vec2::new(t.x, -t.y)];
        let mut lanes = 1;
        for (n, p) in (1..).zip(sides.into_iter().chain(on_back)) {
            points.ahead[n] = p.x;
            points.right[n] = p.y;
            lanes = n + 1;
        }
        points.fit_rim_lanes = lanes <= RIM_POINTS;
        points
    }
}

/// Points along each edge of the image whose rays outline
/// [`PixyCamera::floor_view`].
pub const VIEW_EDGE_POINTS: usize = 8;

impl PixyCamera {
    /// The camera of `config` in a world of `unit_mm` millimetres per unit.
    pub fn new(config: &PixyCameraConfig, unit_mm: f64) -> PixyCamera {
        let tilt = config.tilt_deg.to_radians();
        let half_h = (config.fov_h_deg / 2.0).to_radians();
        let half_v = (config.fov_v_deg / 2.0).to_radians();
        let rim: [Vec2; RIM_POINTS] = std::array::from_fn(|k| {
            Vec2::from_angle(std::f64::consts::TAU * k as f64 / RIM_POINTS as f64)
        });
        PixyCamera {
            forward: config.forward_mm / unit_mm,
            height: config.height_mm / unit_mm,
            cos_tilt: tilt.cos(),
            sin_tilt: tilt.sin(),
            fx: f64::from(IMAGE_WIDTH) / 2.0 / half_h.tan(),
            fy: f64::from(IMAGE_HEIGHT) / 2.0 / half_v.tan(),
            tan_half_h: half_h.tan(),
            beside: BesideBound::new(config, unit_mm),
            puck_height: config.puck_height_mm / unit_mm,
            robot_height: config.robot_height_mm / unit_mm,
            max_range: config.max_range_mm / unit_mm,
            near: 0.5 / unit_mm,
            min_area: config.min_area,
            merge_distance: i32::from(config.merge_distance),
            per_signature: usize::from(config.max_blocks_per_signature),
            classify: config.classify,
            rim_ahead: rim.map(|p| p.x),
            rim_right: rim.map(|p| p.y),
            rim_back: (0..RIM_POINTS)
                .fold(0, |back, k| if rim[k].x < rim[back].x { k } else { back }),
            in_view: Vec::new(),
            cuts: Vec::new(),
            pieces: Vec::new(),
            scratch: Vec::new(),
            blobs: Vec::new(),
            merged: Vec::new(),
            avx2: has_avx2(),
            shapes: None,
        }
    }

    /// The floor the image covers, within the camera's range: where the
    /// rays through [`VIEW_EDGE_POINTS`] points along each edge of the
    /// image meet the floor (or, for rays that do not meet it within the
    /// range, the range along their bearing), as a polygon in the robot's
    /// frame (x ahead, y to its right, units), clockwise from the image's
    /// top left.
    pub fn floor_view(&self) -> Vec<Vec2> {
        let tan_half_v = f64::from(IMAGE_HEIGHT) / 2.0 / self.fy;
        let n = VIEW_EDGE_POINTS;
        let along = |k: usize| -1.0 + 2.0 * k as f64 / n as f64;
        // image coordinates (u to the right, v up), each in [-1, 1]
        let border = (0..n)
            .map(|k| (along(k), 1.0))
            .chain((0..n).map(|k| (1.0, -along(k))))
            .chain((0..n).map(|k| (-along(k), -1.0)))
            .chain((0..n).map(|k| (-1.0, along(k))));
        border
            .map(|(u, v)| {
                let (a, b) = (u * self.tan_half_h, v * tan_half_v);
                // the ray: the optical axis pitched down by the tilt
                let ahead = self.cos_tilt + b * self.sin_tilt;
                let down = self.sin_tilt - b * self.cos_tilt;
                let bearing = Vec2::new(ahead, a);
                let flat = bearing.length();
                let reach = if down > 0.0 {
                    (self.height / down * flat).min(self.max_range)
                } else {
                    self.max_range
                };
                Vec2::new(self.forward, 0.0) + bearing * (reach / flat)
            })
            .collect()
    }

    /// The classification the firmware applies to the blocks.
    pub(crate) fn classify(&self) -> &CameraConfig {
        &self.classify
    }

    /// The frame robot `robot` sees: every block, in the order the Pixy
    /// sends them (replaces `out`'s contents). The four stages of the
    /// module docs, in order; stage 3 only for two blobs or more (it
    /// leaves one as it is).
    pub fn frame(&mut self, world: &World, robot: usize, out: &mut Vec<PixyBlock>) {
        self.gather_in_view(world, robot);
        self.occlude();
        if self.blobs.len() > 1 {
            self.merge_close_blobs();
            self.drop_enclosed_blobs();
        }
        self.emit_blocks(out);
    }

    /// Stage 1: every other body in range and in front of the lens, with its
    /// silhouette, nearest first (ties by body index).
    fn gather_in_view(&mut self, world: &World, robot: usize) {
        let lens = Lens::of(world, robot, self.forward);
        let config = world.config();
        let of = (config.robot_shape, config.robot_radius, config.puck_radius);
        if self.shapes.as_ref().is_none_or(|shapes| shapes.of != of) {
            self.shapes = Some(BodyShapes::new(self, config));
        }
        let shapes = self.shapes.as_ref().expect("set just above");
        let (min, max) = self.search_box(&lens, &shapes.span);
        let mut in_view = std::mem::take(&mut self.in_view);
        in_view.clear();
        let wedge = shapes.wedge.as_ref();
        let robots = world.robots().len();
        world.any_body_in_box(min, max, |row| {
            for b in row {
                let Some(c) = self.candidate(robots, robot, &lens, b) else {
                    continue;
                };
                let rect = match wedge.filter(|_| c.index < robots) {
                    None => self.silhouette(c.ahead, c.side, c.radius, c.height),
                    Some(w) => {
                        self.outline_silhouette(&c, &lens, world.robots()[c.index].direction, w)
                    }
                };
                if let Some(rect) = rect {
                    in_view.push(c.in_view(rect));
                }
            }
            false
        });
        // The grid's rows come in order of growing y: roughly near to far
        // if the lens looks that way, else far to near.
        if lens.ahead.y < 0.0 {
            in_view.reverse();
        }
        sort_nearest_first(&mut in_view);
        self.in_view = in_view;
    }

    /// A box of the world holding the centre of every body that
    /// [`Self::candidate`] passes, for bodies up to the radius `span` is
    /// for: the sector from the apex of the cone the side cull
    /// ([`Self::beside_view`]) keeps centres in, that reaches as far as the
    /// range does, cut off where `ahead >= -r` stops it, within the range's
    /// square around the lens, padded by a millionth of its radius, far
    /// more than the culls' rounding.
    fn search_box(&self, lens: &Lens, span: &SearchSpan) -> (Vec2, Vec2) {
        let (radius, pad) = (span.radius, span.pad);
        let apex = lens.pos - lens.ahead * span.behind;
        let (min, max) = (
            |a: f64, b: f64| if a < b { a } else { b },
            |a: f64, b: f64| if a > b { a } else { b },
        );
        // The cone's corners where it is cut off, and where its edges meet
        // the arc.
        let back = lens.pos - lens.ahead * span.back;
        let half_width = span.half_width;
        let edge = |sign: f64| {
            apex + (lens.ahead * span.cos_half + lens.right * (sign * span.sin_half)) * radius
        };
        let corners = [
            back + lens.right * half_width,
            back - lens.right * half_width,
            edge(1.0),
            edge(-1.0),
        ];
        let mut low = corners[0];
        let mut high = corners[0];
        for p in &corners[1..] {
            low = Vec2::new(min(low.x, p.x), min(low.y, p.y));
            high = Vec2::new(max(high.x, p.x), max(high.y, p.y));
        }
        // The arc between the edges reaches as far as `radius` along each
        // axis within the cone's half angle of the heading.
        let (a, c) = (lens.ahead, span.cos_half);
        if a.x >= c {
            high.x = apex.x + radius;
        }
        if -a.x >= c {
            low.x = apex.x - radius;
        }
        if a.y >= c {
            high.y = apex.y + radius;
        }
        if -a.y >= c {
            low.y = apex.y - radius;
        }
        let square = Vec2::new(span.reach, span.reach);
        let (near, far) = (lens.pos - square, lens.pos + square);
        let padding = Vec2::new(pad, pad);
        (
            Vec2::new(max(low.x, near.x), max(low.y, near.y)) - padding,
            Vec2::new(min(high.x, far.x), min(high.y, far.y)) + padding,
        )
    }

    /// Body `b` if it is another body than robot `robot` (of `robots`,
    /// whose bodies come first) and the cheap culls before projecting keep
    /// it: not behind the lens, not beside the view ([`Self::beside_view`]),
    /// not far outside the horizontal field of view, in range.
    fn candidate(
        &self,
        robots: usize,
        robot: usize,
        lens: &Lens,
        b: &Neighbour,
    ) -> Option<Candidate> {
        let index = b.body as usize;
        if index == robot {
            return None;
        }
        let rel = b.pos - lens.pos;
        let ahead = rel.dot(lens.ahead);
        if ahead + b.radius < 0.0 {
            return None;
        }
        let side = rel.dot(lens.right);
        // The side cull before the side test: it leaves out more bodies,
        // in fewer instructions.
        if self.beside_view(ahead, side, b.radius) {
            return None;
        }
        let (height, signature) = if index < robots {
            (self.robot_height, self.classify.robot_signature)
        } else {
            (self.puck_height, self.classify.puck_signature)
        };
        if side.abs() > (ahead + b.radius + self.height + height) * self.tan_half_h + b.radius {
            return None;
        }
        let reach = self.max_range + b.radius;
        let distance_squared = ahead * ahead + side * side;
        (distance_squared <= reach * reach).then_some(Candidate {
            index,
            signature,
            ahead,
            side,
            radius: b.radius,
            height,
            distance_squared,
        })
    }

    /// Whether every point within `radius` of a centre `ahead` of and
    /// `side` right of the lens, between the floor and the tallest body,
    /// projects beyond one side of the image, so that its silhouette is
    /// `None` (two thirds of the bodies in front of the lens its search box
    /// visits on `tv75`). A
    /// point at `(ahead + a, side + s)` and height `up` from the lens is
    /// beyond the right side when `side + s - tan_half_h depth > 0`, its
    /// depth `(ahead + a) cos_tilt - up sin_tilt`; `s - tan_half_h cos_tilt
    /// a` is at least `-radius spread` and `-up sin_tilt` at most `lift`
    /// ([`BesideBound`]), so the centre's bound below holds for every point
    /// (the left side likewise). Only points in front of the image plane
    /// are projected: the others make the silhouette `None` anyway.
    #[inline(always)]
    fn beside_view(&self, ahead: f64, side: f64, radius: f64) -> bool {
        let bound = &self.beside;
        side.abs() - bound.slope * ahead > radius * bound.per_radius + bound.offset
    }

    /// The clipped pixel box of a cylinder of `radius` and `height` whose
    /// axis is `ahead` of and `side` right of the lens; `None` if it is out
    /// of the image or reaches behind the image plane ([`project`], or
    /// [`project_avx2`] on processors with AVX2).
    #[inline(always)]
    fn silhouette(&self, ahead: f64, side: f64, radius: f64, height: f64) -> Option<Rect> {
        #[cfg(target_arch = "x86_64")]
        if self.avx2 {
            // SAFETY: `avx2` is set only when the processor has AVX2.
            return unsafe { project_avx2(self, ahead, side, radius, height) };
        }
        project(self, ahead, side, radius, height)
    }

    /// The clipped pixel box of a wedge-fronted robot, candidate `c`,
    /// facing `facing` ([`outline_box`], or [`outline_box_avx2`] on
    /// processors with AVX2), in [`RIM_POINTS`] lanes if its points fit.
    #[inline(always)]
    fn outline_silhouette(
        &self,
        c: &Candidate,
        lens: &Lens,
        facing: Vec2,
        wedge: &WedgePoints,
    ) -> Option<Rect> {
        let robot = (c, lens, facing, wedge);
        #[cfg(target_arch = "x86_64")]
        if self.avx2 {
            // SAFETY: `avx2` is set only when the processor has AVX2.
            return unsafe {
                if wedge.fit_rim_lanes {
                    outline_box_avx2::<RIM_POINTS>(self, robot)
                } else {
                    outline_box_avx2::<WEDGE_POINTS>(self, robot)
                }
            };
        }
        if wedge.fit_rim_lanes {
            outline_box_any::<RIM_POINTS>(self, robot)
        } else {
            outline_box_any::<WEDGE_POINTS>(self, robot)
        }
    }

    /// Stage 2: each body's still visible part after the nearer ones'
    /// silhouettes are cut away, as a blob (bounding box, pixel count) if it
    /// has at least `min_area` pixels. The nearer boxes that overlap it are
    /// found in one pass; most bodies have none or one, whose visible part
    /// has a closed form ([`Rect::without`]); more are cut away piece by
    /// piece.
    fn occlude(&mut self) {
        self.blobs.clear();
        for k in 0..self.in_view.len() {
            let body = self.in_view[k];
            self.cuts.clear();
            self.cuts.extend(
                self.in_view[..k]
                    .iter()
                    .filter(|n| n.rect.overlaps(&body.rect))
                    .map(|n| n.rect),
            );
            let visible = match self.cuts[..] {
                [] => Some((body.rect, body.rect.area())),
                [cut] => body.rect.without(&cut),
                _ => self.cut_pieces(body.rect),
            };
            if let Some((rect, area)) = visible {
                if area >= self.min_area {
                    self.blobs.push(Blob {
                        signature: body.signature,
                        rect,
                        area,
                    });
                }
            }
        }
    }

    /// The bounding box and pixel count of what `cuts` leave of `rect`,
    /// `None` if nothing: the pieces left after each cut.
    fn cut_pieces(&mut self, rect: Rect) -> Option<(Rect, u32)> {
        self.pieces.clear();
        self.pieces.push(rect);
        for cut in &self.cuts {
            self.scratch.clear();
            for piece in &self.pieces {
                piece.subtract_into(cut, &mut self.scratch);
            }
            std::mem::swap(&mut self.pieces, &mut self.scratch);
            if self.pieces.is_empty() {
                return None;
            }
        }
        let first = self.pieces[0];
        Some((
            self.pieces.iter().fold(first, |r, p| r.union(p)),
            self.pieces.iter().map(Rect::area).sum(),
        ))
    }

    /// Stage 3, first half: merges close blobs of one signature until no two
    /// merge (the Pixy's `combine2`). Each blob joins the first group merged
    /// so far that it merges with (or starts a group); a group that grows is
    /// checked against the others again. Since growing only brings boxes
    /// closer, every order of merging ends in the same groups, so this gives
    /// the Pixy's result, each group in the place of its first blob.
    fn merge_close_blobs(&mut self) {
        let d = self.merge_distance;
        let groups = &mut self.merged;
        groups.clear();
        for blob in &self.blobs {
            let Some(mut grown) = groups.iter().position(|g| g.merges_with(blob, d)) else {
                groups.push(*blob);
                continue;
            };
            let before = groups[grown].rect;
            groups[grown] = groups[grown].merged(blob);
            if groups[grown].rect == before {
                // Not grown: no other group comes any closer.
                continue;
            }
            while let Some(other) =
                (0..groups.len()).find(|&g| g != grown && groups[g].merges_with(&groups[grown], d))
            {
                let (kept, absorbed) = (grown.min(other), grown.max(other));
                groups[kept] = groups[kept].merged(&groups[absorbed]);
                groups.remove(absorbed);
                grown = kept;
            }
        }
        std::mem::swap(&mut self.blobs, &mut self.merged);
    }

    /// Stage 3, second half: drops each block enclosed by another block (of
    /// the same box: by an earlier one), in one pass (the Pixy's `combine`,
    /// which drops them one by one: a block enclosed by one that is dropped
    /// is enclosed by the one that encloses that, which stays).
    fn drop_enclosed_blobs(&mut self) {
        let blobs = &self.blobs;
        let encloses = |o: usize, k: usize| {
            o != k
                && blobs[o].rect.contains(&blobs[k].rect)
                && (blobs[o].rect != blobs[k].rect || o < k)
        };
        self.merged.clear();
        self.merged.extend(
            (0..blobs.len())
                .filter(|&k| !(0..blobs.len()).any(|o| encloses(o, k)))
                .map(|k| blobs[k]),
        );
        std::mem::swap(&mut self.blobs, &mut self.merged);
    }

    /// Stage 4: the blobs as Pixy blocks, signature 1 first, largest first,
    /// at most `max_blocks_per_signature` of each.
    fn emit_blocks(&mut self, out: &mut Vec<PixyBlock>) {
        out.clear();
        sort_send_order(&mut self.blobs);
        let per_signature = self.per_signature;
        let mut kept = 0;
        out.extend(
            self.blobs
                .iter()
                .enumerate()
                .filter_map(|(i, b)| {
                    // Blobs are grouped by signature: count within the group.
                    kept = if i > 0 && self.blobs[i - 1].signature == b.signature {
                        kept + 1
                    } else {
                        1
                    };
                    (kept <= per_signature).then_some(b)
                })
                .map(|b| {
                    let (width, height) = (
                        (b.rect.right - b.rect.left) as u16,
                        (b.rect.bottom - b.rect.top) as u16,
                    );
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
}

impl Lens {
    /// Robot `robot`'s lens, `forward` ahead of its centre.
    fn of(world: &World, robot: usize, forward: f64) -> Lens {
        let ahead = world.robots()[robot].direction;
        Lens {
            pos: world.bodies()[robot].pos + ahead * forward,
            ahead,
            right: Vec2::new(-ahead.y, ahead.x),
        }
    }
}

impl Candidate {
    /// The candidate in view with silhouette `rect`.
    fn in_view(&self, rect: Rect) -> InView {
        InView {
            distance: self.distance_squared.sqrt(),
            index: self.index as u32,
            signature: self.signature,
            rect,
        }
    }
}

/// Sorts blobs in the order the Pixy sends their blocks: by signature,
/// largest first, then leftmost, then topmost; blobs alike in all four
/// keep their order. A stable insertion sort (the standard library's
/// stable sort gives the same order, called out of line), for a frame
/// holds a few blobs.
fn sort_send_order(blobs: &mut [Blob]) {
    let key = |b: &Blob| (b.signature, Reverse(b.area), b.rect.left, b.rect.top);
    for i in 1..blobs.len() {
        let blob = blobs[i];
        let mut k = i;
        while k > 0 && key(&blob) < key(&blobs[k - 1]) {
            blobs[k] = blobs[k - 1];
            k -= 1;
        }
        blobs[k] = blob;
    }
}

/// Sorts bodies in view nearest first, ties by body index: an insertion
/// sort, for a frame holds a dozen or so bodies, found roughly in order.
fn sort_nearest_first(in_view: &mut [InView]) {
    for i in 1..in_view.len() {
        let body = in_view[i];
        let mut k = i;
        // No distance is NaN.
        while k > 0 && {
            let nearer = &in_view[k - 1];
            body.distance < nearer.distance
                || (body.distance == nearer.distance && body.index < nearer.index)
        } {
            in_view[k] = in_view[k - 1];
            k -= 1;
        }
        in_view[k] = body;
    }
}

/// Defines a function projecting a body's silhouette for
/// [`PixyCamera::silhouette`], with the given attributes and qualifiers:
/// the one body is compiled twice, for any processor ([`project`]) and for
/// x86-64 ones with AVX2 ([`project_avx2`]: four lanes instead of two and
/// three-operand instructions, measured 250 instead of 430 instructions
/// per body, 144,830 -> 125,023 per step on the thesis' square, which is
/// what the `unsafe` call to it is for). AVX2 brings no fused multiply-add
/// (that is FMA, not enabled), so every operation rounds as in the other.
/// The AVX2 one must be a function of its own: compiled inlined into
/// another, its arrays vectorise only two lanes wide.
macro_rules! projection {
    ($(#[$attr:meta])* $($qualifier:ident)* ; $name:ident) => {
        /// The clipped pixel box of a cylinder of `radius` and `height` whose
        /// axis is `ahead` of and `side` right of the lens; `None` if it is out
        /// of the image or reaches behind the image plane. Its 2 x 12 rim points
        /// are projected in fixed-size arrays so that the arithmetic vectorises,
        /// each point's coordinates rounded exactly as one point at a time; the
        /// least and greatest are found by halving the arrays (few registers,
        /// packed comparisons). Adding the image centre rounds monotonically,
        /// so it is added to the extremes alone.
        $(#[$attr])*
        $($qualifier)* fn $name(camera: &PixyCamera, ahead: f64, side: f64, radius: f64, height: f64) -> Option<Rect> {
            let ups = [0.0 - camera.height, height - camera.height];
            let (up_sin, up_cos) = (ups.map(|up| up * camera.sin_tilt), ups.map(|up| up * camera.cos_tilt));
            // A point's depth grows with its `rim_ahead` (radius > 0, and
            // cos_tilt > 0 since the tilt stays within 90 degrees), each step
            // rounded monotonically: the back point's is the least of its rim.
            let back = (ahead + radius * camera.rim_ahead[camera.rim_back]) * camera.cos_tilt;
            if back - up_sin[0] < camera.near || back - up_sin[1] < camera.near {
                return None;
            }
            let point_ahead: [f64; RIM_POINTS] = std::array::from_fn(|k| ahead + radius * camera.rim_ahead[k]);
            let depth_ahead = point_ahead.map(|pf| pf * camera.cos_tilt);
            let down_ahead = point_ahead.map(|pf| -pf * camera.sin_tilt);
            let across: [f64; RIM_POINTS] = std::array::from_fn(|k| camera.fx * (side + radius * camera.rim_right[k]));
            let (mut x, mut y) = ([[0.0; RIM_POINTS]; 2], [[0.0; RIM_POINTS]; 2]);
            for rim in 0..2 {
                let inverse = depth_ahead.map(|d| 1.0 / (d - up_sin[rim]));
                x[rim] = std::array::from_fn(|k| across[k] * inverse[k]);
                y[rim] = std::array::from_fn(|k| camera.fy * (down_ahead[k] - up_cos[rim]) * inverse[k]);
            }
            pixel_box(|| least(&x), || greatest(&x), || least(&y), || greatest(&y))
        }
    };
}

projection!(#[inline(always)] ; project);

#[cfg(target_arch = "x86_64")]
projection!(#[target_feature(enable = "avx2")] #[inline(never)] unsafe ; project_avx2);

/// The clipped pixel box of a wedge-fronted robot, candidate `c`,
/// facing `facing`: the prism on its outline, `c.height` tall, seen
/// through the pinhole as a cylinder is (the bounding box of its
/// points at the bottom and the top, `wedge`'s). `None` if it is out
/// of the image or reaches behind the image plane. A robot or two a
/// frame: each point's place ahead of and beside the lens is found
/// once for both rims, and the lanes keep to fixed-size arrays: the
/// first `N` of `wedge`'s, which hold all its points.
/// Compiled a second time for AVX2 ([`outline_box_avx2`]: 330 instead of
/// 675 instructions a robot in 16 lanes).
#[inline(always)]
fn outline_box<const N: usize>(
    camera: &PixyCamera,
    c: &Candidate,
    lens: &Lens,
    facing: Vec2,
    wedge: &WedgePoints,
) -> Option<Rect>
where
    [[f64; N]; 2]: Lanes,
{
    let right = Vec2::new(-facing.y, facing.x);
    // Plain loops over the lanes: `array::from_fn`'s closures are not
    // inlined into the AVX2 copy.
    let (mut pf, mut across) = ([0.0; N], [0.0; N]);
    for k in 0..N {
        let offset = facing * wedge.ahead[k] + right * wedge.right[k];
        pf[k] = c.ahead + offset.dot(lens.ahead);
        across[k] = camera.fx * (c.side + offset.dot(lens.right));
    }
    // A point's depth, `pf cos_tilt - up sin_tilt`, rounds monotonically
    // in `pf` (cos_tilt > 0, the tilt staying within 90 degrees): each
    // rim's least depth is the least `pf`'s (the one row, twice).
    let nearest = [pf, pf].reduce(|a, b| if a < b { a } else { b });
    let (mut x, mut y) = ([[0.0; N]; 2], [[0.0; N]; 2]);
    for (rim, z) in [0.0, c.height].into_iter().enumerate() {
        let up = z - camera.height;
        if nearest * camera.cos_tilt - up * camera.sin_tilt < camera.near {
            return None;
        }
        let mut depth = [0.0; N];
        for k in 0..N {
            depth[k] = pf[k] * camera.cos_tilt - up * camera.sin_tilt;
        }
        for k in 0..N {
            let down = -pf[k] * camera.sin_tilt - up * camera.cos_tilt;
            x[rim][k] = across[k] / depth[k];
            y[rim][k] = camera.fy * down / depth[k];
        }
    }
    let least = |v: &[[f64; N]; 2]| v.reduce(|a, b| if a < b { a } else { b });
    let greatest = |v: &[[f64; N]; 2]| v.reduce(|a, b| if a > b { a } else { b });
    pixel_box(|| least(&x), || greatest(&x), || least(&y), || greatest(&y))
}

/// [`outline_box`] on any processor (`robot` as for [`outline_box_avx2`]),
/// out of the frame's loop as the AVX2 copy is.
#[inline(never)]
fn outline_box_any<const N: usize>(
    camera: &PixyCamera,
    robot: (&Candidate, &Lens, Vec2, &WedgePoints),
) -> Option<Rect>
where
    [[f64; N]; 2]: Lanes,
{
    let (c, lens, facing, wedge) = robot;
    outline_box::<N>(camera, c, lens, facing, wedge)
}

/// [`outline_box`] compiled for AVX2 (`robot`: its candidate, the lens,
/// its facing, its outline's points): four lanes instead of two, every
/// operation rounding as in the other (no FMA).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
#[inline(never)]
unsafe fn outline_box_avx2<const N: usize>(
    camera: &PixyCamera,
    robot: (&Candidate, &Lens, Vec2, &WedgePoints),
) -> Option<Rect>
where
    [[f64; N]; 2]: Lanes,
{
    let (c, lens, facing, wedge) = robot;
    outline_box::<N>(camera, c, lens, facing, wedge)
}

/// The pixels of points whose image coordinates from the image's centre
/// span `left ..= right` and `top ..= bottom` (each found when its edge
/// is, as few values live at once as one at a time), clipped to the image;
/// `None` if none is in it. Adding the centre rounds monotonically, so it
/// is added to the extremes alone; a zero's sign may differ from the
/// point by point minimum, and the pixel is the same for both.
#[inline(always)]
fn pixel_box(
    left: impl FnOnce() -> f64,
    right: impl FnOnce() -> f64,
    top: impl FnOnce() -> f64,
    bottom: impl FnOnce() -> f64,
) -> Option<Rect> {
    let (cx, cy) = (f64::from(IMAGE_WIDTH) / 2.0, f64::from(IMAGE_HEIGHT) / 2.0);
    let rect = Rect {
        left: first_pixel(cx + left(), IMAGE_WIDTH),
        right: last_pixel(cx + right(), IMAGE_WIDTH),
        top: first_pixel(cy + top(), IMAGE_HEIGHT),
        bottom: last_pixel(cy + bottom(), IMAGE_HEIGHT),
    };
    (rect.left <= rect.right && rect.top <= rect.bottom).then_some(rect)
}

/// Whether the processor has AVX2.
fn has_avx2() -> bool {
    #[cfg(target_arch = "x86_64")]
    return std::is_x86_feature_detected!("avx2");
    #[cfg(not(target_arch = "x86_64"))]
    false
}

/// The least of both rims' values (none is NaN).
#[inline(always)]
fn least(rims: &[[f64; RIM_POINTS]; 2]) -> f64 {
    halving(rims, |a, b| if a < b { a } else { b })
}

/// The greatest of both rims' values (none is NaN).
#[inline(always)]
fn greatest(rims: &[[f64; RIM_POINTS]; 2]) -> f64 {
    halving(rims, |a, b| if a > b { a } else { b })
}

/// Both rims' values reduced by `pick` (the lesser or the greater of two):
/// the lanes halved down to two (12, 6, then 2 of three), which keeps few
/// registers live.
#[inline(always)]
fn halving(rims: &[[f64; RIM_POINTS]; 2], pick: impl Fn(f64, f64) -> f64) -> f64 {
    let v: [f64; RIM_POINTS] = std::array::from_fn(|k| pick(rims[0][k], rims[1][k]));
    let v: [f64; RIM_POINTS / 2] = std::array::from_fn(|k| pick(v[k], v[k + RIM_POINTS / 2]));
    let v: [f64; 2] = std::array::from_fn(|k| pick(pick(v[k], v[k + 2]), v[k + 4]));
    pick(v[1], v[0])
}

/// Two rows of lanes the camera reduces: [`halving`]'s 12 and
/// [`halving_16`]'s 16.
trait Lanes {
    /// Both rows' values reduced by `pick` (the lesser or the greater of
    /// two; none is NaN).
    fn reduce(&self, pick: impl Fn(f64, f64) -> f64) -> f64;
}

impl Lanes for [[f64; RIM_POINTS]; 2] {
    #[inline(always)]
    fn reduce(&self, pick: impl Fn(f64, f64) -> f64) -> f64 {
        halving(self, pick)
    }
}

impl Lanes for [[f64; 16]; 2] {
    #[inline(always)]
    fn reduce(&self, pick: impl Fn(f64, f64) -> f64) -> f64 {
        halving_16(self, pick)
    }
}

/// Both rows' values reduced by `pick` (the lesser or the greater of
/// two), halving the lanes down to one.
#[inline(always)]
fn halving_16(rows: &[[f64; 16]; 2], pick: impl Fn(f64, f64) -> f64) -> f64 {
    let v: [f64; 16] = std::array::from_fn(|k| pick(rows[0][k], rows[1][k]));
    let v: [f64; 8] = std::array::from_fn(|k| pick(v[k], v[k + 8]));
    let v: [f64; 4] = std::array::from_fn(|k| pick(v[k], v[k + 4]));
    pick(pick(v[0], v[2]), pick(v[1], v[3]))
}

/// The first pixel of a span that starts at `v`: `floor(v)` within
/// `0..=end` (truncation is the floor from 0 up, and below 0 both give 0;
/// libm's floor would be a call on the baseline x86-64).
fn first_pixel(v: f64, end: u16) -> i32 {
    (v as i32).clamp(0, i32::from(end))
}

/// The last pixel of a span that ends at `v`: `ceil(v) - 1` within
/// `-1..=end - 1`.
fn last_pixel(v: f64, end: u16) -> i32 {
    if v <= 0.0 {
        return -1;
    }
    let whole = v as i32;
    let ceil_less_one = if f64::from(whole) < v {
        whole
    } else {
        whole - 1
    };
    ceil_less_one.min(i32::from(end) - 1)
}

#[cfg(test)]
mod reference;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::base::rng::SimRng;
    use crate::config::robot_shape::RobotShape;
    use crate::config::SimConfig;
    use crate::physics::body::RobotKind;
    use rand::{RngExt, SeedableRng};
    use shared::ImageRegion;
    use std::f64::consts::FRAC_PI_2;
    use std::sync::Arc;

    const R: f64 = 10.0;

    #[test]
    fn the_floor_view_starts_where_the_lowest_ray_meets_the_floor_and_ends_at_the_range() {
        let camera = PixyCamera::new(&PixyCameraConfig::default(), 6.5);
        let view = camera.floor_view();
        assert_eq!(view.len(), 4 * VIEW_EDGE_POINTS);
        // the image's bottom centre: 20 + 23.5 degrees down from 80 mm up,
        // 15 mm ahead of the centre
        let near = view[2 * VIEW_EDGE_POINTS + VIEW_EDGE_POINTS / 2];
        let expected = (15.0 + 80.0 / 43.5_f64.to_radians().tan()) / 6.5;
        assert!(
            (near.x - expected).abs() < 1e-9 && near.y.abs() < 1e-9,
            "{near:?}"
        );
        // the top edge looks 3.5 degrees above the horizon: out to the range
        let top_centre = view[VIEW_EDGE_POINTS / 2];
        assert!(
            (top_centre.x - 15.0 / 6.5 - 1250.0 / 6.5).abs() < 1e-9,
            "{top_centre:?}"
        );
        // left of the heading on the left half of the image, and symmetric
        assert!(view[0].y < 0.0 && view[VIEW_EDGE_POINTS].y > 0.0);
        let right = view[VIEW_EDGE_POINTS + 3];
        let left = view[4 * VIEW_EDGE_POINTS - 3];
        assert!((right.x - left.x).abs() < 1e-9 && (right.y + left.y).abs() < 1e-9);
    }

    /// Robot 0 at (400, 400) facing +x (its right is +y), plus other robots
    /// and pucks at offsets (ahead, right) in robot radii.
    fn frame_of(robots: &[(f64, f64)], pucks: &[(f64, f64)]) -> Vec<PixyBlock> {
        frame_with(&PixyCameraConfig::default(), robots, pucks)
    }

    fn frame_with(
        camera: &PixyCameraConfig,
        robots: &[(f64, f64)],
        pucks: &[(f64, f64)],
    ) -> Vec<PixyBlock> {
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
        assert!(
            b.y >= 100,
            "a puck 3 radii ahead is in the lower half: {b:?}"
        );
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
        let (f, s) = (
            7.0 * 60f64.to_radians().cos(),
            7.0 * 60f64.to_radians().sin(),
        );
        assert!(frame_of(&[], &[(f, s), (f, -s)]).is_empty());
        // Behind the robot: nothing.
        assert!(frame_of(&[], &[(-4.0, 0.0)]).is_empty());
        // At 30 degrees it is seen.
        let (f, s) = (
            7.0 * 30f64.to_radians().cos(),
            7.0 * 30f64.to_radians().sin(),
        );
        assert_eq!(frame_of(&[], &[(f, s)]).len(), 1);
    }

    #[test]
    fn robots_show_signature_two_after_the_pucks_and_blocks_are_largest_first() {
        let blocks = frame_of(&[(3.0, 2.0)], &[(8.0, -2.0), (3.0, -1.5)]);
        let sigs: Vec<u16> = blocks.iter().map(|b| b.signature).collect();
        assert_eq!(sigs, [1, 1, 2], "{blocks:?}");
        assert!(blocks[0].width * blocks[0].height > blocks[1].width * blocks[1].height);
        let halves = ImageRegion {
            x_min: 160,
            x_max: 319,
            y_min: 100,
            y_max: 199,
        };
        let s = CameraConfig {
            obstacle_right: halves,
            ..CameraConfig::DEFAULT
        }
        .classify(&blocks);
        assert!(s.obstacle_right && !s.obstacle_left);
    }

    #[test]
    fn a_puck_hidden_behind_a_robot_is_not_seen_and_small_far_ones_are_dropped() {
        let blocks = frame_of(&[(3.0, 0.0)], &[(6.0, 0.0)]);
        assert_eq!(
            blocks.iter().map(|b| b.signature).collect::<Vec<_>>(),
            [2],
            "{blocks:?}"
        );
        // The range ends at 25 radii; far blocks are small and high in the image.
        let far = frame_of(&[], &[(24.0, 0.0)]);
        assert!(
            far.len() == 1 && far[0].y < 100 && far[0].width * far[0].height < 200,
            "{far:?}"
        );
        assert!(frame_of(&[], &[(27.0, 0.0)]).is_empty());
        // Blobs under the minimum area are dropped.
        let strict = PixyCameraConfig {
            min_area: 200,
            ..PixyCameraConfig::default()
        };
        assert!(frame_with(&strict, &[], &[(24.0, 0.0)]).is_empty());
    }

    #[test]
    fn each_signature_sends_its_largest_blocks_up_to_the_cap() {
        let pucks = [(4.0, -2.5), (7.0, 0.0), (12.0, 3.0), (16.0, -4.0)];
        let blocks = frame_of(&[(10.0, 5.0)], &pucks);
        let sigs: Vec<u16> = blocks.iter().map(|b| b.signature).collect();
        assert_eq!(sigs, [1, 1, 2], "{blocks:?}");
        let all = PixyCameraConfig {
            max_blocks_per_signature: 10,
            ..PixyCameraConfig::default()
        };
        let blocks = frame_with(&all, &[(10.0, 5.0)], &pucks);
        assert!(
            blocks.iter().filter(|b| b.signature == 1).count() > 2,
            "{blocks:?}"
        );
        assert_eq!(blocks.last().map(|b| b.signature), Some(2));
    }

    /// Robot 0 at (400, 400) facing +x and robot 1 six radii ahead of it
    /// facing +y (robot 0's right), both of `shape`: robot 0's frame.
    fn side_on(shape: RobotShape) -> Vec<PixyBlock> {
        let mut config = SimConfig::default();
        config.world.robot_shape = shape;
        config.world.robots = 2;
        config.world.pucks = 0;
        let scene = [
            (Vec2::new(400.0, 400.0), 0.0, RobotKind::Outie),
            (Vec2::new(460.0, 400.0), FRAC_PI_2, RobotKind::Outie),
        ];
        let world = World::scene(&config, &scene, &[], 1);
        let mut camera = PixyCamera::new(&PixyCameraConfig::default(), 5.0);
        let mut out = Vec::new();
        camera.frame(&world, 0, &mut out);
        out
    }

    #[test]
    fn a_wedge_seen_side_on_reaches_to_its_tip_s_hand_computed_column() {
        // The wedge's tip (13 units = 65 mm to the right of its centre,
        // 57 units = 285 mm ahead of the lens) at the robot's top (60 mm;
        // the lens is 80 mm up, tilted 20 degrees) is its rightmost point:
        // depth 285 cos 20 + 20 sin 20 mm, column 160 + fx 65 / depth, fx
        // = 160 / tan 37.5 degrees. The tangent points and the round back
        // reach less far right (at most 38 / 236 of the depth against the
        // tip's 65 / 285).
        let t = 20f64.to_radians();
        let depth = 285.0 * t.cos() + 20.0 * t.sin();
        let fx = 160.0 / 37.5f64.to_radians().tan();
        let right = (160.0 + fx * 65.0 / depth).ceil() as u16 - 1;
        let wedge = side_on(RobotShape::Wedge { tip: 13.0 });
        assert_eq!(wedge.len(), 1, "{wedge:?}");
        let w = wedge[0];
        assert_eq!(w.signature, 2);
        assert_eq!(w.x - w.width / 2 + w.width, right, "{w:?}");
        // Its round back is the disc's: the same rows, and on the left no
        // further out than the disc's own edge (the back's rim is sampled
        // from the robot's heading, the disc's from the lens).
        let disc = side_on(RobotShape::Disc)[0];
        assert_eq!((w.y, w.height), (disc.y, disc.height), "{w:?} {disc:?}");
        let (left, disc_left) = (w.x - w.width / 2, disc.x - disc.width / 2);
        assert!(left >= disc_left && left <= disc_left + 1, "{w:?} {disc:?}");
        assert!(w.width > disc.width + 10, "{w:?} {disc:?}");
    }

    #[test]
    fn blobs_sort_in_send_order_as_the_stable_sort_orders_them() {
        let mut rng = SimRng::seed_from_u64(23);
        for _ in 0..2000 {
            // Few distinct values, so that many blobs tie in every key.
            let mut blobs: Vec<Blob> = (0..rng.random_range(0..9))
                .map(|_| {
                    let (left, top) = (rng.random_range(0..3), rng.random_range(0..3));
                    Blob {
                        signature: rng.random_range(1..3),
                        rect: Rect {
                            left,
                            top,
                            right: left + rng.random_range(0..3),
                            bottom: top + rng.random_range(0..3),
                        },
                        area: rng.random_range(1..4),
                    }
                })
                .collect();
            let mut expected = blobs.clone();
            expected.sort_by(|a, b| {
                a.signature
                    .cmp(&b.signature)
                    .then(b.area.cmp(&a.area))
                    .then(a.rect.left.cmp(&b.rect.left))
                    .then(a.rect.top.cmp(&b.rect.top))
            });
            sort_send_order(&mut blobs);
            assert_eq!(blobs, expected);
        }
    }

    #[test]
    fn touching_pucks_merge_into_one_block() {
        let blocks = frame_of(&[], &[(5.0, -1.0), (5.0, 1.0)]);
        assert_eq!(blocks.len(), 1, "{blocks:?}");
        assert!(blocks[0].x.abs_diff(160) <= 1);
    }

    #[test]
    fn rectangle_subtraction_keeps_exactly_the_uncovered_pixels() {
        let a = Rect {
            left: 0,
            top: 0,
            right: 9,
            bottom: 9,
        };
        let cut = Rect {
            left: 3,
            top: 4,
            right: 5,
            bottom: 20,
        };
        let mut out = Vec::new();
        a.subtract_into(&cut, &mut out);
        assert_eq!(out.iter().map(Rect::area).sum::<u32>(), 100 - 3 * 6);
        for p in &out {
            assert!(!p.overlaps(&cut) && a.contains(p));
        }
    }

    #[test]
    fn one_cut_leaves_the_box_and_pixels_of_the_pieces_it_leaves() {
        let a = Rect {
            left: 2,
            top: 3,
            right: 6,
            bottom: 7,
        };
        let spans = |lo: i32, hi: i32| (lo..=hi).flat_map(move |l| (l..=hi).map(move |r| (l, r)));
        for (left, right) in spans(0, 8) {
            for (top, bottom) in spans(1, 9) {
                let cut = Rect {
                    left,
                    top,
                    right,
                    bottom,
                };
                if !a.overlaps(&cut) {
                    continue;
                }
                let mut pieces = Vec::new();
                a.subtract_into(&cut, &mut pieces);
                let expected = pieces.first().map(|&first| {
                    (
                        pieces.iter().fold(first, |r, p| r.union(p)),
                        pieces.iter().map(Rect::area).sum(),
                    )
                });
                assert_eq!(a.without(&cut), expected, "{cut:?}");
            }
        }
    }

    #[test]
    fn bad_poses_are_named() {
        let c = PixyCameraConfig {
            tilt_deg: 70.0,
            ..PixyCameraConfig::default()
        };
        assert!(c
            .validate()
            .unwrap_err()
            .to_string()
            .contains("camera.tilt_deg"));
        let c = PixyCameraConfig {
            height_mm: -1.0,
            ..PixyCameraConfig::default()
        };
        assert!(c
            .validate()
            .unwrap_err()
            .to_string()
            .contains("camera.height_mm"));
        assert!(PixyCameraConfig::default().validate().is_ok());
    }

    /// Camera settings that stress other paths than the default: every
    /// block sent, no merging or the smallest blobs, a wide or steep or
    /// upward-tilted view, a short range.
    fn camera_variants() -> Vec<PixyCameraConfig> {
        let d = PixyCameraConfig::default;
        vec![
            d(),
            PixyCameraConfig {
                max_blocks_per_signature: 100,
                ..d()
            },
            PixyCameraConfig {
                max_blocks_per_signature: 100,
                min_area: 1,
                merge_distance: 0,
                ..d()
            },
            PixyCameraConfig {
                max_blocks_per_signature: 100,
                fov_h_deg: 120.0,
                tilt_deg: 5.0,
                merge_distance: 12,
                ..d()
            },
            PixyCameraConfig {
                tilt_deg: -10.0,
                fov_v_deg: 40.0,
                forward_mm: 40.0,
                height_mm: 30.0,
                ..d()
            },
            PixyCameraConfig {
                tilt_deg: 45.0,
                fov_v_deg: 60.0,
                fov_h_deg: 50.0,
                ..d()
            },
            PixyCameraConfig {
                max_range_mm: 400.0,
                max_blocks_per_signature: 100,
                ..d()
            },
        ]
    }

    /// The thesis' square and the TV's scale (another unit, arena and range).
    fn arena_scales() -> Vec<SimConfig> {
        let mut tv = SimConfig::default();
        crate::scenario::arena::ArenaSpec::tv75()
            .apply(&mut tv, &crate::fields::ScalarField::annulus_of(64, 36));
        vec![SimConfig::default(), tv]
    }

    /// A seeded random scene around robot 0 (somewhere in the arena, any
    /// heading): clusters of touching and overlapping pucks in front of it,
    /// robots close to it and to each other, bodies just inside and outside
    /// the edges of the field of view and of the range, and bodies right in
    /// front of the lens; all inside the arena.
    fn random_scene(config: &SimConfig, camera: &PixyCameraConfig, seed: u64) -> World {
        let mut rng = SimRng::seed_from_u64(seed);
        let w = &config.world;
        let (robot_r, puck_r) = (w.robot_radius, w.puck_radius);
        let range = camera.max_range_mm / w.unit_mm;
        let half_h = (camera.fov_h_deg / 2.0).to_radians();
        let inside = |p: Vec2| {
            Vec2::new(
                p.x.clamp(robot_r, w.arena_width - robot_r),
                p.y.clamp(robot_r, w.arena_height - robot_r),
            )
        };
        let me = inside(Vec2::new(
            rng.random_range(0.0..w.arena_width),
            rng.random_range(0.0..w.arena_height),
        ));
        // Headings along the axes too, where the search box is tightest.
        let quarter = std::f64::consts::FRAC_PI_2;
        let heading = if seed % 3 == 0 {
            quarter * rng.random_range(0..4) as f64
        } else {
            rng.random_range(-2.0 * quarter..2.0 * quarter)
        };
        let around =
            |distance: f64, angle: f64| inside(me + Vec2::from_angle(heading + angle) * distance);
        let mut robots = vec![(me, heading, RobotKind::Outie)];
        let mut pucks = Vec::new();
        for _ in 0..rng.random_range(1..5) {
            let centre = around(rng.random_range(0.0..range), rng.random_range(-1.2..1.2));
            for _ in 0..rng.random_range(2..14) {
                let offset = Vec2::from_angle(rng.random_range(0.0..std::f64::consts::TAU))
                    * rng.random_range(0.0..4.0 * puck_r);
                pucks.push(inside(centre + offset));
            }
        }
        for _ in 0..rng.random_range(1..6) {
            let p = around(
                rng.random_range(2.0 * robot_r..0.6 * range),
                rng.random_range(-1.5..1.5),
            );
            let next = inside(
                p + Vec2::from_angle(rng.random_range(0.0..std::f64::consts::TAU)) * 2.05 * robot_r,
            );
            for q in [p, next] {
                robots.push((
                    q,
                    rng.random_range(-std::f64::consts::PI..std::f64::consts::PI),
                    RobotKind::Outie,
                ));
            }
        }
        for _ in 0..rng.random_range(2..8) {
            let edge_of_range = around(
                range + rng.random_range(-2.0 * puck_r..2.0 * puck_r),
                rng.random_range(-half_h..half_h),
            );
            let side = if rng.random_bool(0.5) { 1.0 } else { -1.0 };
            let angle = side * (half_h + rng.random_range(-0.15..0.25));
            let edge_of_view = around(rng.random_range(0.0..range), angle);
            let at_lens = around(
                rng.random_range(robot_r..robot_r + 3.0 * puck_r),
                rng.random_range(-1.6..1.6),
            );
            pucks.extend([edge_of_range, edge_of_view, at_lens]);
        }
        World::scene(config, &robots, &pucks, seed)
    }

    /// Compares every robot's frame with the reference's, projected for any
    /// processor and (where it has AVX2) for AVX2; returns how many blocks
    /// the frames hold.
    fn assert_reference_frames(camera: &mut PixyCamera, world: &World, what: &str) -> usize {
        let mut out = Vec::new();
        let avx2 = has_avx2();
        (0..world.robots().len())
            .map(|robot| {
                let expected = reference::frame(camera, world, robot);
                for projection in [false, avx2] {
                    camera.avx2 = projection;
                    camera.frame(world, robot, &mut out);
                    assert_eq!(out, expected, "{what}, robot {robot}, AVX2 {projection}");
                }
                out.len()
            })
            .sum()
    }

    #[test]
    fn random_scenes_give_the_reference_frames() {
        let mut blocks = 0;
        for config in arena_scales() {
            for (variant, settings) in camera_variants().iter().enumerate() {
                let mut camera = PixyCamera::new(settings, config.world.unit_mm);
                for seed in 0..150 {
                    let world = random_scene(&config, settings, seed);
                    let what = format!(
                        "unit {} mm, camera {variant}, seed {seed}",
                        config.world.unit_mm
                    );
                    blocks += assert_reference_frames(&mut camera, &world, &what);
                }
            }
        }
        assert!(blocks > 10_000, "the scenes are seen: {blocks} blocks");
    }

    #[test]
    fn simulated_runs_give_the_reference_frames() {
        for config in arena_scales() {
            let unit = config.world.unit_mm;
            let sensors = crate::sensors::robot::RobotSensors::new(
                &crate::sensors::robot::RobotSensorConfig::default(),
                &config.world,
            );
            let field = Arc::new(crate::fields::ScalarField::annulus_of(64, 36));
            let mut sim =
                crate::simulation::Simulation::with_sensors(config, field, sensors, 3).unwrap();
            let mut controller =
                crate::control::random::RandomTurns::new(shared::ActionTable::default());
            let every_block = PixyCameraConfig {
                max_blocks_per_signature: 100,
                ..PixyCameraConfig::default()
            };
            let mut camera = PixyCamera::new(&every_block, unit);
            for step in 0..600 {
                sim.run(&mut controller, 1);
                assert_reference_frames(
                    &mut camera,
                    sim.world(),
                    &format!("unit {unit} mm, step {step}"),
                );
            }
        }
    }

    #[test]
    fn bodies_beside_the_view_have_no_silhouette() {
        let mut rng = SimRng::seed_from_u64(11);
        let mut beside = 0;
        for settings in camera_variants() {
            for config in arena_scales() {
                let w = &config.world;
                let camera = PixyCamera::new(&settings, w.unit_mm);
                let outline = Outline::new(w.robot_radius, 1.3 * w.robot_radius);
                let wedge = WedgePoints::new(&outline, &camera.rim_ahead, &camera.rim_right);
                let lens = Lens {
                    pos: Vec2::ZERO,
                    ahead: Vec2::new(1.0, 0.0),
                    right: Vec2::new(0.0, 1.0),
                };
                for k in 0..4000 {
                    let robot = k % 2 == 0;
                    let (radius, height) = if robot {
                        (outline.tip(), camera.robot_height)
                    } else {
                        (w.puck_radius, camera.puck_height)
                    };
                    let reach = camera.max_range + radius;
                    let ahead = rng.random_range(-radius..reach);
                    // Near where the bound crosses zero, on either side.
                    let bound = &camera.beside;
                    let edge = radius * bound.per_radius + bound.offset + bound.slope * ahead;
                    let near = if k % 3 == 0 { 1e-6 } else { 0.05 };
                    let side = edge
                        * rng.random_range(1.0 - near..1.0 + near)
                        * if k % 4 < 2 { 1.0 } else { -1.0 };
                    if !camera.beside_view(ahead, side, radius) {
                        continue;
                    }
                    beside += 1;
                    let c = Candidate {
                        index: usize::from(!robot),
                        signature: 1,
                        ahead,
                        side,
                        radius,
                        height,
                        distance_squared: ahead * ahead + side * side,
                    };
                    let rect = if robot {
                        let facing = Vec2::from_angle(rng.random_range(0.0..std::f64::consts::TAU));
                        outline_box::<WEDGE_POINTS>(&camera, &c, &lens, facing, &wedge)
                    } else {
                        project(&camera, ahead, side, radius, height)
                    };
                    assert!(rect.is_none(), "{settings:?}: {c:?} shows as {rect:?}");
                }
            }
        }
        assert!(beside > 10_000, "{beside}");
    }

    #[test]
    fn the_search_box_holds_every_body_the_culls_pass() {
        let mut rng = SimRng::seed_from_u64(17);
        for settings in camera_variants() {
            let camera = PixyCamera::new(&settings, 5.0);
            let (robot_r, puck_r) = (10.0, 8.0);
            for pose in 0..400 {
                let quarter = std::f64::consts::FRAC_PI_2;
                let heading = if pose % 2 == 0 {
                    quarter * f64::from(pose / 2 % 4)
                } else {
                    rng.random_range(-4.0..4.0)
                };
                let ahead = Vec2::from_angle(heading);
                let lens = Lens {
                    pos: Vec2::new(rng.random_range(0.0..800.0), rng.random_range(0.0..800.0)),
                    ahead,
                    right: Vec2::new(-ahead.y, ahead.x),
                };
                let (min, max) = camera.search_box(&lens, &SearchSpan::new(&camera, robot_r));
                for k in 0..2000 {
                    let (radius, body) = if k % 2 == 0 {
                        (robot_r, 1)
                    } else {
                        (puck_r, 2)
                    };
                    let height = if body == 1 {
                        camera.robot_height
                    } else {
                        camera.puck_height
                    };
                    let reach = camera.max_range + radius;
                    // On the range's circle, on the side cull's or the wider
                    // side test's edges, or anywhere near.
                    let (f, s) = match k % 4 {
                        0 => {
                            let angle = rng.random_range(-1.6..1.6) * (k % 7) as f64 / 6.0;
                            (reach * angle.cos(), reach * angle.sin())
                        }
                        1 | 2 => {
                            let f = rng.random_range(-radius..reach);
                            let bound = &camera.beside;
                            let side = if k % 4 == 1 {
                                bound.slope * f + radius * bound.per_radius + bound.offset
                            } else {
                                (f + radius + camera.height + height) * camera.tan_half_h + radius
                            };
                            (f, if k % 8 < 4 { side } else { -side })
                        }
                        _ => (
                            rng.random_range(-reach..reach),
                            rng.random_range(-reach..reach),
                        ),
                    };
                    let pos = lens.pos + lens.ahead * f + lens.right * s;
                    let b = Neighbour { pos, radius, body };
                    if camera.candidate(2, 0, &lens, &b).is_some() {
                        let inside =
                            min.x <= pos.x && pos.x <= max.x && min.y <= pos.y && pos.y <= max.y;
                        assert!(inside, "{settings:?}: {pos:?} outside {min:?} ..= {max:?}");
                    }
                }
            }
        }
    }
}
