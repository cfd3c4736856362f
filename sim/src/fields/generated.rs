//! Shapes generated from a seed, to learn and to check one policy over
//! shapes in general rather than a list: `gen:FAMILY:SEED` wherever a field
//! is named (`gen:letter:7`, `gen:ring:0`).
//!
//! Each shape is drawn as the built-in letters are ([`crate::fields::raster`]):
//! a 600 x 600 image, the shape 1.0, every other pixel falling off linearly
//! to 0 at 340 px from it. A seed gives, through its own generator, the
//! family's parameters, then a stroke width of 24 to 48 px, a turn by any
//! angle, and the shape centred with its longer side at most 420 px.
//!
//! The families ([`Family`]):
//! - `letter`: a capital A to Z of a stroke font of our own in one of three
//!   styles (plain, with serifs at the ends of upright strokes, slanted),
//!   200 to 300 px high, 0.6 to 1.0 times as wide;
//! - `strokes`: two or three straight strokes of 120 to 240 px, joined end
//!   to end at 40 to 140 degrees or, one time in two, the third from the
//!   first's middle;
//! - `hook`: a straight stroke of 160 to 260 px ending in a curl of 150 to
//!   230 degrees around a radius of 45 to 80 px;
//! - `curve`: an open cubic Bezier curve 220 to 300 px from end to end;
//! - `outline`: the outline of a polygon of 3 to 6 corners, 100 to 160 px
//!   from its centre, each corner's distance varied by up to 15 %;
//! - `polygon`: such a polygon filled, 90 to 140 px from its centre;
//! - `ring`: an ellipse's outline, 90 to 150 px across its half-axes;
//! - `arc`: 90 to 300 degrees of such an ellipse.
//!
//! The held-out split ([`Family::HELD_OUT`]): `hook` and `outline` are kept
//! from every search and training run that learns over the distribution,
//! and reported apart.

use crate::base::rng::SimRng;
use crate::fields::raster::{Drawing, Point};
use crate::fields::ScalarField;
use rand::{RngExt, SeedableRng};
use std::f64::consts::TAU;
use std::fmt;
use std::str::FromStr;

/// Side of a generated image, pixels (the thesis' images').
const SIZE: usize = 600;
/// Distance from the shape at which the value reaches 0, pixels (the
/// thesis' images').
const FALLOFF: f64 = 340.0;
/// The longest side a shape's bounding box may have, pixels.
const LONGEST: f64 = 420.0;

/// A family of generated shapes (see the module docs).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Family {
    /// A capital letter of a stroke font.
    Letter,
    /// Two or three straight strokes.
    Strokes,
    /// A straight stroke ending in a curl.
    Hook,
    /// An open curve.
    Curve,
    /// A polygon's outline.
    Outline,
    /// A filled polygon.
    Polygon,
    /// An ellipse's outline.
    Ring,
    /// Part of an ellipse's outline.
    Arc,
}

impl Family {
    /// Every family.
    pub const ALL: [Family; 8] = [
        Family::Letter,
        Family::Strokes,
        Family::Hook,
        Family::Curve,
        Family::Outline,
        Family::Polygon,
        Family::Ring,
        Family::Arc,
    ];

    /// The families no search or training over the distribution scores on.
    pub const HELD_OUT: [Family; 2] = [Family::Hook, Family::Outline];

    /// The family's name in `gen:FAMILY:SEED`.
    pub fn name(self) -> &'static str {
        match self {
            Family::Letter => "letter",
            Family::Strokes => "strokes",
            Family::Hook => "hook",
            Family::Curve => "curve",
            Family::Outline => "outline",
            Family::Polygon => "polygon",
            Family::Ring => "ring",
            Family::Arc => "arc",
        }
    }

    /// Whether the family is held out of learning.
    pub fn held_out(self) -> bool {
        Family::HELD_OUT.contains(&self)
    }

    /// A number of the family's own, mixed into its shapes' seeds so that
    /// two families' shapes of one seed draw apart.
    fn tag(self) -> u64 {
        self as u64 + 1
    }
}

impl fmt::Display for Family {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// A generated shape's name that does not parse, and why.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct UnknownShape(String);

impl fmt::Display for UnknownShape {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let families: Vec<&str> = Family::ALL.iter().map(|f| f.name()).collect();
        write!(
            f,
            "{:?} is not a generated shape: expected gen:FAMILY:SEED, FAMILY one of {} and SEED a \
             whole number",
            self.0,
            families.join(", ")
        )
    }
}

