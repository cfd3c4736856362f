//! Simulation settings, their defaults (the reference model's) and their
//! validation.
//!
//! Every struct deserialises with `#[serde(default)]`, so a TOML or JSON
//! file only names what it changes. [`SimConfig::validate`] runs before a
//! simulation is built and names the first offending value.
//!
//! Room 3 of the simulator (`lib.rs`): the settings every stage reads, below them all.

pub mod actuation;
pub mod disc_sensors;
pub mod robot_shape;
pub mod validate;

use crate::base::ranges;
use crate::base::vec2::Vec2;
use crate::config::actuation::ActuationNoise;
use crate::config::disc_sensors::DiscSensorConfig;
use crate::config::robot_shape::RobotShape;
use crate::config::validate::{check, positive, ConfigError};
use crate::fields::{FieldFrame, FieldLayout, FieldSampling};
use serde::{Deserialize, Serialize};

/// How contact candidates and sensor neighbours are found. The choice
/// changes speed only: both resolve contacts in the same canonical order
/// and give bit-identical trajectories.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum BroadPhase {
    /// A uniform spatial grid: a step costs O(bodies).
    #[default]
    Grid,
    /// Every pair of bodies, like the original simulator: O(bodies^2).
    Naive,
}

/// The arena and what is in it. Lengths are in units: a tenth of the
/// robot's radius in every built-in arena (so the thesis' constants keep
/// their meaning relative to the robot).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct WorldConfig {
    /// Width of the rectangular arena (x from 0), units.
    pub arena_width: f64,
    /// Height of the arena (y from 0, downwards on screen), units.
    pub arena_height: f64,
    /// Millimetres per unit on the floor (for the robot's physical parts
    /// and the display; the physics does not use it).
    pub unit_mm: f64,
    /// Number of robots (bodies `0 .. robots`).
    pub robots: usize,
    /// How many of the robots are innies (the first ones); the rest are outies.
    pub innies: usize,
    /// Number of pucks (bodies `robots .. robots + pucks`).
    pub pucks: usize,
    /// Robot radius, units: the disc's, or the round back of a wedge.
    pub robot_radius: f64,
    /// The robots' outline ([`RobotShape`]): the disc by default.
    pub robot_shape: RobotShape,
    /// Puck radius, units.
    pub puck_radius: f64,
    /// Puck mass; `None` for the reference model's 10 x radius (the same
    /// rule as robots').
    pub puck_mass: Option<f64>,
    /// Robots' constant forward speed, units per step.
    pub forward_speed: f64,
    /// Contact and neighbour search.
    pub broad_phase: BroadPhase,
    /// Where the field's grid lies in the arena; `None` for the whole arena.
    pub field_frame: Option<FieldFrame>,
    /// How positions read the field.
    pub field_sampling: FieldSampling,
    /// How the robots really move (none: exactly as commanded).
    pub actuation: ActuationNoise,
}

impl Default for WorldConfig {
    /// The reference model's: an 800 x 800 arena (robots of 50 mm radius,
    /// so 5 mm per unit), 8 outies, 250 pucks, radius 10, speed 2, the
    /// field stretched over the arena and read at the nearest cell.
    fn default() -> WorldConfig {
        WorldConfig {
            arena_width: 800.0,
            arena_height: 800.0,
            unit_mm: 5.0,
            robots: 8,
            innies: 0,
            pucks: 250,
            robot_radius: 10.0,
            robot_shape: RobotShape::Disc,
            puck_radius: 10.0,
            puck_mass: None,
            forward_speed: 2.0,
            broad_phase: BroadPhase::Grid,
            field_frame: None,
            field_sampling: FieldSampling::Nearest,
            actuation: ActuationNoise::NONE,
        }
    }
}

impl WorldConfig {
    /// Total number of bodies.
    pub fn bodies(&self) -> usize {
        self.robots + self.pucks
    }

