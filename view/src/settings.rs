//! The view's settings: the controller and the world's settings
//! ([`WorldChoices`], by their names) as URL parameters, parsed and limited
//! to what a browser may choose: built-in fields and arenas, the arena
//! files the server was started with, the policies of its policy folder
//! and the ones uploaded. The values' ranges are checked where the
//! scenario is built ([`sim::scenario::Scenario::prepare`]).

use sim::fields::source::FieldSource;
use sim::scenario::arena_choice::ArenaChoice;
use sim::scenario::choices::{ScenarioChoices, WorldChoices};
use sim::scenario::sensor_choice::SensorChoice;
use sim::scenario::ControllerChoice;
use std::fmt;
use std::path::PathBuf;
use std::str::FromStr;

/// Which controller drives the robots.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum ViewController {
    /// Orbital construction.
    Orbital,
    /// Random turns.
    Random,
    /// A file of the server's policy folder, by name.
    Policy(String),
    /// A policy uploaded to this server, by name.
    Upload(String),
}

impl fmt::Display for ViewController {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            ViewController::Orbital => f.write_str("oc"),
            ViewController::Random => f.write_str("random"),
            ViewController::Policy(name) => write!(f, "policy:{name}"),
            ViewController::Upload(name) => write!(f, "upload:{name}"),
        }
    }
}

impl FromStr for ViewController {
    type Err = String;

    fn from_str(s: &str) -> Result<ViewController, String> {
        let named = |name: &str, what| {
            if valid_name(name) {
                Ok(name.to_string())
            } else {
                Err(format!(
                    "controller {s:?}: {what} names are letters, digits, '.', '-' and '_'"
                ))
            }
        };
        match s {
            "oc" => Ok(ViewController::Orbital),
            "random" => Ok(ViewController::Random),
            _ => {
                if let Some(name) = s.strip_prefix("policy:") {
                    named(name, "policy").map(ViewController::Policy)
                } else if let Some(name) = s.strip_prefix("upload:") {
                    named(name, "upload").map(ViewController::Upload)
                } else {
                    Err(format!(
                        "unknown controller {s:?}: expected oc, random, policy:NAME or upload:NAME"
                    ))
                }
            }
        }
    }
}

/// A file or upload name a browser may give: no paths.
pub fn valid_name(name: &str) -> bool {
    !name.is_empty()
        && name.len() <= 100
        && !name.starts_with('.')
        && name
            .chars()
            .all(|c| c.is_ascii_alphanumeric() || matches!(c, '.' | '-' | '_'))
}

/// The view's settings: the controller, and the world's settings as
/// every front end names them ([`WorldChoices`]; the view offers all but
/// [`SERVER_KEEPS`]).
#[derive(Clone, Debug, PartialEq)]
pub struct ViewSettings {
    /// The controller.
    pub controller: ViewController,
    /// The world.
    pub world: WorldChoices,
}

impl Default for ViewSettings {
    /// The thesis' standard run.
    fn default() -> ViewSettings {
        ViewSettings {
            controller: ViewController::Orbital,
            world: WorldChoices::default(),
        }
    }
}

/// World settings a browser does not choose: the border keeps the one
/// the server was started with.
pub const SERVER_KEEPS: [&str; 1] = ["walls"];

/// The URL parameters of the settings: `controller`, then the world's
/// settings by name (all but [`SERVER_KEEPS`]).
pub fn keys() -> Vec<String> {
    std::iter::once("controller".to_string())
        .chain(
            WorldChoices::names()
                .iter()
                .filter(|k| !SERVER_KEEPS.contains(&k.as_str()))
                .cloned(),
        )
        .collect()
}

/// What a browser may choose beyond the built-in fields and arenas.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Allowed {
    /// Arena files the server was started with.
    pub arena_files: Vec<PathBuf>,
    /// A field image the server was started with.
    pub field_file: Option<PathBuf>,
    /// Sensor settings files the server was started with.
    pub sensor_files: Vec<PathBuf>,
}