impl std::error::Error for UnknownShape {}

/// One generated shape: a family and a seed (`FAMILY:SEED`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct GeneratedShape {
    /// The family.
    pub family: Family,
    /// The seed of every choice drawing it.
    pub seed: u64,
}

impl FromStr for GeneratedShape {
    type Err = UnknownShape;

    /// `FAMILY:SEED`.
    fn from_str(s: &str) -> Result<GeneratedShape, UnknownShape> {
        let unknown = || UnknownShape(format!("gen:{s}"));
        let (family, seed) = s.split_once(':').ok_or_else(unknown)?;
        let family = Family::ALL
            .into_iter()
            .find(|f| f.name() == family)
            .ok_or_else(unknown)?;
        let seed = seed.parse().map_err(|_| unknown())?;
        Ok(GeneratedShape { family, seed })
    }
}

impl fmt::Display for GeneratedShape {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}:{}", self.family, self.seed)
    }
}

impl GeneratedShape {
    /// The first `count` shapes of every family in `families`, by seed from
    /// `first`, family after family.
    pub fn each_of(families: &[Family], first: u64, count: u64) -> Vec<GeneratedShape> {
        families
            .iter()
            .flat_map(|&family| {
                (first..first + count).map(move |seed| GeneratedShape { family, seed })
            })
            .collect()
    }

    /// The shape's field.
    pub fn field(&self) -> ScalarField {
        self.drawing().field(SIZE, FALLOFF)
    }

    /// The shape, placed in the image.
    fn drawing(&self) -> Drawing {
        let mut rng = SimRng::seed_from_u64(self.seed ^ self.family.tag().rotate_right(8));
        let sketch = match self.family {
            Family::Letter => letter(&mut rng),
            Family::Strokes => strokes(&mut rng),
            Family::Hook => hook(&mut rng),
            Family::Curve => curve(&mut rng),
            Family::Outline => Sketch::lines(vec![closed(polygon_corners(&mut rng, 100.0..160.0))]),
            Family::Polygon => Sketch {
                lines: Vec::new(),
                filled: vec![polygon_corners(&mut rng, 90.0..140.0)],
            },
            Family::Ring => Sketch::lines(vec![ellipse(&mut rng, 360.0)]),
            Family::Arc => {
                let sweep = rng.random_range(90.0..300.0);
                Sketch::lines(vec![ellipse(&mut rng, sweep)])
            }
        };
        let width = rng.random_range(24.0..48.0);
        let turn = rng.random_range(0.0..TAU);
        sketch.placed(width, turn)
    }
}

/// A shape before it is placed: polylines to stroke and polygons to fill,
/// in pixels around the origin.
struct Sketch {
    lines: Vec<Vec<Point>>,
    filled: Vec<Vec<Point>>,
}

impl Sketch {
    /// Only polylines.
    fn lines(lines: Vec<Vec<Point>>) -> Sketch {
        Sketch {
            lines,
            filled: Vec::new(),
        }
    }

    /// Every point of the sketch.
    fn points(&self) -> impl Iterator<Item = &Point> {
        self.lines.iter().chain(&self.filled).flatten()
    }

    /// The sketch with every point moved by `f`.
    fn map(&self, f: impl Fn(Point) -> Point) -> Sketch {
        let all = |shapes: &[Vec<Point>]| -> Vec<Vec<Point>> {
            shapes
                .iter()
                .map(|s| s.iter().map(|&p| f(p)).collect())
                .collect()
        };
        Sketch {
            lines: all(&self.lines),
            filled: all(&self.filled),
        }
    }

    /// Stroked `width` wide, turned by `turn` radians, shrunk to at most
    /// [`LONGEST`] px, centred in the image.
    fn placed(self, width: f64, turn: f64) -> Drawing {
        let (sin, cos) = turn.sin_cos();
        let turned = self.map(|(x, y)| (x * cos - y * sin, x * sin + y * cos));
        let (mut low, mut high) = ((f64::MAX, f64::MAX), (f64::MIN, f64::MIN));
        for &(x, y) in turned.points() {
            low = (low.0.min(x), low.1.min(y));
            high = (high.0.max(x), high.1.max(y));
        }
        let longest = (high.0 - low.0).max(high.1 - low.1) + width;
        let scale = (LONGEST / longest).min(1.0);
        let centre = ((low.0 + high.0) / 2.0, (low.1 + high.1) / 2.0);
        let middle = SIZE as f64 / 2.0;
        let placed = turned.map(|(x, y)| {
            (
                middle + (x - centre.0) * scale,
                middle + (y - centre.1) * scale,
            )
        });
        Drawing {
            strokes: placed
                .lines
                .iter()
                .flat_map(|line| line.windows(2).map(|w| ([w[0], w[1]], width * scale)))
                .collect(),
            polygons: placed.filled,
        }
    }
}