    /// The larger of the robots' and the pucks' bounding radii.
    pub(crate) fn max_radius(&self) -> f64 {
        self.robot_body_radius().max(self.puck_radius)
    }

    /// A robot body's radius: its outline's bounding radius (the disc's
    /// radius, or a wedge's tip distance), which the neighbour search and
    /// the cheap culls use.
    pub fn robot_body_radius(&self) -> f64 {
        self.robot_shape.bounding_radius(self.robot_radius)
    }

    /// The arena's width and height.
    pub fn arena(&self) -> Vec2 {
        Vec2::new(self.arena_width, self.arena_height)
    }

    /// Where the field lies and how it is read.
    pub fn field_layout(&self) -> FieldLayout {
        let frame = self
            .field_frame
            .unwrap_or(FieldFrame::whole(self.arena_width, self.arena_height));
        FieldLayout {
            frame,
            sampling: self.field_sampling,
        }
    }
}

/// How the arena's border keeps the bodies in.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Walls {
    /// Bodies that cross the border are put back inside it, with no contact
    /// and no impulse: the thesis author's program (its worlds of the
    /// thesis' experiments have no wall bodies, only the world's bounds),
    /// and so the thesis' square.
    #[default]
    Clamp,
    /// Four wall segments of [`PhysicsConfig::wall_radius`]: a body that
    /// overlaps one is pushed out and bounces off it (an elastic contact,
    /// as the reference model's text describes walls), then is clamped: a
    /// screen arena's bezel.
    Segments,
}

impl Walls {
    /// The choices by name.
    pub const NAMES: &'static str = "clamp, segments";
}

impl std::str::FromStr for Walls {
    type Err = String;

    fn from_str(s: &str) -> Result<Walls, String> {
        match s {
            "clamp" => Ok(Walls::Clamp),
            "segments" => Ok(Walls::Segments),
            _ => Err(format!("unknown walls {s:?}: expected {}", Walls::NAMES)),
        }
    }
}

impl std::fmt::Display for Walls {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Walls::Clamp => "clamp",
            Walls::Segments => "segments",
        })
    }
}

/// The contact model's constants.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct PhysicsConfig {
    /// Velocity lost per step as a fraction of velocity (acceleration = -k v).
    pub deceleration: f64,
    /// Speeds below this are set to zero: the body comes to rest.
    pub stop_speed: f64,
    /// Overlaps up to this depth are not contacts.
    pub overlap_threshold: f64,
    /// Half-thickness of the four wall segments on the arena border.
    pub wall_radius: f64,
    /// How the border keeps bodies in.
    pub walls: Walls,
}

impl Default for PhysicsConfig {
    /// The reference model: 0.4, 0.001, 0.1; a clamping border (wall
    /// segments, where chosen, of zero thickness).
    fn default() -> PhysicsConfig {
        PhysicsConfig {
            deceleration: 0.4,
            stop_speed: 0.001,
            overlap_threshold: 0.1,
            wall_radius: 0.0,
            walls: Walls::Clamp,
        }
    }
}

/// The field thresholds of the target shape; the orbital construction
/// controller uses the same value per robot kind.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct Thresholds {
    /// T_o: pucks below it are too far out; outies orbit at it.
    pub outie: f64,
    /// T_i: pucks above it are too far in; innies orbit at it.
    pub innie: f64,
}

impl Default for Thresholds {
    /// The annulus: 0.6 and 0.8.
    fn default() -> Thresholds {
        Thresholds {
            outie: 0.6,
            innie: 0.8,
        }
    }
}

impl Thresholds {
    /// The letter experiments' thresholds: both 1.0.
    pub(crate) const LETTERS: Thresholds = Thresholds {
        outie: 1.0,
        innie: 1.0,
    };
}

