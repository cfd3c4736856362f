//! `--sensors` (and `sensors = "..."` in training and experiment files):
//! a sensor model by name, `disc`, `disc-thesis` or `robot`
//! ([`SensorSetup`]), or `robot:FILE`, the robot sensor model with
//! the settings of a JSON [`RobotSensorConfig`] file (every field
//! optional; `docs/robot-sensors.md`), or a mix for ablations:
//! `mix:FIELD+PUCKS+OBSTACLES`, the field values, puck bits and obstacle
//! bits each of its own model (`mix:robot+disc+disc`), or
//! `mix:FIELD+OBJECTS` with one model for both kinds of bits.

use crate::base::ranges;
use crate::config::SimConfig;
use crate::scenario::sensor_setup::{SelectedSensors, SensorSetup};
use crate::scenario::ScenarioError;
use crate::sensors::robot::RobotSensorConfig;
use serde::{Deserialize, Serialize};
use std::fmt;
use std::path::{Path, PathBuf};
use std::str::FromStr;

/// The `--sensors` choice.
#[derive(Clone, Debug, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(try_from = "String", into = "String")]
pub enum SensorChoice {
    /// The thesis' disc sensors of `SimConfig::sensors`.
    #[default]
    Disc,
    /// The disc sensors with the thesis' obstacle discs.
    DiscThesis,
    /// The robot sensor model, with the settings of a JSON file if given.
    Robot(Option<PathBuf>),
    /// Field values of the first, puck bits of the second, obstacle bits
    /// of the third.
    Mixed(Box<[SensorChoice; 3]>),
}

impl SensorChoice {
    /// The sensor models by name.
    pub const NAMES: &'static str = "disc, disc-thesis, robot";
}

impl FromStr for SensorChoice {
    type Err = String;

    fn from_str(s: &str) -> Result<SensorChoice, String> {
        if let Some(mix) = s.strip_prefix("mix:") {
            let parts = mix
                .split('+')
                .map(str::parse)
                .collect::<Result<Vec<SensorChoice>, String>>()?;
            return match <[SensorChoice; 2]>::try_from(parts.clone()) {
                Ok([field, objects]) => Ok(SensorChoice::Mixed(Box::new([field, objects.clone(), objects]))),
                Err(_) => <[SensorChoice; 3]>::try_from(parts).map(|p| SensorChoice::Mixed(Box::new(p))).map_err(|_| {
                    format!("sensor model {s:?}: a mix is mix:FIELD+PUCKS+OBSTACLES or mix:FIELD+OBJECTS")
                }),
            };
        }
        match s {
            "disc" => Ok(SensorChoice::Disc),
            "disc-thesis" => Ok(SensorChoice::DiscThesis),
            "robot" => Ok(SensorChoice::Robot(None)),
            _ => match s.strip_prefix("robot:") {
                Some(path) if !path.is_empty() => Ok(SensorChoice::Robot(Some(PathBuf::from(path)))),
                _ => Err(format!(
                    "unknown sensor model {s:?}: expected {}, robot:CONFIG.json or mix:FIELD+OBJECTS",
                    SensorChoice::NAMES
                )),
            },
        }
    }
}

crate::text_form!(SensorChoice);

impl fmt::Display for SensorChoice {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            SensorChoice::Disc => f.write_str("disc"),
            SensorChoice::DiscThesis => f.write_str("disc-thesis"),
            SensorChoice::Robot(None) => f.write_str("robot"),
            SensorChoice::Robot(Some(p)) => write!(f, "robot:{}", p.display()),
            SensorChoice::Mixed(parts) => write!(f, "mix:{}+{}+{}", parts[0], parts[1], parts[2]),
        }
    }
}

/// Reads and validates a robot sensor config file; errors name the file.
pub fn read_robot_config(path: &Path) -> Result<RobotSensorConfig, ScenarioError> {
    let problem = |problem: String| ScenarioError::SettingsFile {
        what: "robot sensor config",
        path: path.to_path_buf(),
        problem,
    };
    let text = ranges::read_text(path, &ranges::SETTINGS_FILE)
        .map_err(|e| problem(format!("cannot be read: {e}")))?;
    let config: RobotSensorConfig =
        serde_json::from_str(&text).map_err(|e| problem(format!("is not valid: {e}")))?;
    config.validate().map_err(|e| problem(e.to_string()))?;
    Ok(config)
}