/// The polyline through `corners` and back to the first.
fn closed(mut corners: Vec<Point>) -> Vec<Point> {
    corners.push(corners[0]);
    corners
}

/// `n + 1` points on the ellipse of half-axes `rx`, `ry` around `centre`,
/// from `from` to `to` degrees (0 to the right, 90 down).
fn arc(centre: Point, rx: f64, ry: f64, from: f64, to: f64, n: usize) -> Vec<Point> {
    (0..=n)
        .map(|k| {
            let a = (from + (to - from) * k as f64 / n as f64).to_radians();
            (centre.0 + rx * a.cos(), centre.1 + ry * a.sin())
        })
        .collect()
}

/// `sweep` degrees of an ellipse 90 to 150 px across its half-axes.
fn ellipse(rng: &mut SimRng, sweep: f64) -> Vec<Point> {
    let rx = rng.random_range(90.0..150.0);
    let ry = rx * rng.random_range(0.7..1.0);
    arc(
        (0.0, 0.0),
        rx,
        ry,
        0.0,
        sweep,
        (sweep / 6.0).ceil() as usize,
    )
}

/// The corners of a polygon of 3 to 6 corners around the origin, each
/// `radius` px from it, varied by up to 15 %.
fn polygon_corners(rng: &mut SimRng, radius: std::ops::Range<f64>) -> Vec<Point> {
    let corners = rng.random_range(3..=6usize);
    let radius = rng.random_range(radius);
    (0..corners)
        .map(|k| {
            let a = TAU * k as f64 / corners as f64;
            let r = radius * rng.random_range(0.85..1.15);
            (r * a.cos(), r * a.sin())
        })
        .collect()
}

/// Two or three straight strokes.
fn strokes(rng: &mut SimRng) -> Sketch {
    let count = rng.random_range(2..=3usize);
    let mut heading: f64 = 0.0;
    let mut points = vec![(0.0, 0.0)];
    let branch = count == 3 && rng.random_bool(0.5);
    let mut lines = Vec::new();
    for k in 0..count {
        let length = rng.random_range(120.0..240.0);
        if k == 2 && branch {
            let first = (
                (points[0].0 + points[1].0) / 2.0,
                (points[0].1 + points[1].1) / 2.0,
            );
            let side = if rng.random_bool(0.5) { 1.0 } else { -1.0 };
            let a = rng.random_range(40.0f64..140.0).to_radians() * side;
            lines.push(vec![
                first,
                (first.0 + length * a.cos(), first.1 + length * a.sin()),
            ]);
            continue;
        }
        if k > 0 {
            let side = if rng.random_bool(0.5) { 1.0 } else { -1.0 };
            heading += (180.0 - rng.random_range(40.0f64..140.0)).to_radians() * side;
        }
        let &(x, y) = points.last().expect("a first point");
        points.push((x + length * heading.cos(), y + length * heading.sin()));
    }
    lines.insert(0, points);
    Sketch::lines(lines)
}

/// A straight stroke ending in a curl.
fn hook(rng: &mut SimRng) -> Sketch {
    let shaft = rng.random_range(160.0..260.0);
    let radius = rng.random_range(45.0..80.0);
    let curl = rng.random_range(150.0..230.0);
    let mut line = vec![(0.0, -shaft)];
    line.extend(arc((-radius, 0.0), radius, radius, 0.0, curl, 24));
    Sketch::lines(vec![line])
}

/// An open cubic Bezier curve.
fn curve(rng: &mut SimRng) -> Sketch {
    let half = rng.random_range(110.0..150.0);
    let mut control = || (rng.random_range(-half..half), rng.random_range(-half..half));
    let (p0, p3) = ((-half, 0.0), (half, 0.0));
    let (p1, p2) = (control(), control());
    let line = (0..=40)
        .map(|k| {
            let t = k as f64 / 40.0;
            let u = 1.0 - t;
            let (a, b, c, d) = (u * u * u, 3.0 * u * u * t, 3.0 * u * t * t, t * t * t);
            (
                a * p0.0 + b * p1.0 + c * p2.0 + d * p3.0,
                a * p0.1 + b * p1.1 + c * p2.1 + d * p3.1,
            )
        })
        .collect();
    Sketch::lines(vec![line])
}

