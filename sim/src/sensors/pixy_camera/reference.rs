//! The camera's stages as they were first written (one rim point at a time,
//! every body near the lens visited, merging restarted after each merge),
//! kept as the reference the faster stages must match block for block.

use super::{first_pixel, last_pixel, Blob, Candidate, InView, Lens, PixyCamera, Rect};
use crate::base::vec2::Vec2;
use crate::physics::outline::Outline;
use crate::world::World;
use shared::camera::{IMAGE_HEIGHT, IMAGE_WIDTH};
use shared::PixyBlock;
use std::cmp::Ordering;

/// The frame robot `robot` sees through `camera`, by the reference stages.
pub(super) fn frame(camera: &PixyCamera, world: &World, robot: usize) -> Vec<PixyBlock> {
    let mut camera = camera.clone();
    gather_in_view(&mut camera, world, robot);
    occlude(&mut camera);
    merge_and_prune(&mut camera.blobs, camera.merge_distance);
    let mut out = Vec::new();
    camera.emit_blocks(&mut out);
    out
}

/// Stage 1: every body near the lens through the culls, each projected.
fn gather_in_view(camera: &mut PixyCamera, world: &World, robot: usize) {
    let lens = Lens::of(world, robot, camera.forward);
    let mut in_view = Vec::new();
    let outline = Outline::of(world.config().robot_shape, world.config().robot_radius);
    let robots = world.robots().len();
    world.any_body_near(lens.pos, camera.max_range, |row| {
        for b in row {
            let Some(c) = camera.candidate(robots, robot, &lens, b) else {
                continue;
            };
            let rect = match outline.filter(|_| c.index < robots) {
                None => silhouette(camera, c.ahead, c.side, c.radius, c.height),
                Some(o) => {
                    outline_silhouette(camera, &c, &lens, world.robots()[c.index].direction, &o)
                }
            };
            if let Some(rect) = rect {
                in_view.push(c.in_view(rect));
            }
        }
        false
    });
    sort_nearest_first(&mut in_view);
    camera.in_view = in_view;
}

/// Sorts bodies in view nearest first, ties by body index.
fn sort_nearest_first(in_view: &mut [InView]) {
    in_view.sort_unstable_by(|a, b| {
        a.distance
            .partial_cmp(&b.distance)
            .unwrap_or(Ordering::Equal)
            .then(a.index.cmp(&b.index))
    });
}

/// The clipped pixel box of a wedge-fronted robot, candidate `c`, facing
/// `facing`: the bounding box of the rim points of its round back, its
/// tangent points and its tip, at the bottom and the top, one point at a
/// time.
fn outline_silhouette(
    camera: &PixyCamera,
    c: &Candidate,
    lens: &Lens,
    facing: Vec2,
    outline: &Outline,
) -> Option<Rect> {
    let right = Vec2::new(-facing.y, facing.x);
    let r = outline.radius();
    let t = outline.tangent_point();
    let mut points = [Vec2::ZERO; super::RIM_POINTS + 3];
    points[..3].copy_from_slice(&[Vec2::new(outline.tip(), 0.0), t, Vec2::new(t.x, -t.y)]);
    let mut n = 3;
    for k in 0..super::RIM_POINTS {
        if camera.rim_ahead[k] * r < t.x {
            points[n] = Vec2::new(camera.rim_ahead[k], camera.rim_right[k]) * r;
            n += 1;
        }
    }
    let (mut min_x, mut max_x, mut min_y, mut max_y) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
    for z in [0.0, c.height] {
        let up = z - camera.height;
        for p in &points[..n] {
            let offset = facing * p.x + right * p.y;
            let (pf, ps) = (
                c.ahead + offset.dot(lens.ahead),
                c.side + offset.dot(lens.right),
            );
            let depth = pf * camera.cos_tilt - up * camera.sin_tilt;
            if depth < camera.near {
                return None;
            }
            let down = -pf * camera.sin_tilt - up * camera.cos_tilt;
            let (x, y) = (camera.fx * ps / depth, camera.fy * down / depth);
            min_x = min_x.min(x);
            max_x = max_x.max(x);
            min_y = min_y.min(y);
            max_y = max_y.max(y);
        }
    }
    let (cx, cy) = (f64::from(IMAGE_WIDTH) / 2.0, f64::from(IMAGE_HEIGHT) / 2.0);
    let rect = Rect {
        left: first_pixel(cx + min_x, IMAGE_WIDTH),
        right: last_pixel(cx + max_x, IMAGE_WIDTH),
        top: first_pixel(cy + min_y, IMAGE_HEIGHT),
        bottom: last_pixel(cy + max_y, IMAGE_HEIGHT),
    };
    (rect.left <= rect.right && rect.top <= rect.bottom).then_some(rect)
}

