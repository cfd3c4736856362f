//! `host observe`: did it build? Measures a run on the floor from a photo
//! of the TV taken from above (`docs/display.md`).
//!
//! The screen's four corners in the photo (given once: the camera stays
//! put) define the perspective map from the arena to the photo
//! ([`homography`]); the photo is resampled top-down over the arena
//! (`pixels_per_unit` as fine as the photo allows), the pucks are found
//! there by colour ([`pucks`]), and the simulator evaluates a world of the
//! detected pucks (`sim::world::World::scene`, `sim::episodes::eval`) against the field's
//! success threshold (`sim::scenario::field_config`). The picture shows
//! the top-down photo with the detected pucks outlined above the
//! simulator's drawing of the detected world over the field.
//!
//! Assumed: the photo is taken from above, so the pucks' tops lie close
//! to the screen's plane (a puck `h` high seen from `H` above shifts by
//! `h / H` of its distance from the point below the camera).

pub mod homography;
pub mod pucks;

use anyhow::{Context, Result};
use homography::Homography;
use image::codecs::png::PngEncoder;
use image::{Rgb, RgbImage};
use pucks::ColourMatch;
use serde::Serialize;
use sim::base::ranges;
use sim::base::vec2::Vec2;
use sim::fields::source::read_image;
use sim::fields::source::FieldSource;
use sim::scenario::arena::ArenaSpec;
use sim::scenario::{Arena, Scenario};
use sim::world::World;
use std::fmt;
use std::path::{Path, PathBuf};

/// The corners' order, as messages name them.
pub const CORNER_NAMES: [&str; 4] = ["top-left", "top-right", "bottom-right", "bottom-left"];

/// What to measure.
#[derive(Clone, Debug, PartialEq)]
pub struct ObserveSettings {
    /// The photo (PNG or JPEG).
    pub photo: PathBuf,
    /// The screen.
    pub arena: ArenaSpec,
    /// The field the run built.
    pub field: FieldSource,
    /// The screen's visible corners in the photo, pixels from its top-left:
    /// the panel's top-left, top-right, bottom-right and bottom-left (its
    /// first pixel is the top-left).
    pub corners: [[f64; 2]; 4],
    /// The pucks' colour as the camera sees it.
    pub puck_colour: [u8; 3],
    /// Where to write the picture, if anywhere.
    pub picture: Option<PathBuf>,
}

/// One detected puck.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct ObservedPuck {
    /// Position, units from the screen's top-left corner.
    pub x: f64,
    /// Position, units.
    pub y: f64,
    /// The field value there, as Eval reads it.
    pub value: f64,
}

/// What the photo shows.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Observation {
    /// The photo.
    pub photo: String,
    /// The arena's name.
    pub arena: String,
    /// The field.
    pub field: String,
    /// Millimetres per unit.
    pub unit_mm: f64,
    /// Resolution of the top-down resampling, pixels per unit.
    pub pixels_per_unit: f64,
    /// The detected pucks.
    pub pucks: Vec<ObservedPuck>,
    /// Pucks the arena places (a different count found is worth a look).
    pub arena_pucks: usize,
    /// Eval of the detected pucks.
    pub eval: f64,
    /// The field's success threshold: formed when Eval exceeds it.
    pub success_eval: f64,
    /// Whether the shape is formed: pucks were found and Eval exceeds the
    /// threshold (Eval of no pucks is 1).
    pub formed: bool,
}

impl fmt::Display for Observation {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(f, "photo {}: {} on {}", self.photo, self.field, self.arena)?;
        writeln!(
            f,
            "pucks found: {} (the arena places {})",
            self.pucks.len(),
            self.arena_pucks
        )?;
        if self.pucks.is_empty() {
            writeln!(f, "  none: check --corners and --puck-colour (the pucks' colour as the camera sees it)")?;
        }
        for (i, p) in self.pucks.iter().enumerate() {
            let (x_mm, y_mm) = (p.x * self.unit_mm, p.y * self.unit_mm);
            writeln!(
                f,
                "  {:>3}: ({:7.1}, {:7.1}) mm, field {:.3}",
                i + 1,
                x_mm,
                y_mm,
                p.value
            )?;
        }
        let verdict = if self.formed { "formed" } else { "not formed" };
        writeln!(
            f,
            "Eval {:.4} (success above {}): {verdict}",
            self.eval, self.success_eval
        )
    }
}

