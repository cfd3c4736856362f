//! Physical arenas: a screen lying flat with the field shown on it, where
//! the field image lies on the screen, and what drives on it.
//!
//! The one definition of the geometry that the simulator, the field export
//! and the display page share. Units: the simulator's unit is a tenth of the
//! robot's radius (so every constant of the reference model keeps its
//! meaning relative to the robot), `unit_mm = robot_radius_mm / 10`
//! millimetres on the floor; the arena is the screen's visible area, walls
//! at its edges (the bezel).
//!
//! Placing a field image on the screen ([`FieldFit`]): `contain` keeps the
//! image's aspect ratio, as large as fits and centred, the rest of the
//! screen black (field 0); `stretch` fills the screen. The annulus is a
//! generated field and is generated for the screen's shape instead
//! (`ArenaSpec::annulus_cells`: circular contours, 0 in the screen's
//! corners), filling it.
//!
//! The screen shows the image scaled smoothly (bilinear), so the robots
//! read the field with [`FieldSampling::Bilinear`] ([`ArenaSpec::field_layout`]);
//! panel pixel `(i, j)` shows the field at its centre
//! (`ArenaSpec::panel_pixel_centre`). Light: the display's light is
//! `pixel ^ display_gamma`; the pixel a field value is shown with is
//! pre-compensated so that the light is `v ^ LIGHT_GAMMA`, the curve the
//! robots' calibration assumes ([`crate::scenario::panel`], `docs/display.md`).

use crate::base::ranges;
use crate::base::vec2::Vec2;
use crate::config::robot_shape::RobotShape;
use crate::config::validate::ConfigError;
use crate::config::{SimConfig, Walls};
use crate::fields::source::{FieldError, FieldSource};
use crate::fields::{FieldFrame, FieldLayout, FieldSampling, ScalarField};
use serde::{Deserialize, Serialize};

/// How a field image lies on the screen.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum FieldFit {
    /// Aspect ratio kept, as large as fits, centred; the rest black.
    #[default]
    Contain,
    /// Stretched over the whole screen.
    Stretch,
}

/// The robots' skirt on a screen, in millimetres: `robot_shape = "disc"` or
/// `robot_shape = { wedge = { tip_mm = 85.0 } }` in an arena file.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase", deny_unknown_fields)]
pub enum SkirtShape {
    /// A round skirt of `robot_radius_mm`.
    Disc,
    /// A round skirt of `robot_radius_mm` with a pointed wedge whose tip is
    /// `tip_mm` ahead of the centre, its faces tangent to the circle
    /// ([`RobotShape::Wedge`]).
    Wedge {
        /// The tip's distance from the robot's centre, mm.
        tip_mm: f64,
    },
}

/// Where the tip of the thesis' wedge is on `tv75`'s robots, mm ahead of the robot's centre
/// (`docs/robot-sensors.md`, "The skirt's outline"): as far as the skirt
/// can reach and stay out of the Pixy's image. The camera's lowest ray
/// (lens 80 mm high, 15 mm ahead, tilted 20 degrees, 47 degrees of view:
/// 43.5 degrees down) passes the top of a 10 mm skirt (two layers of 5 mm
/// foam board) 88.8 mm ahead of the centre; 85 mm leaves a 3.8 mm margin
/// for mounting the camera a little lower or tilting it a little more.
pub const TV75_TIP_MM: f64 = 85.0;

/// The height of the skirt's top above the floor, mm: two layers of 5 mm
/// foam board (an assumption; the thesis does not give it), for
/// [`TV75_TIP_MM`]'s margin.
pub const SKIRT_HEIGHT_MM: f64 = 10.0;

impl SkirtShape {
    /// The thesis' skirt on `tv75`'s robots: the wedge with its tip
    /// [`TV75_TIP_MM`] ahead ([`ArenaSpec::tv75`]'s).
    pub fn thesis_wedge() -> SkirtShape {
        SkirtShape::Wedge {
            tip_mm: TV75_TIP_MM,
        }
    }
}

