//! Sensor models: what each robot perceives, as a [`SensorReading`].
//!
//! [`SensorModel`] is the interface controllers and the trainer depend on;
//! [`DiscSensors`] is the reference model's: three field sample points, two
//! puck sensors of two discs each, two obstacle discs, all fixed to the
//! robot's centre and heading. Angles are degrees, positive to the robot's
//! right (clockwise on screen, y down); distances and radii are in robot
//! radii. Each right-side disc is mirrored (negated angle) on the left.

use super::body::RobotKind;
use super::config::{check, positive, ConfigError};
use super::field::ScalarField;
use super::vec2::Vec2;
use super::world::{disc_overlaps, World};
use serde::{Deserialize, Serialize};
use shared::SensorReading;

/// Produces every robot's reading from the world and field.
///
/// A model may keep state between steps (`&mut self`), for example sensor
/// noise drawn from its own seeded generator.
pub trait SensorModel {
    /// Fills `out[i]` with robot `i`'s reading; `out` has one entry per robot.
    fn sense(&mut self, world: &World, field: &ScalarField, out: &mut [SensorReading]);

    /// Appends the areas robot `robot` senses, for drawing. The default
    /// draws nothing.
    fn footprints(&self, _world: &World, _robot: usize, _out: &mut Vec<Footprint>) {}
}

/// What a drawn sensor area detects.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum FootprintKind {
    /// A field sample point.
    Field,
    /// A puck-sensor disc.
    Puck,
    /// An obstacle-sensor disc.
    Obstacle,
}

/// A sensed area in arena coordinates.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Footprint {
    /// Centre.
    pub centre: Vec2,
    /// Radius (0 for field sample points).
    pub radius: f64,
    /// What it detects.
    pub kind: FootprintKind,
}

/// A sensing disc on the robot's right; its mirror image is on the left.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SensorDisc {
    /// Direction from the robot's centre, degrees right of the heading.
    pub angle_deg: f64,
    /// Distance of the disc's centre from the robot's centre, robot radii.
    pub distance: f64,
    /// Disc radius, robot radii.
    pub radius: f64,
}

impl SensorDisc {
    const fn new(angle_deg: f64, distance: f64, radius: f64) -> SensorDisc {
        SensorDisc { angle_deg, distance, radius }
    }

    fn validate(&self, name: &str) -> Result<(), ConfigError> {
        check(&format!("{name}.angle_deg"), self.angle_deg, true, "must be a finite number")?;
        check(&format!("{name}.distance"), self.distance, self.distance >= 0.0, "must not be negative")?;
        positive(&format!("{name}.radius"), self.radius)
    }
}

/// Which bodies the obstacle sensors detect.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum ObstacleTargets {
    /// Other robots only (the thesis, sections 5.2 and 6).
    Robots,
    /// Any other circle, pucks included (the original code).
    AnyBody,
}

/// Geometry of the disc sensor model.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct DiscSensorConfig {
    /// Angle of the left and right field points (mid is straight ahead), degrees.
    pub field_angle_deg: f64,
    /// Distance of the three field points, robot radii.
    pub field_distance: f64,
    /// Puck discs of outies (and every non-OC robot), right side.
    pub outie_pucks: Vec<SensorDisc>,
    /// Puck discs of innies, right side.
    pub innie_pucks: Vec<SensorDisc>,
    /// The right obstacle disc.
    pub obstacle: SensorDisc,
    /// What the obstacle discs detect.
    pub obstacle_targets: ObstacleTargets,
}

impl Default for DiscSensorConfig {
    /// The original code: field points at (+-45 deg, 2r); outie puck discs
    /// (+-30, 4r) and (+-60, 7r), innie (+-45, 3r) and (+-70, 6.5r), radius 2r;
    /// obstacle discs (+-45, r) of radius r/4 detecting any body.
    fn default() -> DiscSensorConfig {
        DiscSensorConfig {
            field_angle_deg: 45.0,
            field_distance: 2.0,
            outie_pucks: vec![SensorDisc::new(30.0, 4.0, 2.0), SensorDisc::new(60.0, 7.0, 2.0)],
            innie_pucks: vec![SensorDisc::new(45.0, 3.0, 2.0), SensorDisc::new(70.0, 6.5, 2.0)],
            obstacle: SensorDisc::new(45.0, 1.0, 0.25),
            obstacle_targets: ObstacleTargets::AnyBody,
        }
    }
}

impl DiscSensorConfig {
    /// The thesis' obstacle sensors: the size of a puck sensor (radius 2r),
    /// detecting robots only; everything else as [`Default`].
    pub fn thesis_obstacles() -> DiscSensorConfig {
        DiscSensorConfig {
            obstacle: SensorDisc::new(45.0, 1.0, 2.0),
            obstacle_targets: ObstacleTargets::Robots,
            ..DiscSensorConfig::default()
        }
    }

    /// Checks every angle, distance and radius.
    pub fn validate(&self) -> Result<(), ConfigError> {
        check("sensors.field_angle_deg", self.field_angle_deg, true, "must be a finite number")?;
        check("sensors.field_distance", self.field_distance, self.field_distance >= 0.0, "must not be negative")?;
        for (i, d) in self.outie_pucks.iter().enumerate() {
            d.validate(&format!("sensors.outie_pucks[{i}]"))?;
        }
        for (i, d) in self.innie_pucks.iter().enumerate() {
            d.validate(&format!("sensors.innie_pucks[{i}]"))?;
        }
        self.obstacle.validate("sensors.obstacle")
    }
}

/// A disc in the robot's frame: x forward, y to the right, in units.
#[derive(Clone, Copy, Debug, PartialEq)]
struct LocalDisc {
    offset: Vec2,
    radius: f64,
}

