//! The reference model's disc sensors ([`DiscSensors`]): three field sample
//! points, two puck sensors of two discs each, two obstacle discs, all
//! fixed to the robot's centre and heading, in the geometry of a
//! [`DiscSensorConfig`].

use crate::base::vec2::Vec2;
use crate::config::disc_sensors::{DiscSensorConfig, ObstacleTargets, SensorDisc};
use crate::fields::ScalarField;
use crate::physics::body::RobotKind;
use crate::physics::outline::Outline;
use crate::sensors::{Footprint, FootprintKind, SensorModel};
use crate::world::{disc_overlaps, World};
use shared::SensorReading;

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
        [
            LocalDisc {
                offset: Vec2::new(right.x, -right.y),
                radius,
            },
            LocalDisc {
                offset: right,
                radius,
            },
        ]
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
        let side = Vec2::from_angle(config.field_angle_deg.to_radians())
            * (config.field_distance * robot_radius);
        let pucks = |discs: &[SensorDisc]| {
            let pairs: Vec<[LocalDisc; 2]> = discs
                .iter()
                .map(|d| LocalDisc::pair(d, robot_radius))
                .collect();
            [
                pairs.iter().map(|p| p[0]).collect(),
                pairs.iter().map(|p| p[1]).collect(),
            ]
        };
        DiscSensors {
            field: [
                Vec2::new(side.x, -side.y),
                Vec2::new(config.field_distance * robot_radius, 0.0),
                side,
            ],
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
        let layout = world.config().field_layout();
        let obstacles = match self.targets {
            ObstacleTargets::Robots => world.robots().len(),
            ObstacleTargets::AnyBody => world.bodies().len(),
        } as u32;
        let outline = Outline::of(world.config().robot_shape, world.config().robot_radius);
        let robots = world.robots().len() as u32;
        let mut witnesses = std::mem::take(&mut self.witnesses);
        witnesses.resize(world.robots().len(), [usize::MAX; 2]);
        for (i, ((robot, reading), witness)) in world
            .robots()
            .iter()
            .zip(out.iter_mut())
            .zip(&mut witnesses)
            .enumerate()
        {
            let pos = world.bodies()[i].pos;
            let at = |local: Vec2| pos + local.rotated(robot.direction);
            let [left, right] = self.puck_discs(robot.kind);
            let any_puck = |discs: &[LocalDisc], witness: &mut usize| {
                discs
                    .iter()
                    .any(|d| world.puck_overlaps_disc(*witness, at(d.offset), d.radius))
                    || discs
                        .iter()
                        .find_map(|d| world.puck_in_disc(at(d.offset), d.radius))
                        .map(|puck| *witness = puck)
                        .is_some()
            };
            // Both obstacle discs hug the robot: one neighbour query around
            // the robot serves both.
            let [obstacle_left, obstacle_right] = self.obstacle.map(|d| (at(d.offset), d.radius));
            let (mut seen_left, mut seen_right) = (false, false);
            let reach = self.obstacle_reach + world.config().max_radius();
            // A body can touch a disc only within `reach` of the robot's
            // centre (with room for rounding): most of those visited are
            // farther, and skip the two exact tests.
            let near2 = (reach * (1.0 + 1e-9)).powi(2);
            world.any_body_around(i, reach, |row| {
                for b in row {
                    if (b.pos - pos).length_squared() >= near2 {
                        continue;
                    }
                    let counts = (b.body as usize != i) & (b.body < obstacles);
                    // A wedge robot is seen where its outline is.
                    let overlaps = |(c, r): (Vec2, f64)| match outline.filter(|_| b.body < robots) {
                        None => disc_overlaps(c, r, b.pos, b.radius),
                        Some(o) => {
                            let facing = world.robots()[b.body as usize].direction;
                            o.circle_depth(facing, c - b.pos, r).0 > 0.0
                        }
                    };
                    seen_left |= counts & overlaps(obstacle_left);
                    seen_right |= counts & overlaps(obstacle_right);
                }
                seen_left && seen_right
            });
            *reading = SensorReading {
                left: field.sense(at(self.field[0]), &layout),
                mid: field.sense(at(self.field[1]), &layout),
                right: field.sense(at(self.field[2]), &layout),
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
        out.extend(self.field.iter().map(|&p| Footprint {
            centre: at(p),
            radius: 0.0,
            kind: FootprintKind::Field,
        }));
        for d in self.puck_discs(r.kind).iter().flatten() {
            out.push(Footprint {
                centre: at(d.offset),
                radius: d.radius,
                kind: FootprintKind::Puck,
            });
        }
        for d in &self.obstacle {
            out.push(Footprint {
                centre: at(d.offset),
                radius: d.radius,
                kind: FootprintKind::Obstacle,
            });
        }
    }
}