/// What a formation check compares with the success threshold.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum SuccessSignal {
    /// Eval (the default; the thesis author's loop tests Eval whatever the reward).
    #[default]
    Eval,
    /// Eval' as printed in the thesis' chapter 6 (`eval::EvalPrime::AsWritten`, phi and nu below).
    EvalPrime,
    /// Eval' growing with the robots' spread (`eval::EvalPrime::Spread`).
    EvalPrimeSpread,
}

/// Episodes: formation checks, the stuck limit, and Eval' weights.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct EpisodeConfig {
    /// A formation succeeds when the success signal exceeds this at a check.
    pub success_eval: f64,
    /// Steps between formation checks.
    pub check_interval: u64,
    /// An episode without success after this many steps is stuck and reset.
    pub stuck_limit: u64,
    /// Eval' weight phi of Eval (phi + nu = 1).
    pub phi: f64,
    /// Eval' weight nu of the robot term.
    pub nu: f64,
    /// Test, at each check, the signal measured at the previous check (at
    /// the episode's start for the first) instead of the current one: the
    /// thesis author's loop measured Eval, ran `check_interval` steps, then
    /// tested that value. `false` (the default) tests the current world.
    pub stale_eval: bool,
    /// What the checks test.
    pub success_signal: SuccessSignal,
}

impl Default for EpisodeConfig {
    /// Eval above 0.94 checked every 100 steps on the current world, stuck
    /// after 150,000 (annulus), phi 0.6, nu 0.4.
    fn default() -> EpisodeConfig {
        EpisodeConfig {
            success_eval: 0.94,
            check_interval: 100,
            stuck_limit: 150_000,
            phi: 0.6,
            nu: 0.4,
            stale_eval: false,
            success_signal: SuccessSignal::Eval,
        }
    }
}

/// Everything a simulation needs besides its scalar field.
#[derive(Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SimConfig {
    /// Arena and bodies.
    pub world: WorldConfig,
    /// Contact model.
    pub physics: PhysicsConfig,
    /// Sensor geometry.
    pub sensors: DiscSensorConfig,
    /// Target-shape thresholds.
    pub thresholds: Thresholds,
    /// Episodes and evaluation.
    pub episode: EpisodeConfig,
}

/// Densest packing of equal circles in the plane, pi / (2 sqrt 3).
const PACKING_DENSITY: f64 = 0.9069;