/// The clipped pixel box of a cylinder, one rim point at a time.
fn silhouette(camera: &PixyCamera, f: f64, s: f64, radius: f64, height: f64) -> Option<Rect> {
    let (mut min_x, mut max_x, mut min_y, mut max_y) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
    for z in [0.0, height] {
        let up = z - camera.height;
        for (&cos, &sin) in camera.rim_ahead.iter().zip(&camera.rim_right) {
            let (pf, ps) = (f + radius * cos, s + radius * sin);
            let depth = pf * camera.cos_tilt - up * camera.sin_tilt;
            if depth < camera.near {
                return None;
            }
            let down = -pf * camera.sin_tilt - up * camera.cos_tilt;
            let inverse = 1.0 / depth;
            let x = f64::from(IMAGE_WIDTH) / 2.0 + camera.fx * ps * inverse;
            let y = f64::from(IMAGE_HEIGHT) / 2.0 + camera.fy * down * inverse;
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

/// Stage 2: each body's still visible part after the nearer ones'
/// silhouettes are cut away, one nearer body at a time, as a blob if it has
/// at least `min_area` pixels.
fn occlude(camera: &mut PixyCamera) {
    camera.blobs.clear();
    for (k, body) in camera.in_view.iter().enumerate() {
        let mut pieces = vec![body.rect];
        for nearer in &camera.in_view[..k] {
            let mut rest = Vec::new();
            for piece in &pieces {
                piece.subtract_into(&nearer.rect, &mut rest);
            }
            pieces = rest;
        }
        let Some(first) = pieces.first() else {
            continue;
        };
        let rect = pieces.iter().fold(*first, |r, p| r.union(p));
        let area = pieces.iter().map(Rect::area).sum();
        if area >= camera.min_area {
            camera.blobs.push(Blob {
                signature: body.signature,
                rect,
                area,
            });
        }
    }
}

/// Stage 3: merges the first mergeable pair and starts again until none
/// is left, then drops blocks enclosed by another, one at a time.
fn merge_and_prune(blobs: &mut Vec<Blob>, d: i32) {
    let mut merged = true;
    while merged {
        merged = false;
        'outer: for i in 0..blobs.len() {
            for j in i + 1..blobs.len() {
                let (a, b) = (blobs[i], blobs[j]);
                let (gx, gy) = (a.rect.gap_x(&b.rect), a.rect.gap_y(&b.rect));
                if a.signature == b.signature && ((gx <= d && gy <= 0) || (gy <= d && gx <= 0)) {
                    blobs[i] = Blob {
                        signature: a.signature,
                        rect: a.rect.union(&b.rect),
                        area: a.area + b.area,
                    };
                    blobs.remove(j);
                    merged = true;
                    break 'outer;
                }
            }
        }
    }
    let mut k = 0;
    while k < blobs.len() {
        let enclosed = (0..blobs.len()).any(|o| {
            o != k
                && blobs[o].rect.contains(&blobs[k].rect)
                && (blobs[o].rect != blobs[k].rect || o < k)
        });
        if enclosed {
            blobs.remove(k);
        } else {
            k += 1;
        }
    }
}