/// A letter's style.
#[derive(Clone, Copy, PartialEq)]
enum Style {
    Plain,
    Serif,
    Slanted,
}

/// A capital letter of the stroke font.
fn letter(rng: &mut SimRng) -> Sketch {
    let glyph = (b'A' + rng.random_range(0..26u8)) as char;
    let style = [Style::Plain, Style::Serif, Style::Slanted][rng.random_range(0..3usize)];
    let height = rng.random_range(200.0..300.0);
    let width = height * rng.random_range(0.6..1.0);
    let mut lines = glyph_lines(glyph);
    if style == Style::Serif {
        let serifs: Vec<Vec<Point>> = lines
            .iter()
            .flat_map(|line| {
                [
                    (line[0], line[1]),
                    (line[line.len() - 1], line[line.len() - 2]),
                ]
            })
            .filter(|(end, next)| (next.1 - end.1).abs() > 2.0 * (next.0 - end.0).abs())
            .map(|(end, _)| vec![(end.0 - 0.15, end.1), (end.0 + 0.15, end.1)])
            .collect();
        lines.extend(serifs);
    }
    let slant = if style == Style::Slanted { 0.25 } else { 0.0 };
    let lines = lines
        .into_iter()
        .map(|line| {
            line.into_iter()
                .map(|(x, y)| ((x - 0.5 + slant * (0.5 - y)) * width, (y - 0.5) * height))
                .collect()
        })
        .collect();
    Sketch::lines(lines)
}

