//! Pictures of the world like the thesis' Figure 11: the field as a grey
//! background (0 black, 1 white), pucks red, robots blue (discs, or their
//! wedge-fronted outline) with a heading line, optionally each robot's
//! sensor footprints. (Writing them as PNG or GIF files is the host's.)
//!
//! Room 11 of the simulator (`lib.rs`), at the top: it reads a simulation and
//! changes nothing.

use crate::base::vec2::Vec2;
use crate::fields::ScalarField;
use crate::physics::outline::Outline;
use crate::sensors::{FootprintKind, SensorModel};
use crate::simulation::Simulation;
use crate::world::World;
use image::{Rgb, RgbImage};

/// A puck's colour.
pub const PUCK: Rgb<u8> = Rgb([200, 44, 44]);
const ROBOT: Rgb<u8> = Rgb([0, 100, 200]);
const HEADING: Rgb<u8> = Rgb([255, 255, 255]);
const PUCK_SENSOR: Rgb<u8> = Rgb([250, 200, 0]);
const OBSTACLE_SENSOR: Rgb<u8> = Rgb([220, 0, 220]);
const FIELD_SENSOR: Rgb<u8> = Rgb([0, 200, 0]);

/// How to draw.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RenderOptions {
    /// Image width, pixels (the height follows the arena's shape).
    pub size: u32,
    /// Draw each robot's sensor discs and field points.
    pub footprints: bool,
}

impl Default for RenderOptions {
    /// 800 pixels, no footprints.
    fn default() -> RenderOptions {
        RenderOptions {
            size: 800,
            footprints: false,
        }
    }
}

/// Draws the simulation's current world.
pub fn draw<S: SensorModel>(sim: &Simulation<S>, options: RenderOptions) -> RgbImage {
    let world = sim.world();
    let mut img = draw_world(world, sim.field(), options.size);
    if !options.footprints {
        return img;
    }
    let scale = scale_of(world, options.size);
    let to_px = |p: Vec2| p * scale;
    let mut footprints = Vec::new();
    for i in 0..world.robots().len() {
        footprints.clear();
        sim.sensors().footprints(world, i, &mut footprints);
        for f in &footprints {
            let (colour, r) = match f.kind {
                FootprintKind::Field => (FIELD_SENSOR, 2.0),
                FootprintKind::Puck => (PUCK_SENSOR, f.radius * scale),
                FootprintKind::Obstacle => (OBSTACLE_SENSOR, f.radius * scale),
            };
            if f.kind == FootprintKind::Field {
                fill_circle(&mut img, to_px(f.centre), r, colour);
            } else {
                outline_circle(&mut img, to_px(f.centre), r, colour);
            }
        }
    }
    img
}

/// Draws a world over `field`, `size` pixels wide: the field (its value as
/// grey, as the world reads it), pucks, robots with their heading.
pub fn draw_world(world: &World, field: &ScalarField, size: u32) -> RgbImage {
    let (arena, layout) = (world.config().arena(), world.config().field_layout());
    let scale = scale_of(world, size);
    let height = (arena.y * scale).round().max(1.0) as u32;
    let mut img = RgbImage::from_fn(size, height, |x, y| {
        let p = Vec2::new((f64::from(x) + 0.5) / scale, (f64::from(y) + 0.5) / scale);
        let v = (field.evaluate(p, &layout) * 255.0).round() as u8;
        Rgb([v, v, v])
    });
    let to_px = |p: Vec2| p * scale;
    for puck in world.pucks() {
        fill_circle(&mut img, to_px(puck.pos), puck.radius * scale, PUCK);
    }
    let outline = Outline::of(world.config().robot_shape, world.config().robot_radius);
    for (i, robot) in world.robots().iter().enumerate() {
        let body = &world.bodies()[i];
        match &outline {
            None => fill_circle(&mut img, to_px(body.pos), body.radius * scale, ROBOT),
            Some(o) => fill_outline(&mut img, to_px(body.pos), robot.direction, o, scale, ROBOT),
        }
        let tip = body.pos + robot.direction * body.radius;
        draw_line(&mut img, to_px(body.pos), to_px(tip), HEADING);
    }
    img
}

/// Fills the outline of a wedge-fronted robot centred at `c` (pixels),
/// facing `direction`, at `scale` pixels per unit: every pixel whose centre
/// lies inside it.
pub fn fill_outline(
    img: &mut RgbImage,
    c: Vec2,
    direction: Vec2,
    outline: &Outline,
    scale: f64,
    colour: Rgb<u8>,
) {
    let reach = (outline.tip() * scale).ceil() as i64;
    let (cx, cy) = (c.x.floor() as i64, c.y.floor() as i64);
    let right = Vec2::new(-direction.y, direction.x);
    for y in cy - reach..=cy + reach {
        for x in cx - reach..=cx + reach {
            let d = (Vec2::new(x as f64 + 0.5, y as f64 + 0.5) - c) * (1.0 / scale);
            if outline
                .distance(Vec2::new(d.dot(direction), d.dot(right)))
                .0
                <= 0.0
            {
                put(img, x, y, colour);
            }
        }
    }
}

/// Pixels per unit of a drawing `size` pixels wide.
fn scale_of(world: &World, size: u32) -> f64 {
    f64::from(size) / world.config().arena().x
}

fn put(img: &mut RgbImage, x: i64, y: i64, colour: Rgb<u8>) {
    if (0..i64::from(img.width())).contains(&x) && (0..i64::from(img.height())).contains(&y) {
        img.put_pixel(x as u32, y as u32, colour);
    }
}

fn fill_circle(img: &mut RgbImage, c: Vec2, r: f64, colour: Rgb<u8>) {
    let reach = r.ceil() as i64;
    let (cx, cy) = (c.x.floor() as i64, c.y.floor() as i64);
    for y in cy - reach..=cy + reach {
        for x in cx - reach..=cx + reach {
            let d = Vec2::new(x as f64 + 0.5, y as f64 + 0.5) - c;
            if d.length_squared() <= r * r {
                put(img, x, y, colour);
            }
        }
    }
}

/// A circle's outline of radius `r` around `c`, pixels.
pub fn outline_circle(img: &mut RgbImage, c: Vec2, r: f64, colour: Rgb<u8>) {
    let steps = (r * 8.0).ceil().max(16.0) as usize;
    for k in 0..steps {
        let p = c + Vec2::from_angle(k as f64 * std::f64::consts::TAU / steps as f64) * r;
        put(img, p.x.floor() as i64, p.y.floor() as i64, colour);
    }
}

fn draw_line(img: &mut RgbImage, a: Vec2, b: Vec2, colour: Rgb<u8>) {
    let steps = (b - a).length().ceil().max(1.0) as usize * 2;
    for k in 0..=steps {
        let p = a + (b - a) * (k as f64 / steps as f64);
        put(img, p.x.floor() as i64, p.y.floor() as i64, colour);
    }
}
