//! `host view`: the live browser view's options (the world's flags are
//! `host run`'s, [`ScenarioArgs`]).

use super::robot::OdometryArgs;
use super::scenario::ScenarioArgs;
use super::screen::{parse_bind, Bind};
use anyhow::{bail, Result};
use clap::Args;
use sim::fields::source::FieldSource;
use sim::scenario::arena::ArenaSpec;
use sim::scenario::arena_choice::ArenaChoice;
use sim::scenario::sensor_choice::SensorChoice;
use sim::scenario::{Arena, ControllerChoice, Scenario};
use std::path::{Path, PathBuf};
use view::{Allowed, Speed, ViewController, ViewOptions, ViewSettings};

/// `host view`'s options.
#[derive(Args)]
pub struct ViewArgs {
    /// The first scenario (the page can change it).
    #[command(flatten)]
    pub scenario: ScenarioArgs,
    /// Address to listen on, IP or IP:PORT.
    #[arg(long, default_value = "127.0.0.1", value_parser = parse_bind)]
    pub bind: Bind,
    /// Port, when --bind names none (0: any free port).
    #[arg(long, default_value_t = 8076)]
    pub port: u16,
    /// Folder of the policy files the page offers [default: policies, if
    /// there is one; the folder of --controller policy:FILE].
    #[arg(long)]
    pub policies: Option<PathBuf>,
    /// A screen arena file the page may choose besides the built-in ones
    /// (repeatable).
    #[arg(long = "arena-file")]
    pub arena_files: Vec<PathBuf>,
    /// Start paused.
    #[arg(long)]
    pub paused: bool,
    /// real (50 steps/s, the robot's 20 ms period), 10x or max.
    #[arg(long, default_value = "real")]
    pub speed: Speed,
    /// Play a robot's recorded log (`host monitor`'s, or a raw capture)
    /// instead of a simulation, each frame checked against --policy as
    /// `host replay` checks it; --field and --arena say what the robot
    /// drove on (default the annulus on tv75).
    #[arg(long, requires = "policy")]
    pub log: Option<PathBuf>,
    /// With --log only: the policy blob the robot was flashed with (a
    /// simulation's policy is --controller policy:FILE).
    #[arg(long, requires = "log")]
    pub policy: Option<PathBuf>,
    /// How --log's wheel encoder counts become the robot's track.
    #[command(flatten)]
    pub odometry: OdometryArgs,
}

impl ViewArgs {
    /// The world a recorded log is drawn on: the flags' field and arena,
    /// tv75 when no arena is given (the robots' screen).
    pub fn log_scenario(&self) -> Result<Scenario> {
        let mut scenario = self.scenario.clone().scenario()?;
        if self.scenario.choices().world.arena.is_none() {
            scenario.arena = Arena::Screen(Box::new(ArenaSpec::tv75()));
        }
        Ok(scenario)
    }

    /// The server's options; errors name the flag.
    pub fn options(self) -> Result<ViewOptions> {
        let bind = self.bind.or_port(self.port);
        let choices = self.scenario.choices();
        let mut policies = self.policies;
        let controller = match &choices.controller {
            ControllerChoice::Orbital => ViewController::Orbital,
            ControllerChoice::Random => ViewController::Random,
            ControllerChoice::Policy(path) => {
                let (folder, name) = split_policy(path)?;
                match &policies {
                    Some(p) if p != &folder => bail!(
                        "--controller policy:{}: not in --policies {}",
                        path.display(),
                        p.display()
                    ),
                    _ => policies = Some(folder),
                }
                ViewController::Policy(name)
            }
        };
        let policies = policies.or_else(|| {
            let default = PathBuf::from("policies");
            default.is_dir().then_some(default)
        });
        let mut allowed = Allowed {
            arena_files: self.arena_files,
            ..Allowed::default()
        };
        if let Some(ArenaChoice::File(path)) = &choices.world.arena {
            allowed.arena_files.push(path.clone());
        }
        if let FieldSource::Image(path) = &choices.world.field {
            allowed.field_file = Some(path.clone());
        }
        sensor_files(&choices.world.sensors, &mut allowed.sensor_files);
        Ok(ViewOptions {
            bind,
            settings: ViewSettings::from_choices(&choices, controller),
            policies,
            allowed,
            paused: self.paused,
            speed: self.speed,
        })
    }
}

/// A policy file's folder and name.
fn split_policy(path: &Path) -> Result<(PathBuf, String)> {
    let name = path
        .file_name()
        .and_then(|n| n.to_str())
        .filter(|n| view::settings::valid_name(n));
    let Some(name) = name else {
        bail!(
            "--controller policy:{}: the page names policies by file name, of letters, digits, '.', '-' and '_'",
            path.display()
        );
    };
    let folder = match path.parent() {
        Some(p) if !p.as_os_str().is_empty() => p.to_path_buf(),
        _ => PathBuf::from("."),
    };
    Ok((folder, name.to_string()))
}

fn sensor_files(sensors: &SensorChoice, out: &mut Vec<PathBuf>) {
    match sensors {
        SensorChoice::Robot(Some(path)) => out.push(path.clone()),
        SensorChoice::Mixed(parts) => parts.iter().for_each(|p| sensor_files(p, out)),
        _ => {}
    }
}
