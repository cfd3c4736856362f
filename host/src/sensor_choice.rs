//! `--sensors`: which sensor model the simulated robots have.
//!
//! - `disc`: the disc sensors of the reference model (default; obstacle
//!   discs as in the original code: radius r/4, any body);
//! - `disc-thesis`: the same with the obstacle discs the thesis describes
//!   (section 5.2: the size of a puck sensor, robots only);
//! - `robot`: the Zumo's real senses ([`RobotSensors`]: photo-transistors
//!   through the firmware's RC timing and calibration, the Pixy camera
//!   through the firmware's blob classification), default settings;
//! - `robot:FILE`: the same with the settings of a JSON [`RobotSensorConfig`]
//!   file (every field optional; `docs/robot-sensors.md`).

use crate::sim::{DiscSensorConfig, DiscSensors, Footprint, RobotSensorConfig, RobotSensors, ScalarField, SensorModel, SimConfig, World};
use anyhow::{Context, Result};
use serde::{Deserialize, Serialize};
use shared::SensorReading;
use std::fmt;
use std::path::{Path, PathBuf};
use std::str::FromStr;

/// The `--sensors` choice (`sensors = "..."` in training and experiment
/// files, with the same names).
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(try_from = "String", into = "String")]
pub enum SensorChoice {
    /// The thesis' disc sensors of `SimConfig::sensors`.
    #[default]
    Disc,
    /// The disc sensors with the thesis' obstacle discs
    /// ([`DiscSensorConfig::thesis_obstacles`]).
    DiscThesis,
    /// The robot sensor model, with the settings of a JSON file if given.
    Robot(Option<PathBuf>),
}

impl FromStr for SensorChoice {
    type Err = String;

    fn from_str(s: &str) -> Result<SensorChoice, String> {
        match s {
            "disc" => Ok(SensorChoice::Disc),
            "disc-thesis" => Ok(SensorChoice::DiscThesis),
            "robot" => Ok(SensorChoice::Robot(None)),
            _ => match s.strip_prefix("robot:") {
                Some(path) if !path.is_empty() => Ok(SensorChoice::Robot(Some(PathBuf::from(path)))),
                _ => Err(format!("unknown sensor model {s:?}: expected disc, disc-thesis, robot or robot:CONFIG.json")),
            },
        }
    }
}

impl TryFrom<String> for SensorChoice {
    type Error = String;

    fn try_from(s: String) -> Result<SensorChoice, String> {
        s.parse()
    }
}

impl From<SensorChoice> for String {
    fn from(c: SensorChoice) -> String {
        c.to_string()
    }
}

impl fmt::Display for SensorChoice {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            SensorChoice::Disc => f.write_str("disc"),
            SensorChoice::DiscThesis => f.write_str("disc-thesis"),
            SensorChoice::Robot(None) => f.write_str("robot"),
            SensorChoice::Robot(Some(p)) => write!(f, "robot:{}", p.display()),
        }
    }
}

/// Reads and validates a robot sensor config file; errors name the file.
pub fn read_robot_config(path: &Path) -> Result<RobotSensorConfig> {
    let text =
        std::fs::read_to_string(path).with_context(|| format!("cannot read robot sensor config {}", path.display()))?;
    let config: RobotSensorConfig =
        serde_json::from_str(&text).with_context(|| format!("robot sensor config {} is not valid", path.display()))?;
    config.validate().with_context(|| format!("robot sensor config {}", path.display()))?;
    Ok(config)
}

impl SensorChoice {
    /// The sensor model for the robots of `config`.
    pub fn build(&self, config: &SimConfig) -> Result<SelectedSensors> {
        let radius = config.world.robot_radius;
        Ok(match self {
            SensorChoice::Disc => SelectedSensors::Disc(DiscSensors::new(&config.sensors, radius)),
            SensorChoice::DiscThesis => {
                let thesis = DiscSensorConfig::thesis_obstacles();
                let discs = DiscSensorConfig {
                    obstacle: thesis.obstacle,
                    obstacle_targets: thesis.obstacle_targets,
                    ..config.sensors.clone()
                };
                SelectedSensors::Disc(DiscSensors::new(&discs, radius))
            }
            SensorChoice::Robot(file) => {
                let robot = match file {
                    Some(path) => read_robot_config(path)?,
                    None => RobotSensorConfig::default(),
                };
                SelectedSensors::Robot(Box::new(RobotSensors::new(&robot, radius)))
            }
        })
    }
}

/// The model a [`SensorChoice`] selected.
#[derive(Clone, Debug)]
pub enum SelectedSensors {
    /// The thesis' discs.
    Disc(DiscSensors),
    /// The robot's photo-transistors and camera.
    Robot(Box<RobotSensors>),
}

impl SensorModel for SelectedSensors {
    fn sense(&mut self, world: &World, field: &ScalarField, out: &mut [SensorReading]) {
        match self {
            SelectedSensors::Disc(s) => s.sense(world, field, out),
            SelectedSensors::Robot(s) => s.sense(world, field, out),
        }
    }

    fn footprints(&self, world: &World, robot: usize, out: &mut Vec<Footprint>) {
        match self {
            SelectedSensors::Disc(s) => s.footprints(world, robot, out),
            SelectedSensors::Robot(s) => s.footprints(world, robot, out),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn choices_parse_print_and_errors_name_the_input() {
        for s in ["disc", "disc-thesis", "robot", "robot:cam.json"] {
            assert_eq!(s.parse::<SensorChoice>().unwrap().to_string(), s);
        }
        let e = "pixy".parse::<SensorChoice>().unwrap_err();
        assert!(e.contains("\"pixy\""), "{e}");
        assert!("robot:".parse::<SensorChoice>().is_err());
    }

    #[test]
    fn config_files_are_read_and_bad_ones_named() {
        let dir = tempfile::tempdir().unwrap();
        let good = dir.path().join("good.json");
        std::fs::write(&good, r#"{"camera": {"tilt_deg": 15.0}}"#).unwrap();
        assert_eq!(read_robot_config(&good).unwrap().camera.tilt_deg, 15.0);
        let bad = dir.path().join("bad.json");
        std::fs::write(&bad, r#"{"camera": {"height": 0}}"#).unwrap();
        let e = format!("{:#}", read_robot_config(&bad).unwrap_err());
        assert!(e.contains("bad.json") && e.contains("camera.height"), "{e}");
        let e = format!("{:#}", read_robot_config(&dir.path().join("none.json")).unwrap_err());
        assert!(e.contains("none.json"), "{e}");
    }
}