impl ViewSettings {
    /// The view's settings of `choices` (its controller replaced by `controller`).
    pub fn from_choices(choices: &ScenarioChoices, controller: ViewController) -> ViewSettings {
        ViewSettings {
            controller,
            world: choices.world.clone(),
        }
    }

    /// The world's settings by name; a policy controller is named by
    /// `policy_path` (the caller has read or decoded it).
    pub fn choices(&self, policy_path: Option<PathBuf>) -> ScenarioChoices {
        let controller = match (&self.controller, policy_path) {
            (ViewController::Orbital, _) => ControllerChoice::Orbital,
            (ViewController::Random, _) => ControllerChoice::Random,
            (_, Some(path)) => ControllerChoice::Policy(path),
            (other, None) => ControllerChoice::Policy(PathBuf::from(other.to_string())),
        };
        ScenarioChoices {
            controller,
            world: self.world.clone(),
        }
    }

    /// Each setting as its URL parameter's value ("" for the arena's
    /// own), in the order of [`keys`].
    pub fn pairs(&self) -> Vec<(String, String)> {
        std::iter::once(("controller".to_string(), self.controller.to_string()))
            .chain(
                self.world
                    .pairs()
                    .into_iter()
                    .filter(|(k, _)| !SERVER_KEEPS.contains(&k.as_str())),
            )
            .collect()
    }

    /// These settings with the URL parameters `query` applied (keys other
    /// than [`keys`] are left to the caller: `ignore` lists those it
    /// takes). Errors name the parameter and its value.
    pub fn with_query(
        &self,
        query: &str,
        allowed: &Allowed,
        ignore: &[&str],
    ) -> Result<ViewSettings, String> {
        let mut s = self.clone();
        let offered = keys();
        for (key, value) in query_pairs(query) {
            let bad = |why: String| format!("{key}={value}: {why}");
            if key == "controller" {
                s.controller = value.parse().map_err(bad)?;
            } else if offered.contains(&key) {
                s.world.set(&key, &value).map_err(|e| bad(e.problem))?;
                // only the files the server was started with
                match key.as_str() {
                    "field" => check_field(&s.world.field, allowed),
                    "arena" => check_arena(s.world.arena.as_ref(), allowed),
                    "sensors" => check_sensors(&s.world.sensors, allowed),
                    _ => Ok(()),
                }
                .map_err(bad)?;
            } else if !ignore.contains(&key.as_str()) {
                return Err(format!(
                    "unknown setting {key:?}: expected {}",
                    offered.join(", ")
                ));
            }
        }
        Ok(s)
    }
}

/// A field a browser may choose: built in, or the server's image.
fn check_field(field: &FieldSource, allowed: &Allowed) -> Result<(), String> {
    match field {
        FieldSource::Image(path) if allowed.field_file.as_ref() != Some(path) => Err(
            "a field image must be the one the server was started with; built in: annulus, letter:T (I, L, V, X, Z), thesis:T (L, V, X, Z), either turned (letter:L@mirror), generated (gen:ring:3)"
                .into(),
        ),
        _ => Ok(()),
    }
}

/// An arena a browser may choose: built in, or one of the server's files.
fn check_arena(arena: Option<&ArenaChoice>, allowed: &Allowed) -> Result<(), String> {
    match arena {
        Some(ArenaChoice::File(path)) if !allowed.arena_files.contains(path) => {
            Err("an arena file must be one the server was started with (--arena-file)".into())
        }
        _ => Ok(()),
    }
}

/// Sensors a browser may choose: every settings file one of the server's.
fn check_sensors(sensors: &SensorChoice, allowed: &Allowed) -> Result<(), String> {
    fn files(s: &SensorChoice, out: &mut Vec<PathBuf>) {
        match s {
            SensorChoice::Robot(Some(path)) => out.push(path.clone()),
            SensorChoice::Mixed(parts) => parts.iter().for_each(|p| files(p, out)),
            _ => {}
        }
    }
    let mut named = Vec::new();
    files(sensors, &mut named);
    if named.iter().all(|p| allowed.sensor_files.contains(p)) {
        Ok(())
    } else {
        Err("a sensor settings file must be one the server was started with".into())
    }
}

