//! The field on the TV: `host field export`, `host field gain`, `host
//! display` and `host observe`.

use super::scenario::train_config_args;
use anyhow::{bail, Result};
use clap::error::ErrorKind;
use clap::{ArgMatches, Args, FromArgMatches};
use host::display::DisplaySettings;
use host::flat_field::MarkGrid;
use host::observe::ObserveSettings;
use host::panel_file::Picture;
use sim::base::gain_grid::GainGrid;
use sim::base::ranges;
use sim::fields::source::FieldSource;
use sim::scenario::arena::ArenaSpec;
use sim::scenario::arena_choice::ArenaChoice;
use sim::scenario::sensor_choice::SensorChoice;
use sim::scenario::sensor_setup::SensorSetup;
use sim::sensors::photo::PhotoSensorConfig;
use std::net::{IpAddr, SocketAddr};
use std::path::PathBuf;

/// The screen and field of the TV tools: a training config's `--arena`
/// (a screen arena; `tv75` by default) and `--field` ([`TrainConfig`]'s
/// fields, declared there once).
#[derive(Clone, Debug)]
pub struct ScreenArgs {
    /// The screen arena.
    pub arena: ArenaChoice,
    /// The field.
    pub field: FieldSource,
}

/// A training config's flags `ids` with these defaults (the help's own
/// "[default: ...]", the training config's, dropped).
fn with_defaults(command: clap::Command, defaults: &[(&str, &'static str)]) -> clap::Command {
    let ids: Vec<&str> = defaults.iter().map(|(id, _)| *id).collect();
    command.args(train_config_args(&ids).into_iter().map(|a| {
        let default = defaults
            .iter()
            .find(|(id, _)| a.get_id() == *id)
            .map_or("", |(_, d)| *d);
        let help = a.get_help().map(|h| h.to_string()).unwrap_or_default();
        let help = help
            .split(" [default:")
            .next()
            .unwrap_or_default()
            .to_string();
        a.default_value(default).help(help)
    }))
}

/// The value of flag `id`, which has a default.
fn value<T: Clone + Send + Sync + 'static>(m: &ArgMatches, id: &str) -> Result<T, clap::Error> {
    m.get_one::<T>(id).cloned().ok_or_else(|| {
        clap::Error::raw(
            ErrorKind::MissingRequiredArgument,
            format!("--{id} is missing"),
        )
    })
}

const SCREEN_DEFAULTS: [(&str, &str); 2] = [("arena", "tv75"), ("field", "annulus")];

impl Args for ScreenArgs {
    fn augment_args(command: clap::Command) -> clap::Command {
        with_defaults(command, &SCREEN_DEFAULTS)
    }

    fn augment_args_for_update(command: clap::Command) -> clap::Command {
        ScreenArgs::augment_args(command)
    }
}

impl FromArgMatches for ScreenArgs {
    fn from_arg_matches(matches: &ArgMatches) -> Result<ScreenArgs, clap::Error> {
        Ok(ScreenArgs {
            arena: value(matches, "arena")?,
            field: value(matches, "field")?,
        })
    }

    fn update_from_arg_matches(&mut self, matches: &ArgMatches) -> Result<(), clap::Error> {
        *self = ScreenArgs::from_arg_matches(matches)?;
        Ok(())
    }
}

/// The robot on the screen whose panel `host field gain` measures: a
/// training config's `--arena` (`tv75` by default) and `--sensors` (a
/// robot model; `robot` by default).
#[derive(Clone, Debug)]
pub struct RobotOnScreenArgs {
    /// The screen arena.
    pub arena: ArenaChoice,
    /// The robot's sensors.
    pub sensors: SensorChoice,
}

const ROBOT_ON_SCREEN_DEFAULTS: [(&str, &str); 2] = [("arena", "tv75"), ("sensors", "robot")];

impl Args for RobotOnScreenArgs {
    fn augment_args(command: clap::Command) -> clap::Command {
        with_defaults(command, &ROBOT_ON_SCREEN_DEFAULTS)
    }

    fn augment_args_for_update(command: clap::Command) -> clap::Command {
        RobotOnScreenArgs::augment_args(command)
    }
}

impl FromArgMatches for RobotOnScreenArgs {
    fn from_arg_matches(matches: &ArgMatches) -> Result<RobotOnScreenArgs, clap::Error> {
        Ok(RobotOnScreenArgs {
            arena: value(matches, "arena")?,
            sensors: value(matches, "sensors")?,
        })
    }

    fn update_from_arg_matches(&mut self, matches: &ArgMatches) -> Result<(), clap::Error> {
        *self = RobotOnScreenArgs::from_arg_matches(matches)?;
        Ok(())
    }
}

/// The panel's measured gain (`host field gain`'s file), for the tools
/// that show the field.
#[derive(Args)]
pub struct GainArgs {
    /// Even out what the panel shows by its measured brightness gain, a
    /// file `host field gain` wrote (docs/display.md, "Flat-field
    /// correction").
    #[arg(long, value_name = "FILE")]
    pub gain: Option<PathBuf>,
}

impl GainArgs {
    /// The gain read, if given.
    pub fn read(&self) -> Result<Option<GainGrid>> {
        self.gain.as_deref().map(host::flat_field::read).transpose()
    }
}

/// The grid of marks the panel's gain is measured at.
#[derive(Args)]
pub struct MarksArgs {
    /// Marks across and down, COLUMNSxROWS, at the centres of equal tiles
    /// of the screen.
    #[arg(long, default_value = "4x3")]
    pub marks: MarkGrid,
}

/// `host field gain`'s options.
#[derive(Args)]
pub struct FieldGainArgs {
    #[command(flatten)]
    pub robot: RobotOnScreenArgs,
    #[command(flatten)]
    pub marks: MarksArgs,
    /// One log per mark, row by row from the top-left (mark 1 first): the
    /// robot standing in the mark on `host display`'s marks screen,
    /// recorded with `host monitor --out`.
    #[arg(required = true, value_name = "LOG")]
    pub logs: Vec<PathBuf>,
    /// Gain file to write.
    #[arg(long)]
    pub out: PathBuf,
}

impl FieldGainArgs {
    /// The arena and the robot's field sensors.
    pub fn robot(&self) -> Result<(ArenaSpec, PhotoSensorConfig)> {
        let arena = self.robot.arena.screen()?;
        match self.robot.sensors.setup()? {
            SensorSetup::Robot(config) => Ok((arena, config.field)),
            _ => bail!(
                "--sensors {}: the gain is measured with a robot's field sensors (robot or robot:FILE)",
                self.robot.sensors
            ),
        }
    }
}

/// `host field export`'s options.
#[derive(Args)]
pub struct FieldExportArgs {
    #[command(flatten)]
    pub screen: ScreenArgs,
    /// Outline the target band in cyan: a colour picture to look at, not
    /// for the TV (the robots would read the outline as field).
    #[arg(long)]
    pub band: bool,
    /// Full white instead of the field: the calibration's white screen
    /// (evened out by --gain), for showing the field from a file.
    #[arg(long, conflicts_with = "band")]
    pub white: bool,
    #[command(flatten)]
    pub gain: GainArgs,
    /// PNG file to write.
    #[arg(long)]
    pub out: PathBuf,
}

impl FieldExportArgs {
    /// Which picture to write.
    pub fn picture(&self) -> Picture {
        match (self.band, self.white) {
            (true, _) => Picture::Band,
            (_, true) => Picture::White,
            _ => Picture::Field,
        }
    }
}

/// `host display`'s options.
#[derive(Args)]
pub struct DisplayArgs {
    #[command(flatten)]
    pub screen: ScreenArgs,
    /// Address to listen on, IP or IP:PORT (0.0.0.0 for the TV's own
    /// browser on the network).
    #[arg(long, default_value = "127.0.0.1", value_parser = parse_bind)]
    pub bind: Bind,
    /// Port, when --bind names none (0: any free port).
    #[arg(long, default_value_t = 8075)]
    pub port: u16,
    /// Seconds the calibration sequence holds white, then black.
    #[arg(long, default_value_t = 3.0)]
    pub hold: f64,
    #[command(flatten)]
    pub gain: GainArgs,
    #[command(flatten)]
    pub marks: MarksArgs,
}

/// `--bind`: an address with or without a port.
#[derive(Clone, Copy, Debug)]
pub enum Bind {
    /// Just the IP.
    Ip(IpAddr),
    /// IP and port.
    Socket(SocketAddr),
}

impl Bind {
    /// The address, `port` when it names none.
    pub fn or_port(self, port: u16) -> SocketAddr {
        match self {
            Bind::Socket(a) => a,
            Bind::Ip(ip) => SocketAddr::new(ip, port),
        }
    }
}

pub(crate) fn parse_bind(s: &str) -> Result<Bind, String> {
    s.parse::<SocketAddr>()
        .map(Bind::Socket)
        .or_else(|_| s.parse::<IpAddr>().map(Bind::Ip))
        .map_err(|_| format!("{s:?} is not an IP address or IP:PORT"))
}

impl DisplayArgs {
    /// The server's settings.
    pub fn settings(self) -> Result<DisplaySettings> {
        let bind = self.bind.or_port(self.port);
        // checked in seconds, as given, before it becomes milliseconds
        ranges::HOLD_S.check(self.hold)?;
        let hold_ms = (self.hold * 1000.0).round() as u32;
        Ok(DisplaySettings {
            arena: self.screen.arena.screen()?,
            gain: self.gain.read()?,
            field: self.screen.field,
            bind,
            hold_ms,
            marks: self.marks.marks,
        })
    }
}

/// `host observe`'s options.
#[derive(Args)]
pub struct ObserveArgs {
    /// Photo of the TV from above (JPEG or PNG).
    #[arg(long)]
    pub photo: PathBuf,
    #[command(flatten)]
    pub screen: ScreenArgs,
    /// The screen's visible corners in the photo, pixels:
    /// x,y of the panel's top-left, top-right, bottom-right, bottom-left.
    #[arg(long, value_parser = parse_corners)]
    pub corners: Corners,
    /// The pucks' colour as the camera sees it, R,G,B [default: the
    /// simulator's drawing's, 200,44,44].
    #[arg(long, value_parser = parse_rgb)]
    pub puck_colour: Option<[u8; 3]>,
    /// PNG to write: the top-down photo with the detected pucks, above
    /// them drawn over the field.
    #[arg(long)]
    pub picture: Option<PathBuf>,
    /// Print one JSON object instead of text.
    #[arg(long)]
    pub json: bool,
}

/// `--corners`: four photo points.
#[derive(Clone, Copy, Debug)]
pub struct Corners(pub [[f64; 2]; 4]);

fn parse_corners(s: &str) -> Result<Corners, String> {
    let numbers: Vec<f64> = s
        .split(|c: char| c == ',' || c.is_whitespace())
        .filter(|t| !t.is_empty())
        .map(|t| t.parse::<f64>().ok().filter(|v| v.is_finite()))
        .collect::<Option<_>>()
        .ok_or_else(|| format!("{s:?}: the corners are 8 numbers x,y,x,y,x,y,x,y"))?;
    let [a, b, c, d, e, f, g, h] = numbers[..] else {
        return Err(format!(
            "{s:?} has {} numbers: the corners are 8, x,y of 4 points",
            numbers.len()
        ));
    };
    Ok(Corners([[a, b], [c, d], [e, f], [g, h]]))
}

fn parse_rgb(s: &str) -> Result<[u8; 3], String> {
    let parts: Option<Vec<u8>> = s.split(',').map(|t| t.trim().parse::<u8>().ok()).collect();
    match parts.as_deref() {
        Some(&[r, g, b]) => Ok([r, g, b]),
        _ => Err(format!("{s:?} is not R,G,B (three numbers 0 to 255)")),
    }
}

impl ObserveArgs {
    /// The measurement's settings.
    pub fn settings(self) -> Result<ObserveSettings> {
        Ok(ObserveSettings {
            photo: self.photo,
            arena: self.screen.arena.screen()?,
            field: self.screen.field,
            corners: self.corners.0,
            puck_colour: self.puck_colour.unwrap_or(sim::render::PUCK.0),
            picture: self.picture,
        })
    }
}
