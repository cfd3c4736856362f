//! Pictures of the world like the thesis' Figure 11: the field as a grey
//! background (0 black, 1 white), pucks red, robots blue (discs, or their
//! wedge-fronted outline) with a heading line, optionally the outline of
//! the target band (cyan: the edge of the region whose field value lies
//! between the thresholds, where Eval wants every puck; the pucks Eval
//! counts as in it are then drawn green) and each robot's sensor
//! footprints. (Writing them as PNG or GIF files is the host's.)
//!
//! Room 11 of the simulator (`lib.rs`), at the top: it reads a simulation and
//! changes nothing.

use crate::base::vec2::Vec2;
use crate::episodes::eval::{in_band, pucks_in_band};
use crate::fields::ScalarField;
use crate::physics::outline::Outline;
use crate::sensors::{FootprintKind, SensorModel};
use crate::simulation::Simulation;
use crate::world::World;
use image::{Rgb, RgbImage};

/// A puck's colour.
pub const PUCK: Rgb<u8> = Rgb([200, 44, 44]);
/// A puck's colour in the target band, when the band is drawn.
/// The live view's page (`view/src/page.html`) draws them the same.
pub const PUCK_IN_BAND: Rgb<u8> = Rgb([40, 180, 80]);
const ROBOT: Rgb<u8> = Rgb([0, 100, 200]);
const HEADING: Rgb<u8> = Rgb([255, 255, 255]);
const PUCK_SENSOR: Rgb<u8> = Rgb([250, 200, 0]);
const OBSTACLE_SENSOR: Rgb<u8> = Rgb([220, 0, 220]);
const FIELD_SENSOR: Rgb<u8> = Rgb([0, 200, 0]);
/// The target band's outline.
pub const BAND: Rgb<u8> = Rgb([0, 220, 220]);

/// How to draw.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct RenderOptions {
    /// Image width, pixels (the height follows the arena's shape).
    pub size: u32,
    /// Draw each robot's sensor discs and field points.
    pub footprints: bool,
    /// Outline the target band under the bodies.
    pub band: bool,
}

impl Default for RenderOptions {
    /// 800 pixels, no footprints, no band.
    fn default() -> RenderOptions {
        RenderOptions {
            size: 800,
            footprints: false,
            band: false,
        }
    }
}