/// A screen arena and the bodies on it. Every field is optional in a file.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct ArenaSpec {
    /// Name, for messages and provenance.
    pub name: String,
    /// Visible screen width and height, mm.
    pub screen_mm: [f64; 2],
    /// Panel resolution, width and height, pixels.
    pub screen_px: [u32; 2],
    /// How a field image lies on the screen.
    pub fit: FieldFit,
    /// The display's gamma: its light is `pixel ^ display_gamma` of full
    /// white (for measuring it, the display page shows grey patches).
    pub display_gamma: f64,
    /// The share of the panel's brightness unevenness (the robot senses'
    /// `noise.brightness`) the robots see: 1 for a panel as it comes, less
    /// for one whose shown image is divided by its measured gain (a
    /// flat-field correction, `docs/display.md`).
    pub brightness_unevenness: f64,
    /// The share of the robots' motion noise (`--noise`'s wheel speeds,
    /// turning bias, period jitter and drops) they show: 1 for the
    /// firmware's open-loop motor commands, less for robots that hold their
    /// wheel speeds on the encoders (0.5 at `--noise 2` is the default
    /// motion beside twice the senses' noise).
    pub motion_noise: f64,
    /// Robot radius, mm: the Zumo in its skirt (a wedge's round back).
    pub robot_radius_mm: f64,
    /// The skirt's outline.
    pub robot_shape: SkirtShape,
    /// Puck radius, mm.
    pub puck_radius_mm: f64,
    /// A puck's mass over a robot's.
    pub puck_mass_ratio: f64,
    /// Robots on the screen.
    pub robots: usize,
    /// Pucks on the screen.
    pub pucks: usize,
    /// Robots' forward speed, units (tenths of their radius) per step.
    pub forward_speed: f64,
    /// Steps an episode may last without forming the shape (a lab trial's
    /// length: one step is one 20 ms control period).
    pub stuck_limit: u64,
}

impl Default for ArenaSpec {
    /// [`ArenaSpec::tv75`].
    fn default() -> ArenaSpec {
        ArenaSpec::tv75()
    }
}

impl ArenaSpec {
    /// The built-in arenas' names, as messages list them.
    pub const NAMES: &'static str = "tv75";

    /// The thesis' hardware (section 1.4): a 75" LG TV (75UK6190PUB) lying
    /// flat, 1,650 x 928 mm visible, 3840 x 2160 pixels; a Zumo 32U4
    /// (98 x 86 mm) in the thesis' wedge-fronted skirt: a round back of
    /// 65 mm radius, the least circle around the chassis, and a pointed
    /// wedge whose tip is [`TV75_TIP_MM`] ahead of the centre (the round
    /// skirt alone, which tv75 had until 2026-12-04, is
    /// `experiments/arenas/tv75-disc.toml`); 5 robots and 12 pucks as large and heavy as a
    /// robot (as in the thesis, radius and mass equal); the thesis' forward speed of
    /// 2 units (0.2 radii) per step; trials of 15,000 steps (5 minutes);
    /// images kept in their aspect; display gamma 2.2 (a TV's nominal). The
    /// counts, sizes and trial length are ours, from a sweep with the disc
    /// sensors (`docs/robot-sensors.md`, which gives the density beside the
    /// thesis').
    pub fn tv75() -> ArenaSpec {
        ArenaSpec {
            name: "tv75".into(),
            screen_mm: [1650.0, 928.0],
            screen_px: [3840, 2160],
            fit: FieldFit::Contain,
            display_gamma: 2.2,
            brightness_unevenness: 1.0,
            motion_noise: 1.0,
            robot_radius_mm: 65.0,
            robot_shape: SkirtShape::thesis_wedge(),
            puck_radius_mm: 65.0,
            puck_mass_ratio: 1.0,
            robots: 5,
            pucks: 12,
            forward_speed: 2.0,
            stuck_limit: 15_000,
        }
    }

    /// A built-in arena by name, or `None`.
    pub fn by_name(name: &str) -> Option<ArenaSpec> {
        (name == "tv75").then(ArenaSpec::tv75)
    }

    /// Millimetres per simulator unit: a tenth of the robot's radius.
    pub fn unit_mm(&self) -> f64 {
        self.robot_radius_mm / ROBOT_RADIUS_UNITS
    }

    /// The screen's width and height in units.
    pub fn size(&self) -> Vec2 {
        Vec2::new(self.screen_mm[0], self.screen_mm[1]) * (1.0 / self.unit_mm())
    }