impl SimConfig {
    /// Checks every setting against its plausible range
    /// ([`crate::base::ranges`]) and the rules between settings; the
    /// error names the first bad one and its value.
    pub fn validate(&self) -> Result<(), ConfigError> {
        let w = &self.world;
        ranges::ROBOTS.check_count("world.robots", w.robots as u64)?;
        ranges::PUCKS.check_count("world.pucks", w.pucks as u64)?;
        check(
            "world.innies",
            w.innies as f64,
            w.innies <= w.robots,
            "cannot exceed world.robots",
        )?;
        positive("world.arena_width", w.arena_width)?;
        positive("world.arena_height", w.arena_height)?;
        ranges::ROBOT_RADIUS_UNITS.check(w.robot_radius)?;
        let r = w.robot_radius;
        ranges::ARENA_IN_ROBOT_RADII
            .check_as("world.arena_width / world.robot_radius", w.arena_width / r)?;
        ranges::ARENA_IN_ROBOT_RADII.check_as(
            "world.arena_height / world.robot_radius",
            w.arena_height / r,
        )?;
        ranges::UNIT_MM.check(w.unit_mm)?;
        w.robot_shape.validate(w.robot_radius)?;
        positive("world.puck_radius", w.puck_radius)?;
        ranges::PUCK_OVER_ROBOT_RADIUS.check(w.puck_radius / r)?;
        if let Some(mass) = w.puck_mass {
            positive("world.puck_mass", mass)?;
        }
        ranges::FORWARD_SPEED_RADII.check(w.forward_speed / r)?;
        let short_side = w.arena_width.min(w.arena_height);
        check(
            "world.puck_radius",
            w.puck_radius,
            8.0 * w.puck_radius < short_side,
            "pucks start at least 4 radii from the walls, so 8 x radius must be less than the arena's shorter side",
        )?;
        check(
            "world.robot_radius",
            w.robot_radius,
            2.0 * w.robot_body_radius() < short_side,
            "a robot must fit in the arena",
        )?;
        if let Some(f) = &w.field_frame {
            positive("world.field_frame.width", f.width)?;
            positive("world.field_frame.height", f.height)?;
            check("world.field_frame.x", f.x, true, "must be a finite number")?;
            check("world.field_frame.y", f.y, true, "must be a finite number")?;
        }
        w.actuation.validate()?;
        let area = std::f64::consts::PI
            * (w.robots as f64 * w.robot_radius * w.robot_radius
                + w.pucks as f64 * w.puck_radius * w.puck_radius);
        let capacity = PACKING_DENSITY * w.arena_width * w.arena_height;
        if area > capacity {
            return Err(ConfigError::TooManyBodies {
                bodies: w.bodies(),
                area,
                capacity,
            });
        }

        let p = &self.physics;
        ranges::DECELERATION.check(p.deceleration)?;
        for (key, value) in [
            ("physics.stop_speed", p.stop_speed),
            ("physics.overlap_threshold", p.overlap_threshold),
            ("physics.wall_radius", p.wall_radius),
        ] {
            ranges::PHYSICS_LENGTH.check_as(key, value)?;
        }

        self.sensors.validate()?;

        let t = &self.thresholds;
        ranges::FRACTION.check_as("thresholds.outie", t.outie)?;
        ranges::FRACTION.check_as("thresholds.innie", t.innie)?;
        check(
            "thresholds.innie",
            t.innie,
            t.innie >= t.outie,
            "must not be below thresholds.outie",
        )?;

        let e = &self.episode;
        ranges::FRACTION.check_as("episode.success_eval", e.success_eval)?;
        ranges::CHECK_INTERVAL.check_count("episode.check_interval", e.check_interval)?;
        ranges::STUCK_LIMIT.check_count("episode.stuck_limit", e.stuck_limit)?;
        ranges::FRACTION.check_as("episode.phi", e.phi)?;
        ranges::FRACTION.check_as("episode.nu", e.nu)?;
        check(
            "episode.nu",
            e.nu,
            (e.phi + e.nu - 1.0).abs() < 1e-9,
            "episode.phi + episode.nu must be 1",
        )?;
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn defaults_are_valid() {
        assert_eq!(SimConfig::default().validate(), Ok(()));
    }

    #[test]
    fn errors_name_the_offending_value() {
        let mut c = SimConfig::default();
        c.world.robot_radius = -2.0;
        assert!(c
            .validate()
            .unwrap_err()
            .to_string()
            .starts_with("world.robot_radius = -2: outside its plausible range [0.1, 1000] units"));

        let mut c = SimConfig::default();
        c.world.robots = 0;
        assert!(c
            .validate()
            .unwrap_err()
            .to_string()
            .starts_with("world.robots = 0"));

        let mut c = SimConfig::default();
        c.thresholds.outie = 1.5;
        assert!(c
            .validate()
            .unwrap_err()
            .to_string()
            .starts_with("thresholds.outie = 1.5: outside its plausible range [0, 1]"));

        let mut c = SimConfig::default();
        c.world.pucks = 10_000;
        assert!(matches!(
            c.validate(),
            Err(ConfigError::TooManyBodies { bodies: 10_008, .. })
        ));

        let mut c = SimConfig::default();
        c.world.arena_width = f64::NAN;
        assert!(c
            .validate()
            .unwrap_err()
            .to_string()
            .starts_with("world.arena_width = NaN"));

        let mut c = SimConfig::default();
        c.world.arena_height = 70.0;
        let e = c.validate().unwrap_err().to_string();
        assert!(
            e.starts_with("world.puck_radius = 10") && e.contains("shorter side"),
            "{e}"
        );
    }
}