/// Draws the simulation's current world.
pub fn draw<S: SensorModel>(sim: &Simulation<S>, options: RenderOptions) -> RgbImage {
    let world = sim.world();
    let mut img = draw_ground(sim, options);
    let scale = scale_of(world, options.size);
    let in_band: Vec<bool> = if options.band {
        pucks_in_band(world, sim.field(), &sim.config().thresholds).collect()
    } else {
        Vec::new()
    };
    draw_bodies(&mut img, world, scale, &in_band);
    if !options.footprints {
        return img;
    }
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

/// What lies under the bodies: the field as grey and, with `options.band`,
/// the target band's outline (the live view's background, `view`).
pub fn draw_ground<S: SensorModel>(sim: &Simulation<S>, options: RenderOptions) -> RgbImage {
    let world = sim.world();
    let mut img = draw_field(world, sim.field(), options.size);
    if options.band {
        let scale = scale_of(world, options.size);
        let layout = world.config().field_layout();
        let thresholds = &sim.config().thresholds;
        outline_region(&mut img, BAND, |x, y| {
            let p = Vec2::new((f64::from(x) + 0.5) / scale, (f64::from(y) + 0.5) / scale);
            in_band(f64::from(sim.field().evaluate(p, &layout)), thresholds)
        });
    }
    img
}

/// Draws a world over `field`, `size` pixels wide: the field (its value as
/// grey, as the world reads it), pucks, robots with their heading.
pub fn draw_world(world: &World, field: &ScalarField, size: u32) -> RgbImage {
    let mut img = draw_field(world, field, size);
    draw_bodies(&mut img, world, scale_of(world, size), &[]);
    img
}

/// The field as the world reads it, as grey, `size` pixels wide.
fn draw_field(world: &World, field: &ScalarField, size: u32) -> RgbImage {
    let (arena, layout) = (world.config().arena(), world.config().field_layout());
    let scale = scale_of(world, size);
    let height = (arena.y * scale).round().max(1.0) as u32;
    RgbImage::from_fn(size, height, |x, y| {
        let p = Vec2::new((f64::from(x) + 0.5) / scale, (f64::from(y) + 0.5) / scale);
        let v = (field.evaluate(p, &layout) * 255.0).round() as u8;
        Rgb([v, v, v])
    })
}

/// Pucks (those `in_band` says are in the target band green), then
/// robots with their heading, `scale` pixels per unit.
fn draw_bodies(img: &mut RgbImage, world: &World, scale: f64, in_band: &[bool]) {
    let to_px = |p: Vec2| p * scale;
    for (i, puck) in world.pucks().iter().enumerate() {
        let colour = if in_band.get(i) == Some(&true) {
            PUCK_IN_BAND
        } else {
            PUCK
        };
        fill_circle(img, to_px(puck.pos), puck.radius * scale, colour);
    }
    let outline = Outline::of(world.config().robot_shape, world.config().robot_radius);
    for (i, robot) in world.robots().iter().enumerate() {
        let body = &world.bodies()[i];
        match &outline {
            None => fill_circle(img, to_px(body.pos), body.radius * scale, ROBOT),
            Some(o) => fill_outline(img, to_px(body.pos), robot.direction, o, scale, ROBOT),
        }
        let tip = body.pos + robot.direction * body.radius;
        draw_line(img, to_px(body.pos), to_px(tip), HEADING);
    }
}

/// Colours the edge of a region of `img`: every pixel inside it (`inside(x,
/// y)`) with a 4-neighbour in the image outside it. The image's border is
/// no edge, so a region that fills the picture draws nothing.
pub fn outline_region(img: &mut RgbImage, colour: Rgb<u8>, inside: impl Fn(u32, u32) -> bool) {
    let (w, h) = img.dimensions();
    let mask: Vec<bool> = (0..h)
        .flat_map(|y| (0..w).map(move |x| (x, y)))
        .map(|(x, y)| inside(x, y))
        .collect();
    let at = |x: u32, y: u32| mask[y as usize * w as usize + x as usize];
    for y in 0..h {
        for x in 0..w {
            let edge = at(x, y)
                && ((x > 0 && !at(x - 1, y))
                    || (x + 1 < w && !at(x + 1, y))
                    || (y > 0 && !at(x, y - 1))
                    || (y + 1 < h && !at(x, y + 1)));
            if edge {
                img.put_pixel(x, y, colour);
            }
        }
    }
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scenario::Scenario;

    #[test]
    fn the_band_option_outlines_the_band_and_turns_only_the_pucks_in_it_green() {
        let (sim, _) = Scenario::default().build().unwrap();
        let plain = draw(&sim, RenderOptions::default());
        let banded = draw(
            &sim,
            RenderOptions {
                band: true,
                ..RenderOptions::default()
            },
        );
        let scale = scale_of(sim.world(), plain.width());
        let layout = sim.world().config().field_layout();
        let in_band_pucks: Vec<bool> =
            pucks_in_band(sim.world(), sim.field(), &sim.config().thresholds).collect();
        let (mut changed, mut green) = (0, 0);
        for (x, y, p) in banded.enumerate_pixels() {
            if p == plain.get_pixel(x, y) {
                continue;
            }
            let centre = Vec2::new((f64::from(x) + 0.5) / scale, (f64::from(y) + 0.5) / scale);
            if *p == PUCK_IN_BAND {
                // a puck's pixel: the puck under it lies in the band
                let puck = sim
                    .world()
                    .pucks()
                    .iter()
                    .position(|q| (q.pos - centre).length() <= q.radius + 1.0 / scale)
                    .unwrap_or_else(|| panic!("({x}, {y}) is green off every puck"));
                assert!(
                    in_band_pucks[puck],
                    "({x}, {y}): puck {puck} is not in the band"
                );
                green += 1;
                continue;
            }
            changed += 1;
            assert_eq!(*p, BAND, "pixel ({x}, {y})");
            let value = f64::from(sim.field().evaluate(centre, &layout));
            assert!(
                in_band(value, &sim.config().thresholds),
                "({x}, {y}): {value}"
            );
        }
        assert!(changed > 100, "{changed} pixels outlined");
        assert_eq!(
            green > 0,
            in_band_pucks.contains(&true),
            "{green} green pixels"
        );
        assert!(
            plain.pixels().all(|p| *p != PUCK_IN_BAND),
            "green only with the band"
        );
    }

    #[test]
    fn a_region_filling_the_picture_has_no_outline_and_a_square_has_its_rim() {
        let mut img = RgbImage::new(8, 8);
        outline_region(&mut img, BAND, |_, _| true);
        assert!(img.pixels().all(|p| *p != BAND));
        outline_region(&mut img, BAND, |x, y| {
            (2..6).contains(&x) && (2..6).contains(&y)
        });
        let rim: Vec<(u32, u32)> = img
            .enumerate_pixels()
            .filter(|(_, _, p)| **p == BAND)
            .map(|(x, y, _)| (x, y))
            .collect();
        assert_eq!(rim.len(), 12, "{rim:?}");
        assert!(rim
            .iter()
            .all(|&(x, y)| x == 2 || x == 5 || y == 2 || y == 5));
    }
}