/// Measures the photo; writes the picture if asked.
pub fn observe(settings: &ObserveSettings) -> Result<Observation> {
    let arena = &settings.arena;
    arena
        .validate()
        .with_context(|| format!("arena {}", arena.name))?;
    let colour = ColourMatch::of(settings.puck_colour).with_context(|| {
        let [r, g, b] = settings.puck_colour;
        format!(
            "--puck-colour {r},{g},{b} is too grey to tell the pucks from the field: give their colour as the camera sees it"
        )
    })?;
    let photo_path = &settings.photo;
    let photo = read_image(photo_path, "photo", &ranges::PHOTO_SIDE)?.to_rgb8();
    let to_photo = screen_map(arena, &settings.corners, photo.dimensions())?;
    let scale = pixels_per_unit(arena, &settings.corners);
    let top_down = resample(&photo, &to_photo, arena.size(), scale);
    let radius = arena.puck_radius_mm / arena.unit_mm();
    let centres: Vec<Vec2> = pucks::find_pucks(&top_down, &colour, radius * scale)
        .into_iter()
        .map(|[x, y]| Vec2::new(x / scale, y / scale))
        .collect();

    let field = arena.load_field(&settings.field)?;
    let scenario = Scenario {
        field: settings.field.clone(),
        arena: Arena::Screen(Box::new(arena.clone())),
        ..Scenario::default()
    };
    let config = scenario.config(&field);
    let world = World::scene(&config, &[], &centres, 0);
    let eval = sim::episodes::eval::eval(&world, &field, &config.thresholds);
    let layout = config.world.field_layout();
    let observation = Observation {
        photo: photo_path.display().to_string(),
        arena: arena.name.clone(),
        field: settings.field.to_string(),
        unit_mm: arena.unit_mm(),
        pixels_per_unit: scale,
        pucks: centres
            .iter()
            .map(|p| ObservedPuck {
                x: p.x,
                y: p.y,
                value: f64::from(field.evaluate(*p, &layout)),
            })
            .collect(),
        arena_pucks: arena.pucks,
        eval,
        success_eval: config.episode.success_eval,
        formed: !centres.is_empty() && eval > config.episode.success_eval,
    };
    if let Some(path) = &settings.picture {
        let mut outlined = top_down;
        for c in &centres {
            for r in [radius, radius + 1.0 / scale] {
                sim::render::outline_circle(&mut outlined, *c * scale, r * scale, OUTLINE);
            }
        }
        let drawn = sim::render::draw_world(&world, &field, outlined.width());
        write_png(&stack(&outlined, &drawn), path)?;
    }
    Ok(observation)
}

/// Detected pucks' outline in the picture.
const OUTLINE: Rgb<u8> = Rgb([0, 230, 0]);

/// The map from the arena (units) to the photo (pixels), the corners checked.
fn screen_map(
    arena: &ArenaSpec,
    corners: &[[f64; 2]; 4],
    (w, h): (u32, u32),
) -> Result<Homography> {
    for (c, name) in corners.iter().zip(CORNER_NAMES) {
        let inside = (0.0..=f64::from(w)).contains(&c[0]) && (0.0..=f64::from(h)).contains(&c[1]);
        anyhow::ensure!(
            inside,
            "--corners: the {name} corner ({}, {}) lies outside the photo ({w} x {h})",
            c[0],
            c[1]
        );
    }
    let turns: Vec<f64> = (0..4)
        .map(|i| {
            let (a, b, c) = (corners[i], corners[(i + 1) % 4], corners[(i + 2) % 4]);
            (b[0] - a[0]) * (c[1] - b[1]) - (b[1] - a[1]) * (c[0] - b[0])
        })
        .collect();
    let convex = turns.iter().all(|t| *t > 0.0) || turns.iter().all(|t| *t < 0.0);
    anyhow::ensure!(
        convex,
        "--corners do not form a convex quadrilateral in the order {}: check the order and the values",
        CORNER_NAMES.join(", ")
    );
    let size = arena.size();
    let screen = [[0.0, 0.0], [size.x, 0.0], [size.x, size.y], [0.0, size.y]];
    Homography::from_points(&screen, corners)
        .context("--corners: no perspective maps the screen onto them")
}