impl LocalDisc {
    /// The right-side disc and its left mirror image.
    fn pair(d: &SensorDisc, robot_radius: f64) -> [LocalDisc; 2] {
        let right = Vec2::from_angle(d.angle_deg.to_radians()) * (d.distance * robot_radius);
        let radius = d.radius * robot_radius;
        [LocalDisc { offset: Vec2::new(right.x, -right.y), radius }, LocalDisc { offset: right, radius }]
    }
}

/// The reference model's disc sensors, with the geometry converted to units.
#[derive(Clone, Debug)]
pub struct DiscSensors {
    /// Left, mid, right sample points.
    field: [Vec2; 3],
    /// Left discs then right discs, per kind: `[outie, innie]`.
    pucks: [[Vec<LocalDisc>; 2]; 2],
    /// Left and right obstacle discs (mirror images: the same radius).
    obstacle: [LocalDisc; 2],
    /// How far from the robot's centre the obstacle discs reach.
    obstacle_reach: f64,
    targets: ObstacleTargets,
    /// Per robot, left and right: the puck that set the puck bit last
    /// time. A puck usually stays in a disc for several steps, so it is
    /// tested first and spares the neighbour queries. Only a hint: it is
    /// tested exactly like any other puck, so readings never depend on it.
    witnesses: Vec<[usize; 2]>,
}

impl DiscSensors {
    /// Sensors of the given geometry for robots of `robot_radius`.
    pub fn new(config: &DiscSensorConfig, robot_radius: f64) -> DiscSensors {
        let side = Vec2::from_angle(config.field_angle_deg.to_radians()) * (config.field_distance * robot_radius);
        let pucks = |discs: &[SensorDisc]| {
            let pairs: Vec<[LocalDisc; 2]> = discs.iter().map(|d| LocalDisc::pair(d, robot_radius)).collect();
            [pairs.iter().map(|p| p[0]).collect(), pairs.iter().map(|p| p[1]).collect()]
        };
        DiscSensors {
            field: [Vec2::new(side.x, -side.y), Vec2::new(config.field_distance * robot_radius, 0.0), side],
            pucks: [pucks(&config.outie_pucks), pucks(&config.innie_pucks)],
            obstacle: LocalDisc::pair(&config.obstacle, robot_radius),
            obstacle_reach: (config.obstacle.distance + config.obstacle.radius) * robot_radius,
            targets: config.obstacle_targets,
            witnesses: Vec::new(),
        }
    }

    fn puck_discs(&self, kind: RobotKind) -> &[Vec<LocalDisc>; 2] {
        &self.pucks[usize::from(kind == RobotKind::Innie)]
    }
}

impl SensorModel for DiscSensors {
    fn sense(&mut self, world: &World, field: &ScalarField, out: &mut [SensorReading]) {
        let size = world.config().arena_size;
        let obstacles = match self.targets {
            ObstacleTargets::Robots => world.robots().len(),
            ObstacleTargets::AnyBody => world.bodies().len(),
        } as u32;
        let mut witnesses = std::mem::take(&mut self.witnesses);
        witnesses.resize(world.robots().len(), [usize::MAX; 2]);
        for (i, ((robot, reading), witness)) in world.robots().iter().zip(out.iter_mut()).zip(&mut witnesses).enumerate() {
            let pos = world.bodies()[i].pos;
            let at = |local: Vec2| pos + local.rotated(robot.direction);
            let [left, right] = self.puck_discs(robot.kind);
            let any_puck = |discs: &[LocalDisc], witness: &mut usize| {
                discs.iter().any(|d| world.puck_overlaps_disc(*witness, at(d.offset), d.radius))
                    || discs.iter().find_map(|d| world.puck_in_disc(at(d.offset), d.radius)).map(|puck| *witness = puck).is_some()
            };
            // Both obstacle discs hug the robot: one neighbour query around
            // the robot serves both.
            let [obstacle_left, obstacle_right] = self.obstacle.map(|d| (at(d.offset), d.radius));
            let (mut seen_left, mut seen_right) = (false, false);
            world.any_body_around(i, self.obstacle_reach + world.config().max_radius(), |row| {
                for b in row {
                    let counts = (b.body as usize != i) & (b.body < obstacles);
                    let overlaps = |(c, r): (Vec2, f64)| disc_overlaps(c, r, b.pos, b.radius);
                    seen_left |= counts & overlaps(obstacle_left);
                    seen_right |= counts & overlaps(obstacle_right);
                }
                seen_left && seen_right
            });
            *reading = SensorReading {
                left: field.sense(at(self.field[0]), size),
                mid: field.sense(at(self.field[1]), size),
                right: field.sense(at(self.field[2]), size),
                puck_left: any_puck(left, &mut witness[0]),
                puck_right: any_puck(right, &mut witness[1]),
                obstacle_left: seen_left,
                obstacle_right: seen_right,
            };
        }
        self.witnesses = witnesses;
    }

    fn footprints(&self, world: &World, robot: usize, out: &mut Vec<Footprint>) {
        let (pos, r) = (world.bodies()[robot].pos, world.robots()[robot]);
        let at = |local: Vec2| pos + local.rotated(r.direction);
        out.extend(self.field.iter().map(|&p| Footprint { centre: at(p), radius: 0.0, kind: FootprintKind::Field }));
        for d in self.puck_discs(r.kind).iter().flatten() {
            out.push(Footprint { centre: at(d.offset), radius: d.radius, kind: FootprintKind::Puck });
        }
        for d in &self.obstacle {
            out.push(Footprint { centre: at(d.offset), radius: d.radius, kind: FootprintKind::Obstacle });
        }
    }
}