impl SensorChoice {
    /// The sensor model with its settings (a config file read and checked).
    pub fn setup(&self) -> Result<SensorSetup, ScenarioError> {
        Ok(match self {
            SensorChoice::Disc => SensorSetup::Disc,
            SensorChoice::DiscThesis => SensorSetup::DiscThesis,
            SensorChoice::Robot(None) => SensorSetup::Robot(Box::default()),
            SensorChoice::Robot(Some(path)) => {
                SensorSetup::Robot(Box::new(read_robot_config(path)?))
            }
            SensorChoice::Mixed(parts) => SensorSetup::Mixed {
                field: Box::new(parts[0].setup()?),
                pucks: Box::new(parts[1].setup()?),
                obstacles: Box::new(parts[2].setup()?),
            },
        })
    }

    /// Whether the robot sensor model takes part.
    pub fn is_robot(&self) -> bool {
        match self {
            SensorChoice::Robot(_) => true,
            SensorChoice::Mixed(parts) => parts.iter().any(SensorChoice::is_robot),
            _ => false,
        }
    }

    /// The sensor model for the robots of `config`.
    pub fn build(&self, config: &SimConfig) -> Result<SelectedSensors, ScenarioError> {
        Ok(self.setup()?.build(config))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_give_their_models() {
        assert_eq!(
            "disc".parse::<SensorChoice>().unwrap().setup().unwrap(),
            SensorSetup::Disc
        );
        assert_eq!(
            "disc-thesis"
                .parse::<SensorChoice>()
                .unwrap()
                .setup()
                .unwrap(),
            SensorSetup::DiscThesis
        );
        assert_eq!(
            "robot".parse::<SensorChoice>().unwrap().setup().unwrap(),
            SensorSetup::Robot(Box::default())
        );
    }

    #[test]
    fn choices_parse_print_and_errors_name_the_input() {
        for s in [
            "disc",
            "disc-thesis",
            "robot",
            "robot:cam.json",
            "mix:robot+disc+disc-thesis",
            "mix:disc+robot:cam.json+disc",
        ] {
            assert_eq!(s.parse::<SensorChoice>().unwrap().to_string(), s);
        }
        assert_eq!(
            "mix:robot+disc"
                .parse::<SensorChoice>()
                .unwrap()
                .to_string(),
            "mix:robot+disc+disc"
        );
        let e = "pixy".parse::<SensorChoice>().unwrap_err();
        assert!(e.contains("\"pixy\""), "{e}");
        assert!("robot:".parse::<SensorChoice>().is_err());
        let e = "mix:robot".parse::<SensorChoice>().unwrap_err();
        assert!(e.contains("mix:FIELD+PUCKS+OBSTACLES"), "{e}");
        assert!("mix:robot+sonar"
            .parse::<SensorChoice>()
            .unwrap_err()
            .contains("\"sonar\""));
    }

    #[test]
    fn config_files_are_read_and_bad_ones_named() {
        let dir = tempfile::tempdir().unwrap();
        let good = dir.path().join("good.json");
        std::fs::write(&good, r#"{"camera": {"tilt_deg": 15.0}}"#).unwrap();
        assert_eq!(read_robot_config(&good).unwrap().camera.tilt_deg, 15.0);
        let bad = dir.path().join("bad.json");
        std::fs::write(&bad, r#"{"camera": {"height_mm": 0}}"#).unwrap();
        let e = read_robot_config(&bad).unwrap_err().to_string();
        assert!(
            e.contains("bad.json") && e.contains("camera.height_mm"),
            "{e}"
        );
        let e = read_robot_config(&dir.path().join("none.json"))
            .unwrap_err()
            .to_string();
        assert!(e.contains("none.json"), "{e}");
    }
}