/// The stroke font: each capital's polylines in the unit box, y down.
fn glyph_lines(glyph: char) -> Vec<Vec<Point>> {
    let bowl = |top: f64, bottom: f64, reach: f64| {
        let r = (bottom - top) / 2.0;
        let mut line = vec![(0.0, top), (reach - r, top)];
        line.extend(arc((reach - r, top + r), r, r, -90.0, 90.0, 12));
        line.push((0.0, bottom));
        line
    };
    let o = || arc((0.5, 0.5), 0.5, 0.5, 0.0, 360.0, 36);
    match glyph {
        'A' => vec![
            vec![(0.0, 1.0), (0.5, 0.0), (1.0, 1.0)],
            vec![(0.22, 0.6), (0.78, 0.6)],
        ],
        'B' => vec![
            vec![(0.0, 0.0), (0.0, 1.0)],
            bowl(0.0, 0.48, 0.85),
            bowl(0.48, 1.0, 1.0),
        ],
        'C' => vec![arc((0.5, 0.5), 0.5, 0.5, 45.0, 315.0, 30)],
        'D' => vec![vec![(0.0, 0.0), (0.0, 1.0)], bowl(0.0, 1.0, 1.0)],
        'E' => vec![
            vec![(1.0, 0.0), (0.0, 0.0), (0.0, 1.0), (1.0, 1.0)],
            vec![(0.0, 0.5), (0.75, 0.5)],
        ],
        'F' => vec![
            vec![(1.0, 0.0), (0.0, 0.0), (0.0, 1.0)],
            vec![(0.0, 0.5), (0.75, 0.5)],
        ],
        'G' => vec![
            arc((0.5, 0.5), 0.5, 0.5, -45.0 + 360.0, 45.0, 30),
            vec![(0.55, 0.55), (1.0, 0.55), (1.0, 0.85)],
        ],
        'H' => vec![
            vec![(0.0, 0.0), (0.0, 1.0)],
            vec![(1.0, 0.0), (1.0, 1.0)],
            vec![(0.0, 0.5), (1.0, 0.5)],
        ],
        'I' => vec![vec![(0.5, 0.0), (0.5, 1.0)]],
        'J' => {
            let mut line = vec![(0.75, 0.0), (0.75, 0.7)];
            line.extend(arc((0.45, 0.7), 0.3, 0.3, 0.0, 180.0, 12));
            vec![line]
        }
        'K' => vec![
            vec![(0.0, 0.0), (0.0, 1.0)],
            vec![(1.0, 0.0), (0.0, 0.6)],
            vec![(0.3, 0.42), (1.0, 1.0)],
        ],
        'L' => vec![vec![(0.0, 0.0), (0.0, 1.0), (1.0, 1.0)]],
        'M' => vec![vec![
            (0.0, 1.0),
            (0.0, 0.0),
            (0.5, 0.6),
            (1.0, 0.0),
            (1.0, 1.0),
        ]],
        'N' => vec![vec![(0.0, 1.0), (0.0, 0.0), (1.0, 1.0), (1.0, 0.0)]],
        'O' => vec![o()],
        'P' => vec![vec![(0.0, 1.0), (0.0, 0.0)], bowl(0.0, 0.55, 1.0)],
        'Q' => vec![o(), vec![(0.6, 0.7), (1.0, 1.05)]],
        'R' => vec![
            vec![(0.0, 1.0), (0.0, 0.0)],
            bowl(0.0, 0.55, 1.0),
            vec![(0.4, 0.55), (1.0, 1.0)],
        ],
        'S' => {
            let mut line = arc((0.5, 0.25), 0.45, 0.25, 340.0, 90.0, 14);
            line.extend(arc((0.5, 0.75), 0.45, 0.25, 270.0, 520.0, 14));
            vec![line]
        }
        'T' => vec![vec![(0.0, 0.0), (1.0, 0.0)], vec![(0.5, 0.0), (0.5, 1.0)]],
        'U' => {
            let mut line = vec![(0.0, 0.0), (0.0, 0.5)];
            line.extend(arc((0.5, 0.5), 0.5, 0.5, 180.0, 0.0, 18));
            line.push((1.0, 0.0));
            vec![line]
        }
        'V' => vec![vec![(0.0, 0.0), (0.5, 1.0), (1.0, 0.0)]],
        'W' => vec![vec![
            (0.0, 0.0),
            (0.25, 1.0),
            (0.5, 0.4),
            (0.75, 1.0),
            (1.0, 0.0),
        ]],
        'X' => vec![vec![(0.0, 0.0), (1.0, 1.0)], vec![(1.0, 0.0), (0.0, 1.0)]],
        'Y' => vec![
            vec![(0.0, 0.0), (0.5, 0.5), (1.0, 0.0)],
            vec![(0.5, 0.5), (0.5, 1.0)],
        ],
        // Z
        _ => vec![vec![(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (1.0, 1.0)]],
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_shape_is_the_same_for_the_same_seed_and_differs_for_another() {
        for family in Family::ALL {
            let one = GeneratedShape { family, seed: 3 };
            let other = GeneratedShape { family, seed: 4 };
            assert_eq!(one.field(), one.field(), "{one}");
            assert_ne!(one.field(), other.field(), "{one} and {other}");
        }
    }

    #[test]
    fn every_shape_lies_inside_the_image_with_a_dark_border() {
        for shape in GeneratedShape::each_of(&Family::ALL, 0, 6) {
            let field = shape.field();
            let n = SIZE as i64;
            let on: usize = (0..n * n)
                .filter(|&k| field.cell(k % n, k / n) == 1.0)
                .count();
            let share = on as f64 / (SIZE * SIZE) as f64;
            assert!(
                (0.005..=0.12).contains(&share),
                "{shape}: the shape covers {share}"
            );
            for k in 0..n {
                for (x, y) in [(k, 0), (k, n - 1), (0, k), (n - 1, k)] {
                    assert!(
                        field.cell(x, y) < 1.0,
                        "{shape} touches the border at ({x}, {y})"
                    );
                }
            }
        }
    }

    #[test]
    fn names_parse_back_to_their_shape_and_bad_names_say_what_is_expected() {
        for shape in GeneratedShape::each_of(&Family::ALL, 9, 1) {
            assert_eq!(shape.to_string().parse::<GeneratedShape>(), Ok(shape));
        }
        for bad in ["ring", "ring:x", "blob:3", "ring:-1"] {
            let e = bad.parse::<GeneratedShape>().unwrap_err().to_string();
            assert!(
                e.contains("gen:FAMILY:SEED") && e.contains("outline"),
                "{bad}: {e}"
            );
        }
    }

    #[test]
    fn the_stroke_font_has_every_capital() {
        for glyph in 'A'..='Z' {
            let lines = glyph_lines(glyph);
            assert!(
                !lines.is_empty() && lines.iter().all(|l| l.len() >= 2),
                "{glyph}"
            );
            for &(x, y) in lines.iter().flatten() {
                assert!(
                    (-0.01..=1.06).contains(&x) && (-0.01..=1.06).contains(&y),
                    "{glyph}: ({x}, {y})"
                );
            }
        }
        let z = glyph_lines('Z');
        assert_eq!(
            z,
            vec![vec![(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (1.0, 1.0)]]
        );
    }
}