    /// Checks every setting against its plausible range
    /// ([`crate::base::ranges`]); the error names the first bad one. Run
    /// before anything of the arena's size is allocated: a screen of
    /// 10 km, or a robot radius given in metres, is refused here.
    pub fn validate(&self) -> Result<(), ConfigError> {
        for (i, mm) in self.screen_mm.iter().enumerate() {
            ranges::SCREEN_MM.check_as(&format!("arena.screen_mm[{i}]"), *mm)?;
        }
        for (i, px) in self.screen_px.iter().enumerate() {
            ranges::SCREEN_PX.check_count(&format!("arena.screen_px[{i}]"), u64::from(*px))?;
        }
        ranges::GAMMA.check(self.display_gamma)?;
        ranges::UNEVENNESS.check(self.brightness_unevenness)?;
        ranges::MOTION_NOISE_SHARE.check(self.motion_noise)?;
        ranges::BODY_RADIUS_MM.check(self.robot_radius_mm)?;
        ranges::BODY_RADIUS_MM.check_as("arena.puck_radius_mm", self.puck_radius_mm)?;
        for (i, mm) in self.screen_mm.iter().enumerate() {
            ranges::ARENA_IN_ROBOT_RADII.check_as(
                &format!("arena.screen_mm[{i}] / arena.robot_radius_mm"),
                mm / self.robot_radius_mm,
            )?;
        }
        if let SkirtShape::Wedge { tip_mm } = self.robot_shape {
            ranges::TIP_RADII.check_as(
                "arena.robot_shape.wedge.tip_mm / arena.robot_radius_mm",
                tip_mm / self.robot_radius_mm,
            )?;
        }
        ranges::PUCK_MASS_RATIO.check(self.puck_mass_ratio)?;
        ranges::ROBOTS.check_count("arena.robots", self.robots as u64)?;
        ranges::PUCKS.check_count("arena.pucks", self.pucks as u64)?;
        ranges::FORWARD_SPEED.check(self.forward_speed)?;
        ranges::STUCK_LIMIT.check_count("arena.stuck_limit", self.stuck_limit)?;
        Ok(())
    }

    /// The skirt in the world's units.
    pub fn robot_shape_units(&self) -> RobotShape {
        match self.robot_shape {
            SkirtShape::Disc => RobotShape::Disc,
            SkirtShape::Wedge { tip_mm } => RobotShape::Wedge {
                tip: tip_mm / self.unit_mm(),
            },
        }
    }

    /// Cells of the annulus generated for this screen: 64 across, as many
    /// down as keep the cells square.
    pub(crate) fn annulus_cells(&self) -> (usize, usize) {
        let rows = (ANNULUS_COLUMNS as f64 * self.screen_mm[1] / self.screen_mm[0])
            .round()
            .max(1.0) as usize;
        (ANNULUS_COLUMNS, rows)
    }

    /// Where a field image of `cells` (width, height) lies on the screen,
    /// in units from the screen's top-left corner.
    pub fn field_frame(&self, cells: (usize, usize)) -> FieldFrame {
        let size = self.size();
        match self.fit {
            FieldFit::Stretch => FieldFrame::whole(size.x, size.y),
            FieldFit::Contain => {
                let scale = (size.x / cells.0 as f64).min(size.y / cells.1 as f64);
                let (width, height) = (cells.0 as f64 * scale, cells.1 as f64 * scale);
                FieldFrame {
                    x: (size.x - width) / 2.0,
                    y: (size.y - height) / 2.0,
                    width,
                    height,
                }
            }
        }
    }

    /// Where `field` lies on this screen and how the robots read it: its
    /// [`ArenaSpec::field_frame`], bilinear (as the screen scales it).
    pub fn field_layout(&self, field: &ScalarField) -> FieldLayout {
        FieldLayout {
            frame: self.field_frame((field.width(), field.height())),
            sampling: FieldSampling::Bilinear,
        }
    }

    /// The position of panel pixel (`i`, `j`)'s centre, in units from the
    /// screen's top-left corner (column `i` from the left, row `j` from the
    /// top): the panel's pixels tile the visible area.
    pub fn panel_pixel_centre(&self, i: u32, j: u32) -> Vec2 {
        let size = self.size();
        Vec2::new(
            (f64::from(i) + 0.5) * size.x / f64::from(self.screen_px[0]),
            (f64::from(j) + 0.5) * size.y / f64::from(self.screen_px[1]),
        )
    }

    /// Builds or loads `source`'s field for this screen: the annulus
    /// generated for the screen's shape, any other field as
    /// [`FieldSource::load`].
    pub fn load_field(&self, source: &FieldSource) -> Result<ScalarField, FieldError> {
        match source {
            FieldSource::Annulus => {
                let (width, height) = self.annulus_cells();
                Ok(ScalarField::annulus_of(width, height))
            }
            _ => source.load(),
        }
    }

