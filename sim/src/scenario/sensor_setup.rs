//! Which sensor model the simulated robots have, and the model it builds:
//!
//! - `disc`: the disc sensors of the reference model (obstacle discs as in
//!   the original code: radius r/4, any body);
//! - `disc-thesis`: the same with the obstacle discs the thesis describes
//!   (section 5.2: the size of a puck sensor, robots only);
//! - `robot`: the Zumo's real senses ([`RobotSensors`]: photo-transistors
//!   through the firmware's RC timing and calibration, the Pixy camera
//!   through the firmware's blob classification), with a
//!   [`RobotSensorConfig`];
//! - a mix, for ablations: the field values, the puck bits and the
//!   obstacle bits each from its own model ([`crate::sensors::mixed`]).

use crate::base::vec2::Vec2;
use crate::config::disc_sensors::DiscSensorConfig;
use crate::config::validate::ConfigError;
use crate::config::SimConfig;
use crate::fields::ScalarField;
use crate::sensors::disc::DiscSensors;
use crate::sensors::mixed::MixedSensors;
use crate::sensors::robot::{RobotSensorConfig, RobotSensors};
use crate::sensors::robot_noise::RobotNoise;
use crate::sensors::{Footprint, SensorMemory, SensorModel};
use crate::world::World;
use shared::SensorReading;

/// A sensor model and its settings.
#[derive(Clone, Debug, Default, PartialEq)]
pub enum SensorSetup {
    /// The thesis' disc sensors of `SimConfig::sensors`.
    #[default]
    Disc,
    /// The disc sensors with the thesis' obstacle discs
    /// ([`DiscSensorConfig::thesis_obstacles`]).
    DiscThesis,
    /// The robot sensor model with these settings.
    Robot(Box<RobotSensorConfig>),
    /// Field values from `field`'s model, puck bits from `pucks`',
    /// obstacle bits from `obstacles`'.
    Mixed {
        /// The model of the field values.
        field: Box<SensorSetup>,
        /// The model of the puck bits.
        pucks: Box<SensorSetup>,
        /// The model of the obstacle bits.
        obstacles: Box<SensorSetup>,
    },
}

impl SensorSetup {
    /// This setup with the robot sensor model's noise set to `noise`
    /// (in every part of a mix; the disc models have none).
    pub(crate) fn with_noise(&self, noise: &RobotNoise) -> SensorSetup {
        self.map_noise(&|_| noise.clone())
    }

    /// This setup with the screen's brightness unevenness of the robot
    /// sensor model's noise times `share` (a flat-field corrected panel).
    pub(crate) fn with_unevenness(&self, share: f64) -> SensorSetup {
        self.map_noise(&|noise| RobotNoise {
            brightness: noise.brightness * share,
            ..noise.clone()
        })
    }

    /// This setup with the robot sensor model's noise replaced by `f` of
    /// it, in every part of a mix.
    fn map_noise(&self, f: &dyn Fn(&RobotNoise) -> RobotNoise) -> SensorSetup {
        match self {
            SensorSetup::Robot(robot) => SensorSetup::Robot(Box::new(RobotSensorConfig {
                noise: f(&robot.noise),
                ..(**robot).clone()
            })),
            SensorSetup::Mixed {
                field,
                pucks,
                obstacles,
            } => SensorSetup::Mixed {
                field: Box::new(field.map_noise(f)),
                pucks: Box::new(pucks.map_noise(f)),
                obstacles: Box::new(obstacles.map_noise(f)),
            },
            other => other.clone(),
        }
    }

    /// Checks a robot sensor config's settings (the others have none).
    pub fn validate(&self) -> Result<(), ConfigError> {
        match self {
            SensorSetup::Disc | SensorSetup::DiscThesis => Ok(()),
            SensorSetup::Robot(robot) => robot.validate(),
            SensorSetup::Mixed {
                field,
                pucks,
                obstacles,
            } => field
                .validate()
                .and(pucks.validate())
                .and(obstacles.validate()),
        }
    }

    /// The sensor model for the robots of `config` (validate first:
    /// [`SensorSetup::validate`]).
    pub fn build(&self, config: &SimConfig) -> SelectedSensors {
        let radius = config.world.robot_radius;
        match self {
            SensorSetup::Disc => SelectedSensors::Disc(DiscSensors::new(&config.sensors, radius)),
            SensorSetup::DiscThesis => {
                let thesis = DiscSensorConfig::thesis_obstacles();
                let discs = DiscSensorConfig {
                    obstacle: thesis.obstacle,
                    obstacle_targets: thesis.obstacle_targets,
                    ..config.sensors.clone()
                };
                SelectedSensors::Disc(DiscSensors::new(&discs, radius))
            }
            SensorSetup::Robot(robot) => {
                SelectedSensors::Robot(Box::new(RobotSensors::new(robot, &config.world)))
            }
            SensorSetup::Mixed {
                field,
                pucks,
                obstacles,
            } => SelectedSensors::Mixed(Box::new(MixedSensors::new(
                field.build(config),
                pucks.build(config),
                obstacles.build(config),
            ))),
        }
    }
}

/// The model a [`SensorSetup`] built.
#[allow(
    clippy::large_enum_variant,
    reason = "one per simulation; the disc model, the common one, stays unboxed"
)]
#[derive(Clone, Debug)]
pub enum SelectedSensors {
    /// The thesis' discs.
    Disc(DiscSensors),
    /// The robot's photo-transistors and camera.
    Robot(Box<RobotSensors>),
    /// Two models' mix.
    Mixed(Box<MixedSensors<SelectedSensors>>),
}

impl SensorModel for SelectedSensors {
    fn sense(&mut self, world: &World, field: &ScalarField, out: &mut [SensorReading]) {
        match self {
            SelectedSensors::Disc(s) => s.sense(world, field, out),
            SelectedSensors::Robot(s) => s.sense(world, field, out),
            SelectedSensors::Mixed(s) => s.sense(world, field, out),
        }
    }

    fn footprints(&self, world: &World, robot: usize, out: &mut Vec<Footprint>) {
        match self {
            SelectedSensors::Disc(s) => s.footprints(world, robot, out),
            SelectedSensors::Robot(s) => s.footprints(world, robot, out),
            SelectedSensors::Mixed(s) => s.footprints(world, robot, out),
        }
    }

    fn camera_view(&self) -> Vec<Vec2> {
        match self {
            SelectedSensors::Disc(s) => s.camera_view(),
            SelectedSensors::Robot(s) => s.camera_view(),
            SelectedSensors::Mixed(s) => s.camera_view(),
        }
    }

    fn memory(&self) -> SensorMemory {
        match self {
            SelectedSensors::Disc(s) => s.memory(),
            SelectedSensors::Robot(s) => s.memory(),
            SelectedSensors::Mixed(s) => s.memory(),
        }
    }

    fn restore(&mut self, memory: &SensorMemory) {
        match self {
            SelectedSensors::Disc(s) => s.restore(memory),
            SelectedSensors::Robot(s) => s.restore(memory),
            SelectedSensors::Mixed(s) => s.restore(memory),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_robot_setup_builds_the_robot_sensor_model() {
        let config = SimConfig::default();
        assert!(matches!(
            SensorSetup::Robot(Box::default()).build(&config),
            SelectedSensors::Robot(_)
        ));
    }
}