/// Top-down pixels per unit: as fine as the photo's view of the screen
/// (its shorter mean side), 1 to 8.
fn pixels_per_unit(arena: &ArenaSpec, c: &[[f64; 2]; 4]) -> f64 {
    let length = |a: [f64; 2], b: [f64; 2]| (a[0] - b[0]).hypot(a[1] - b[1]);
    let size = arena.size();
    let across = (length(c[0], c[1]) + length(c[3], c[2])) / 2.0 / size.x;
    let down = (length(c[0], c[3]) + length(c[1], c[2])) / 2.0 / size.y;
    across.min(down).clamp(1.0, 8.0)
}

/// The photo resampled over the arena, `scale` pixels per unit (bilinear).
fn resample(photo: &RgbImage, to_photo: &Homography, size: Vec2, scale: f64) -> RgbImage {
    let (w, h) = (
        (size.x * scale).round().max(1.0) as u32,
        (size.y * scale).round().max(1.0) as u32,
    );
    RgbImage::from_fn(w, h, |x, y| {
        let p = [(f64::from(x) + 0.5) / scale, (f64::from(y) + 0.5) / scale];
        to_photo
            .apply(p)
            .map_or(Rgb([0, 0, 0]), |q| sample(photo, q))
    })
}

/// The photo's colour at `p` (pixels, continuous), bilinear between pixel
/// centres, edges extended.
pub fn sample(photo: &RgbImage, [x, y]: [f64; 2]) -> Rgb<u8> {
    let (w, h) = (photo.width() as i64, photo.height() as i64);
    let (fx, fy) = (x - 0.5, y - 0.5);
    let (x0, y0) = (fx.floor(), fy.floor());
    let (tx, ty) = (fx - x0, fy - y0);
    let at = |i: i64, j: i64| {
        photo
            .get_pixel(i.clamp(0, w - 1) as u32, j.clamp(0, h - 1) as u32)
            .0
    };
    let (i, j) = (x0 as i64, y0 as i64);
    let (a, b, c, d) = (at(i, j), at(i + 1, j), at(i, j + 1), at(i + 1, j + 1));
    Rgb(std::array::from_fn(|k| {
        let top = f64::from(a[k]) + (f64::from(b[k]) - f64::from(a[k])) * tx;
        let bottom = f64::from(c[k]) + (f64::from(d[k]) - f64::from(c[k])) * tx;
        (top + (bottom - top) * ty).round().clamp(0.0, 255.0) as u8
    }))
}

/// `top` above `bottom`.
fn stack(top: &RgbImage, bottom: &RgbImage) -> RgbImage {
    let width = top.width().max(bottom.width());
    RgbImage::from_fn(width, top.height() + bottom.height(), |x, y| {
        let (img, y) = if y < top.height() {
            (top, y)
        } else {
            (bottom, y - top.height())
        };
        if x < img.width() {
            *img.get_pixel(x, y)
        } else {
            Rgb([0, 0, 0])
        }
    })
}

fn write_png(img: &RgbImage, path: &Path) -> Result<()> {
    let mut bytes = Vec::new();
    img.write_with_encoder(PngEncoder::new(&mut bytes))
        .context("cannot encode the picture")?;
    crate::atomic::write(path, &bytes)
}
