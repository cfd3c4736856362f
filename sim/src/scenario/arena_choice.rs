//! `--arena` (and `arena = "..."` in training files): `thesis`, the
//! reference model's 800 x 800 square; a built-in screen arena by name
//! (`tv75`, [`ArenaSpec::by_name`]); or the path of a TOML file of a screen arena
//! (every field optional, the rest `tv75`'s; `docs/robot-sensors.md`).
//! Without one, runs with the robot's senses use `tv75` and the others the
//! thesis' square.

use crate::base::ranges;
use crate::scenario::arena::ArenaSpec;
use crate::scenario::{Arena, ScenarioError};
use serde::{Deserialize, Serialize};
use std::fmt;
use std::path::{Path, PathBuf};
use std::str::FromStr;

/// The `--arena` choice.
#[derive(Clone, Debug, PartialEq, Eq, Serialize, Deserialize)]
#[serde(try_from = "String", into = "String")]
pub enum ArenaChoice {
    /// The thesis' square.
    Thesis,
    /// A built-in screen arena.
    Named(String),
    /// A screen arena file.
    File(PathBuf),
}

impl FromStr for ArenaChoice {
    type Err = String;

    fn from_str(s: &str) -> Result<ArenaChoice, String> {
        if s == "thesis" {
            Ok(ArenaChoice::Thesis)
        } else if ArenaSpec::by_name(s).is_some() {
            Ok(ArenaChoice::Named(s.to_string()))
        } else if s.ends_with(".toml") {
            Ok(ArenaChoice::File(PathBuf::from(s)))
        } else {
            Err(format!(
                "unknown arena {s:?}: expected thesis, {} or a FILE.toml",
                ArenaSpec::NAMES
            ))
        }
    }
}

crate::text_form!(ArenaChoice);

impl fmt::Display for ArenaChoice {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ArenaChoice::Thesis => f.write_str("thesis"),
            ArenaChoice::Named(name) => f.write_str(name),
            ArenaChoice::File(path) => write!(f, "{}", path.display()),
        }
    }
}

/// Reads and validates a screen arena file; errors name the file.
pub fn read_arena(path: &Path) -> Result<ArenaSpec, ScenarioError> {
    let problem = |problem: String| ScenarioError::SettingsFile {
        what: "arena file",
        path: path.to_path_buf(),
        problem,
    };
    let text = ranges::read_text(path, &ranges::SETTINGS_FILE)
        .map_err(|e| problem(format!("cannot be read: {e}")))?;
    let spec: ArenaSpec =
        toml::from_str(&text).map_err(|e| problem(format!("is not valid: {e}")))?;
    spec.validate().map_err(|e| problem(e.to_string()))?;
    Ok(spec)
}

impl ArenaChoice {
    /// The arena, a file read and checked.
    pub fn arena(&self) -> Result<Arena, ScenarioError> {
        Ok(match self {
            ArenaChoice::Thesis => Arena::default(),
            ArenaChoice::Named(name) => {
                let spec = ArenaSpec::by_name(name)
                    .ok_or_else(|| ScenarioError::UnknownArena(name.clone()))?;
                Arena::Screen(Box::new(spec))
            }
            ArenaChoice::File(path) => Arena::Screen(Box::new(read_arena(path)?)),
        })
    }

    /// The screen arena, for the tools of the TV (`host field export`,
    /// `host display`, `host observe`): the thesis' square is refused.
    pub fn screen(&self) -> Result<ArenaSpec, ScenarioError> {
        match self.arena()? {
            Arena::Screen(spec) => Ok(*spec),
            Arena::Square(_) => Err(ScenarioError::NotAScreen(self.to_string())),
        }
    }

    /// The arena a run uses without `--arena`: the TV with the robot's
    /// senses, the thesis' square otherwise.
    pub fn default_for(robot_senses: bool) -> ArenaChoice {
        if robot_senses {
            ArenaChoice::Named("tv75".into())
        } else {
            ArenaChoice::Thesis
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn choices_parse_print_and_errors_name_the_input() {
        for s in ["thesis", "tv75", "lab.toml"] {
            assert_eq!(s.parse::<ArenaChoice>().unwrap().to_string(), s);
        }
        assert_eq!(
            ArenaChoice::Named("tv75".into()).screen().unwrap(),
            ArenaSpec::tv75()
        );
        let e = ArenaChoice::Thesis.screen().unwrap_err().to_string();
        assert!(
            e.contains("--arena thesis") && e.contains("screen arena"),
            "{e}"
        );
        let e = "tv55".parse::<ArenaChoice>().unwrap_err();
        assert!(e.contains("\"tv55\"") && e.contains("tv75"), "{e}");
    }

    #[test]
    fn arena_files_name_only_what_they_change_and_bad_ones_are_named() {
        let dir = tempfile::tempdir().unwrap();
        let good = dir.path().join("lab.toml");
        std::fs::write(&good, "robots = 4\nscreen_mm = [1428.0, 804.0]\n").unwrap();
        let spec = read_arena(&good).unwrap();
        assert_eq!(
            (spec.robots, spec.screen_mm, spec.pucks),
            (4, [1428.0, 804.0], ArenaSpec::tv75().pucks)
        );
        let bad = dir.path().join("bad.toml");
        std::fs::write(&bad, "display_gamma = 0\n").unwrap();
        let e = read_arena(&bad).unwrap_err().to_string();
        assert!(
            e.contains("bad.toml") && e.contains("arena.display_gamma"),
            "{e}"
        );
        std::fs::write(&bad, "robot_radius = 3\n").unwrap();
        let e = read_arena(&bad).unwrap_err().to_string();
        assert!(e.contains("bad.toml") && e.contains("robot_radius"), "{e}");
    }
}