    /// Sets the arena, the bodies, the field's placement of `field` and the
    /// trial length in `config` (counts as given here; the caller may
    /// change them after).
    pub fn apply(&self, config: &mut SimConfig, field: &ScalarField) {
        config.episode.stuck_limit = self.stuck_limit;
        // The screen's bezel: robots and pucks bounce off it.
        config.physics.walls = Walls::Segments;
        let world = &mut config.world;
        let size = self.size();
        let unit = self.unit_mm();
        world.arena_width = size.x;
        world.arena_height = size.y;
        world.unit_mm = unit;
        world.robot_radius = ROBOT_RADIUS_UNITS;
        world.robot_shape = self.robot_shape_units();
        world.puck_radius = self.puck_radius_mm / unit;
        world.puck_mass = Some(
            self.puck_mass_ratio * crate::physics::body::Body::MASS_PER_RADIUS * ROBOT_RADIUS_UNITS,
        );
        world.robots = self.robots;
        world.pucks = self.pucks;
        world.forward_speed = self.forward_speed;
        let layout = self.field_layout(field);
        world.field_frame = Some(layout.frame);
        world.field_sampling = layout.sampling;
    }
}

/// A robot's radius in units, in every arena.
pub(crate) const ROBOT_RADIUS_UNITS: f64 = 10.0;

/// Columns of a generated annulus (the reference model's 64).
const ANNULUS_COLUMNS: usize = 64;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_tv_is_about_25_by_14_robot_radii_and_its_annulus_has_square_cells() {
        let tv = ArenaSpec::tv75();
        let size = tv.size();
        assert!(
            (size.x / 10.0 - 25.4).abs() < 0.05 && (size.y / 10.0 - 14.3).abs() < 0.05,
            "{size:?}"
        );
        assert_eq!(tv.annulus_cells(), (64, 36));
        assert_eq!(tv.unit_mm(), 6.5);
        assert!(tv.validate().is_ok());
    }

    #[test]
    fn a_square_image_is_centred_at_full_height_or_stretched() {
        let tv = ArenaSpec::tv75();
        let size = tv.size();
        let f = tv.field_frame((600, 600));
        assert!((f.height - size.y).abs() < 1e-9 && (f.width - size.y).abs() < 1e-9);
        assert!((f.x - (size.x - size.y) / 2.0).abs() < 1e-9 && f.y == 0.0);
        let stretched = ArenaSpec {
            fit: FieldFit::Stretch,
            ..tv
        };
        assert_eq!(
            stretched.field_frame((600, 600)),
            FieldFrame::whole(size.x, size.y)
        );
    }

    #[test]
    fn panel_pixels_tile_the_screen_centre_to_centre() {
        let tv = ArenaSpec::tv75();
        let size = tv.size();
        let pixel = size.x / 3840.0;
        let first = tv.panel_pixel_centre(0, 0);
        assert!(
            (first.x - pixel / 2.0).abs() < 1e-12
                && (first.y - size.y / 2160.0 / 2.0).abs() < 1e-12
        );
        let last = tv.panel_pixel_centre(3839, 2159);
        assert!(
            (size.x - last.x - pixel / 2.0).abs() < 1e-9
                && (size.y - last.y - size.y / 4320.0).abs() < 1e-9
        );
    }

    #[test]
    fn applying_an_arena_sets_a_valid_world_read_bilinear() {
        let tv = ArenaSpec::tv75();
        let mut config = crate::config::SimConfig::default();
        tv.apply(&mut config, &ScalarField::annulus_of(64, 36));
        assert_eq!((config.world.robots, config.world.pucks), (5, 12));
        assert_eq!(config.world.field_sampling, FieldSampling::Bilinear);
        assert_eq!(
            (config.world.puck_radius, config.world.puck_mass),
            (10.0, Some(100.0))
        );
        assert_eq!(config.episode.stuck_limit, 15_000);
        assert_eq!(config.validate(), Ok(()));
        let bad = ArenaSpec {
            robot_radius_mm: -1.0,
            ..ArenaSpec::tv75()
        };
        assert_eq!(
            config.world.field_layout(),
            tv.field_layout(&ScalarField::annulus_of(64, 36))
        );
        assert!(bad
            .validate()
            .unwrap_err()
            .to_string()
            .contains("arena.robot_radius_mm"));
    }
}
