//! The geometry of the reference model's disc sensors: where the three
//! field points and the puck and obstacle discs sit on a robot, and what
//! the obstacle discs detect. Angles are degrees, positive to the robot's
//! right (clockwise on screen, y down); distances and radii are in robot
//! radii. Each right-side disc is mirrored (negated angle) on the left.

use crate::base::ranges;
use crate::config::validate::ConfigError;
use serde::{Deserialize, Serialize};

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
        SensorDisc {
            angle_deg,
            distance,
            radius,
        }
    }

    fn validate(&self, name: &str) -> Result<(), ConfigError> {
        ranges::DISC_ANGLE.check_as(&format!("{name}.angle_deg"), self.angle_deg)?;
        ranges::DISC_DISTANCE.check_as(&format!("{name}.distance"), self.distance)?;
        ranges::DISC_RADIUS.check_as(&format!("{name}.radius"), self.radius)?;
        Ok(())
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
            outie_pucks: vec![
                SensorDisc::new(30.0, 4.0, 2.0),
                SensorDisc::new(60.0, 7.0, 2.0),
            ],
            innie_pucks: vec![
                SensorDisc::new(45.0, 3.0, 2.0),
                SensorDisc::new(70.0, 6.5, 2.0),
            ],
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
        ranges::DISC_ANGLE.check(self.field_angle_deg)?;
        ranges::DISC_DISTANCE.check(self.field_distance)?;
        for (i, d) in self.outie_pucks.iter().enumerate() {
            d.validate(&format!("sensors.outie_pucks[{i}]"))?;
        }
        for (i, d) in self.innie_pucks.iter().enumerate() {
            d.validate(&format!("sensors.innie_pucks[{i}]"))?;
        }
        self.obstacle.validate("sensors.obstacle")
    }
}