/// The `key=value` pairs of a URL query, percent-decoded (`+` a space).
pub fn query_pairs(query: &str) -> Vec<(String, String)> {
    query
        .split('&')
        .filter(|p| !p.is_empty())
        .map(|p| {
            let (k, v) = p.split_once('=').unwrap_or((p, ""));
            (decode(k), decode(v))
        })
        .collect()
}

fn decode(s: &str) -> String {
    let bytes = s.as_bytes();
    let mut out = Vec::with_capacity(bytes.len());
    let mut i = 0;
    while i < bytes.len() {
        match bytes[i] {
            b'+' => out.push(b' '),
            b'%' if i + 2 < bytes.len() => {
                let hex = |c: u8| (c as char).to_digit(16);
                match (hex(bytes[i + 1]), hex(bytes[i + 2])) {
                    (Some(h), Some(l)) => {
                        out.push((h * 16 + l) as u8);
                        i += 2;
                    }
                    _ => out.push(b'%'),
                }
            }
            b => out.push(b),
        }
        i += 1;
    }
    String::from_utf8_lossy(&out).into_owned()
}

/// `pairs` as a URL query, percent-encoded.
pub fn encode_query(pairs: &[(String, String)]) -> String {
    let encode = |s: &str| {
        s.bytes()
            .map(|b| match b {
                b'A'..=b'Z' | b'a'..=b'z' | b'0'..=b'9' | b'-' | b'_' | b'.' | b'~' | b':' => {
                    (b as char).to_string()
                }
                _ => format!("%{b:02X}"),
            })
            .collect::<String>()
    };
    pairs
        .iter()
        .map(|(k, v)| format!("{k}={}", encode(v)))
        .collect::<Vec<_>>()
        .join("&")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn settings_round_trip_through_their_url_parameters() {
        let s = ViewSettings::default()
            .with_query(
                "controller=random&field=letter%3AT&arena=tv75&sensors=robot&noise=0.5&robots=5&pucks=&seed=7",
                &Allowed::default(),
                &[],
            )
            .unwrap();
        assert_eq!(s.world.robots, Some(5));
        assert_eq!(s.world.pucks, None);
        assert_eq!(s.world.field.to_string(), "letter:T");
        let again = ViewSettings::default()
            .with_query(&encode_query(&s.pairs()), &Allowed::default(), &[])
            .unwrap();
        assert_eq!(again, s);
    }

    #[test]
    fn a_browser_cannot_name_files_the_server_was_not_started_with() {
        let none = Allowed::default();
        let d = ViewSettings::default();
        for (query, says) in [
            ("field=/etc/passwd", "field=/etc/passwd: a field image"),
            // only built-in letters turn: a turned path is still a path
            ("field=/etc/passwd@mirror", "a field image"),
            ("arena=/tmp/x.toml", "arena=/tmp/x.toml: an arena file"),
            ("sensors=robot:/tmp/x.json", "sensor settings file"),
            ("controller=policy:../x", "controller=policy:../x"),
            (
                "robots=-1",
                "robots=-1: invalid value: integer `-1`, expected usize",
            ),
            ("noise=nan", "noise=nan: invalid type"),
            ("colour=red", "unknown setting \"colour\""),
        ] {
            let e = d.with_query(query, &none, &[]).unwrap_err();
            assert!(e.contains(says), "{query}: {e}");
        }
        let allowed = Allowed {
            arena_files: vec![PathBuf::from("/tmp/x.toml")],
            ..Allowed::default()
        };
        assert!(d.with_query("arena=/tmp/x.toml", &allowed, &[]).is_ok());
        assert!(d
            .with_query("field=letter%3AL%40mirror", &none, &[])
            .is_ok());
        assert!(d.with_query("speed=max", &none, &["speed"]).is_ok());
    }
}
