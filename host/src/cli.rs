//! The command line: every `clap` type of `host`, and the conversions
//! from flags into the libraries' plain settings (`main.rs` dispatches).

use anyhow::Result;
use clap::{Args, Parser, Subcommand};
use host::arena_choice::ArenaChoice;
use host::bench::BenchVariant;
use host::display::DisplaySettings;
use host::experiment::shard::Shard;
use host::experiment::RunOptions;
use host::learn::StateHasherName;
use host::observe::ObserveSettings;
use host::sensor_choice::SensorChoice;
use host::train::selection::SelectConfig;
use host::train::{TrainOverrides, TrainRequest};
use shared::StateHasher;
use sim::reward::Reward;
use sim::scenario::{ControllerChoice, Scenario};
use sim::{BroadPhase, FieldError, FieldSource};
use std::net::{IpAddr, SocketAddr};
use std::path::PathBuf;

/// Simulate, train and inspect policies for Zumo puck-construction swarms;
/// flash robots, record and replay their logs.
#[derive(Parser)]
#[command(version, about)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Command,
}

#[derive(Subcommand)]
pub enum Command {
    /// Run a simulation and print formations, stuck episodes, collisions,
    /// mean Eval and speed.
    Run {
        #[command(flatten)]
        scenario: ScenarioArgs,
        /// Steps to run.
        #[arg(long, default_value_t = 200_000)]
        steps: u64,
        /// Print one JSON object instead of text.
        #[arg(long)]
        json: bool,
    },
    /// Draw the world (after --steps steps) as a PNG, or animate an episode.
    Render {
        #[command(flatten)]
        scenario: ScenarioArgs,
        /// Steps to run before drawing (or to animate, with --gif).
        #[arg(long, default_value_t = 0)]
        steps: u64,
        /// PNG file to write.
        #[arg(long, required_unless_present = "gif")]
        out: Option<PathBuf>,
        /// Animated GIF file to write instead, one frame every --every steps.
        #[arg(long)]
        gif: Option<PathBuf>,
        /// Steps between GIF frames.
        #[arg(long, default_value_t = 100)]
        every: u64,
        /// Image side in pixels.
        #[arg(long, default_value_t = 800)]
        size: u32,
        /// Draw each robot's sensor discs and field points.
        #[arg(long)]
        footprints: bool,
    },
    /// Measure steps per second of the standard configuration (8 robots,
    /// 250 pucks, annulus, orbital construction), single-threaded; with
    /// --sensors robot, the same with the robot's senses and random turns.
    Bench(BenchArgs),
    /// Learn a policy with Q-learning: writes <out>/<name>.policy (the greedy
    /// blob for the firmware) and <out>/<name>.ckpt (the complete training
    /// state), and prints formations, stuck episodes, speed and state
    /// coverage. With no arguments: annulus, 8 robots, 250 pucks, Original
    /// hasher, 2,000,000 steps, into out/.
    Train(TrainArgs),
    /// Run one of the thesis' experiments (trials in parallel, resumable)
    /// and write CSV, JSON, a markdown table beside the thesis' numbers and
    /// PNG figures into --out.
    Experiment(ExperimentArgs),
    /// Work with policy blob files.
    #[command(subcommand)]
    Policy(PolicyCommand),
    /// Record a robot's serial log into a file (each frame with a host
    /// timestamp) with a live status line; survives unplugging, Ctrl-C ends.
    Monitor(MonitorArgs),
    /// Check a recorded log (or a raw serial capture) against a policy:
    /// divergences, state coverage, actions, faults, damaged records.
    Replay(ReplayArgs),
    /// Build the firmware with a policy and flash it with avrdude (double
    /// press of reset); --dry-run prints the commands.
    Flash(FlashArgs),
    /// Work with fields on a screen arena.
    #[command(subcommand)]
    Field(FieldCommand),
    /// Serve the web page that shows the field on the TV, its calibration
    /// sequence and grey patches (docs/display.md).
    Display(DisplayArgs),
    /// Measure a run from a photo of the TV taken from above: the pucks,
    /// Eval and whether the shape is formed (docs/display.md).
    Observe(ObserveArgs),
}

#[derive(Subcommand)]
pub enum FieldCommand {
    /// Write the exact panel image the simulator's arena model assumes
    /// (one pixel per panel pixel, pre-compensated for the display's gamma).
    Export(FieldExportArgs),
}

/// The screen and field of the TV tools.
#[derive(Args)]
pub struct ScreenArgs {
    /// tv75 (the thesis' 75" TV) or a FILE.toml of a screen arena.
    #[arg(long, default_value = "tv75")]
    pub arena: ArenaChoice,
    /// annulus, letter:T (T, I, L, V, X, Z) or an image file (PNG, JPEG).
    #[arg(long, default_value = "annulus", value_parser = parse_field)]
    pub field: FieldSource,
}

/// `host field export`'s options.
#[derive(Args)]
pub struct FieldExportArgs {
    #[command(flatten)]
    pub screen: ScreenArgs,
    /// PNG file to write.
    #[arg(long)]
    pub out: PathBuf,
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
}

/// `--bind`: an address with or without a port.
#[derive(Clone, Copy, Debug)]
pub enum Bind {
    /// Just the IP.
    Ip(IpAddr),
    /// IP and port.
    Socket(SocketAddr),
}

fn parse_bind(s: &str) -> Result<Bind, String> {
    s.parse::<SocketAddr>()
        .map(Bind::Socket)
        .or_else(|_| s.parse::<IpAddr>().map(Bind::Ip))
        .map_err(|_| format!("{s:?} is not an IP address or IP:PORT"))
}

impl DisplayArgs {
    /// The server's settings.
    pub fn settings(self) -> Result<DisplaySettings> {
        let bind = match self.bind {
            Bind::Socket(a) => a,
            Bind::Ip(ip) => SocketAddr::new(ip, self.port),
        };
        let hold_ms = self.hold * 1000.0;
        anyhow::ensure!(
            hold_ms.is_finite() && hold_ms >= 0.0,
            "--hold {}: give a number of seconds, {} to {}",
            self.hold,
            f64::from(host::display::MIN_HOLD_MS) / 1000.0,
            f64::from(host::display::MAX_HOLD_MS) / 1000.0
        );
        Ok(DisplaySettings {
            arena: self.screen.arena.screen()?,
            field: self.screen.field,
            bind,
            hold_ms: hold_ms.round().min(f64::from(u32::MAX)) as u32,
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

/// `host monitor`'s options (docs/robot-logs.md).
#[derive(Args)]
pub struct MonitorArgs {
    /// The robot's USB serial port (/dev/ttyACM0, or its /dev/serial/by-id/ link) or its TTL adapter's or radio's, e.g. /dev/ttyUSB0.
    #[arg(long, required_unless_present = "list")]
    pub port: Option<String>,
    /// Baud rate (the firmware sends 115200 8N1).
    #[arg(long, default_value_t = host::robot::monitor::DEFAULT_BAUD)]
    pub baud: u32,
    /// Recorded-log file to write (refused if it exists, unless --append).
    #[arg(long, required_unless_present = "list")]
    pub out: Option<PathBuf>,
    /// Add to an existing recorded log instead of refusing it.
    #[arg(long)]
    pub append: bool,
    /// Stop after recording this many frames (for scripts and tests).
    #[arg(long)]
    pub frames: Option<u64>,
    /// List the serial ports and exit.
    #[arg(long)]
    pub list: bool,
}

/// `host replay`'s options (docs/robot-logs.md).
#[derive(Args)]
pub struct ReplayArgs {
    /// Recorded log from `host monitor`, or a raw capture of the serial line.
    #[arg(long)]
    pub log: PathBuf,
    /// The policy blob the robot was flashed with.
    #[arg(long)]
    pub policy: PathBuf,
    /// The policy's training checkpoint (`host train`'s .ckpt), or a JSON
    /// file of visit counts per state (docs/robot-logs.md): reports the
    /// states the robot met that training never visited.
    #[arg(long)]
    pub visits: Option<PathBuf>,
    /// Print one JSON object instead of text.
    #[arg(long)]
    pub json: bool,
    /// Write each robot's measured wheel_speed_factor and turn_bias to this
    /// JSON file ({"robots": [...]}); an existing fit file keeps its other
    /// robots, so the logs of a swarm merge into one file.
    #[arg(long)]
    pub fit_profile: Option<PathBuf>,
    /// Millimetres per simulator unit (a tenth of the robot radius; 6.5 for
    /// the Zumo in its 65 mm skirt on the TV arena).
    #[arg(long, default_value_t = 6.5, value_parser = parse_positive)]
    pub mm_per_unit: f64,
    /// Wheel encoder counts per millimetre of track travel (909.7 / 119 on 75:1 motors).
    #[arg(long, default_value_t = 909.7 / 119.0, value_parser = parse_positive)]
    pub counts_per_mm: f64,
    /// Distance between the tracks' centre lines, mm.
    #[arg(long, default_value_t = 85.0, value_parser = parse_positive)]
    pub track_mm: f64,
}

/// `host bench`'s options.
#[derive(Args)]
pub struct BenchArgs {
    /// All-pairs contact and sensor checks, like the original simulator.
    #[arg(long)]
    pub naive: bool,
    /// 64 robots and 1,000 pucks (arena enlarged to the same density).
    #[arg(long)]
    pub scale: bool,
    /// disc (the reference model's discs, orbital construction) or
    /// robot (the Zumo's senses with random turns, timed after a
    /// 2,000-step warm-up; also prints the mean number of bodies in
    /// the camera's range).
    #[arg(long, value_enum, default_value_t = BenchSensors::Disc)]
    pub sensors: BenchSensors,
    /// thesis (800 x 800, 8 robots, 250 pucks), tv75 or a FILE.toml of
    /// a screen arena (with its own robots and pucks).
    #[arg(long, default_value = "thesis")]
    pub arena: ArenaChoice,
    /// Steps to time [default: 1,000,000; 20,000 with --sensors robot].
    #[arg(long)]
    pub steps: Option<u64>,
}

impl BenchArgs {
    /// The configuration to measure, an arena file read and checked.
    pub fn variant(&self) -> Result<BenchVariant> {
        let arena = match &self.arena {
            ArenaChoice::Thesis => None,
            other => Some(other.arena()?),
        };
        Ok(BenchVariant {
            naive: self.naive,
            scale: self.scale,
            robot_senses: self.sensors == BenchSensors::Robot,
            arena,
        })
    }

    /// Steps to time.
    pub fn steps(&self) -> u64 {
        let default = if self.sensors == BenchSensors::Robot {
            host::bench::ROBOT_STEPS
        } else {
            1_000_000
        };
        self.steps.unwrap_or(default)
    }
}

/// `host bench --sensors`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum BenchSensors {
    /// The reference model's disc sensors.
    Disc,
    /// The robot's photo-transistors and Pixy camera.
    Robot,
}

fn parse_positive(s: &str) -> Result<f64, String> {
    match s.parse::<f64>() {
        Ok(v) if v.is_finite() && v > 0.0 => Ok(v),
        _ => Err(format!("{s:?} is not a positive number")),
    }
}

/// `host flash`'s options (docs/robot-logs.md).
#[derive(Args)]
pub struct FlashArgs {
    /// The policy blob to embed.
    #[arg(long)]
    pub policy: PathBuf,
    /// The robot's USB serial port (touched at 1200 baud to enter its bootloader), or the bootloader's, e.g. /dev/ttyACM0.
    #[arg(long)]
    pub port: Option<String>,
    /// Build for this hasher; the policy must use it (default: the policy's own).
    #[arg(long, value_parser = parse_hasher)]
    pub hasher: Option<StateHasher>,
    /// The zumo-swarm checkout to build in (default: the one around the current directory).
    #[arg(long)]
    pub repo: Option<PathBuf>,
    /// The robot's id, 0..=255, built into the firmware and sent in every
    /// log frame (default 0: none); give each robot of a swarm its own.
    #[arg(long, default_value_t = 0)]
    pub robot_id: u8,
    /// Validate and print the exact commands; build and write nothing.
    #[arg(long)]
    pub dry_run: bool,
}

fn parse_hasher(s: &str) -> Result<StateHasher, String> {
    StateHasher::from_name(s)
        .ok_or_else(|| format!("{s:?} is not a hasher ({})", StateHasher::NAMES))
}

/// What to simulate.
#[derive(Args)]
pub struct ScenarioArgs {
    /// oc, random or policy:FILE.
    #[arg(long, default_value = "oc", value_parser = parse_controller)]
    pub controller: ControllerChoice,
    /// annulus, letter:T (our T, I, L, V, X, Z), thesis:T (the thesis' T, L, V, X, Z) or an image file (PNG, JPEG).
    #[arg(long, default_value = "annulus", value_parser = parse_field)]
    pub field: FieldSource,
    /// Number of robots [default: the arena's: 8 in the thesis' arena, 5 on tv75].
    #[arg(long)]
    pub robots: Option<usize>,
    /// Number of pucks [default: the arena's: 250 in the thesis' arena, 12 on tv75].
    #[arg(long)]
    pub pucks: Option<usize>,
    /// Seed of every random choice.
    #[arg(long, default_value_t = 1)]
    pub seed: u64,
    /// thesis (the reference model's 800 x 800 square), tv75 (the thesis'
    /// 75" TV lying flat) or a FILE.toml of a screen arena
    /// (docs/robot-sensors.md) [default: tv75 with --sensors robot, else thesis].
    #[arg(long)]
    pub arena: Option<ArenaChoice>,
    /// All-pairs contact checks instead of the spatial grid (same results).
    #[arg(long)]
    pub naive: bool,
    /// Sensor model: disc (the reference model's discs), disc-thesis (with
    /// the thesis' larger, robots-only obstacle discs), robot (the Zumo's
    /// photo-transistors and Pixy camera, through the firmware's arithmetic)
    /// or robot:CONFIG.json (the same with settings from a JSON file;
    /// docs/robot-sensors.md).
    #[arg(long, default_value = "disc", value_parser = parse_sensors)]
    pub sensors: SensorChoice,
    /// Real-world noise, in multiples of the default (0 none, 1 the
    /// default, 2 twice as much; docs/robot-sensors.md): wheel speeds,
    /// turns and timing always, the robot senses' noise with --sensors robot.
    #[arg(long, default_value_t = 0.0)]
    pub noise: f64,
}

impl ScenarioArgs {
    /// The scenario, with robot sensor and arena files read and checked.
    pub fn scenario(self) -> Result<Scenario> {
        let arena = self
            .arena
            .unwrap_or_else(|| ArenaChoice::default_for(self.sensors.is_robot()));
        Ok(Scenario {
            field: self.field,
            controller: self.controller,
            robots: self.robots,
            pucks: self.pucks,
            seed: self.seed,
            broad_phase: if self.naive {
                BroadPhase::Naive
            } else {
                BroadPhase::Grid
            },
            arena: arena.arena()?,
            sensors: self.sensors.setup()?,
            noise: self.noise,
        })
    }
}

fn parse_controller(s: &str) -> Result<ControllerChoice, String> {
    s.parse()
}

fn parse_sensors(s: &str) -> Result<SensorChoice, String> {
    s.parse()
}

fn parse_field(s: &str) -> Result<FieldSource, String> {
    s.parse().map_err(|e: FieldError| e.to_string())
}

#[derive(Subcommand)]
pub enum PolicyCommand {
    /// Print a blob's header and its state -> action table.
    Inspect {
        /// The policy blob file.
        file: PathBuf,
    },
}

/// `host train`'s options.
#[derive(Clone, Debug, Default, Args)]
pub struct TrainArgs {
    /// TOML file with any of the settings (docs/training.md); flags override it.
    #[arg(long)]
    pub config: Option<PathBuf>,
    /// The settings flags.
    #[command(flatten)]
    pub overrides: TrainOverrideArgs,
    /// Steps to run [default: 2000000; when resuming, the checkpoint's run length].
    #[arg(long)]
    pub steps: Option<u64>,
    /// Directory for <name>.policy and <name>.ckpt [default: out].
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Name of the output files and of the policy [default: <field>-<hasher>].
    #[arg(long)]
    pub name: Option<String>,
    /// Steps between checkpoints, 0 for only at the end [default: 1000000].
    #[arg(long)]
    pub checkpoint_every: Option<u64>,
    /// Continue a run from its checkpoint, with its settings, for --steps more steps.
    #[arg(long, conflicts_with_all = ["config", "init_from"])]
    pub resume: Option<PathBuf>,
    /// Start from the Q-table of a checkpoint (the thesis' RL2), or from a
    /// policy blob (its actions preferred); hasher and actions must match.
    #[arg(long)]
    pub init_from: Option<PathBuf>,
}

impl TrainArgs {
    /// The request these flags make.
    pub fn request(self) -> TrainRequest {
        let o = self.overrides;
        TrainRequest {
            config: self.config,
            overrides: TrainOverrides {
                field: o.field,
                sensors: o.sensors,
                arena: o.arena,
                robots: o.robots,
                pucks: o.pucks,
                noise: if o.randomise { Some(1.0) } else { o.noise },
                select: o
                    .select_every
                    .zip(o.select_steps)
                    .map(|(every, steps)| SelectConfig { every, steps }),
                distil_oc: o.distil_oc,
                seed: o.seed,
                hasher: o.hasher,
                reward: o.reward,
                alpha: o.alpha,
                gamma: o.gamma,
                epsilon: o.epsilon,
            },
            steps: self.steps,
            out: self.out,
            name: self.name,
            checkpoint_every: self.checkpoint_every,
            resume: self.resume,
            init_from: self.init_from,
        }
    }
}

/// The `host train` flags that change a training config; each overrides
/// the config file's value when given.
#[derive(Clone, Debug, Default, Args)]
pub struct TrainOverrideArgs {
    /// annulus, letter:T (our T, I, L, V, X, Z), thesis:T (the thesis' T, L, V, X, Z) or an image file (PNG, JPEG).
    #[arg(long, value_parser = parse_field)]
    pub field: Option<FieldSource>,
    /// Sensor model: disc (the reference model's discs), disc-thesis (with
    /// the thesis' larger, robots-only obstacle discs), robot (the Zumo's
    /// photo-transistors and Pixy camera, through the firmware's arithmetic)
    /// or robot:CONFIG.json (docs/robot-sensors.md).
    #[arg(long)]
    pub sensors: Option<SensorChoice>,
    /// thesis (the reference model's 800 x 800 square), tv75 (the thesis'
    /// 75" TV lying flat) or a FILE.toml of a screen arena [default: tv75
    /// with --sensors robot, else thesis].
    #[arg(long)]
    pub arena: Option<ArenaChoice>,
    /// Number of robots [default: the arena's: 8 in the thesis' arena, 5 on tv75].
    #[arg(long)]
    pub robots: Option<usize>,
    /// Number of pucks [default: the arena's: 250 in the thesis' arena, 12 on tv75].
    #[arg(long)]
    pub pucks: Option<usize>,
    /// Train with the default real-world noise (domain randomisation, the
    /// same as --noise 1; docs/robot-sensors.md).
    #[arg(long, conflicts_with = "noise")]
    pub randomise: bool,
    /// Real-world noise in multiples of the default (0 none, 1 the
    /// default, 2 twice as much) [default: 0].
    #[arg(long)]
    pub noise: Option<f64>,
    /// Policy selection: every N training steps, evaluate the greedy
    /// policy on a fixed evaluation world and keep the best as the run's
    /// policy (docs/training.md) [default: none, the last greedy policy].
    #[arg(long, requires = "select_steps")]
    pub select_every: Option<u64>,
    /// Steps of each evaluation of --select-every.
    #[arg(long, requires = "select_every")]
    pub select_steps: Option<u64>,
    /// Start from orbital construction: distil this many of its steps, on
    /// a world of the run's settings, into the table the run starts from
    /// (docs/training.md).
    #[arg(long)]
    pub distil_oc: Option<u64>,
    /// Seed of every random choice [default: 1].
    #[arg(long)]
    pub seed: Option<u64>,
    /// State hasher: original, original-obstacle, bits7, bits9 (or 8, 10,
    /// 7, 9), original-role (innies and outies apart) [default: original].
    #[arg(long)]
    pub hasher: Option<StateHasherName>,
    /// Reward: reference, thesis, collision, collision-spread [default:
    /// reference].
    #[arg(long)]
    pub reward: Option<Reward>,
    /// Learning rate [default: 0.2].
    #[arg(long)]
    pub alpha: Option<f64>,
    /// Discount [default: 0.9].
    #[arg(long)]
    pub gamma: Option<f64>,
    /// Exploration probability [default: 0].
    #[arg(long)]
    pub epsilon: Option<f64>,
}

/// `host experiment`'s arguments: an experiment to run, or `merge` or `report`.
#[derive(Clone, Debug, Args)]
#[command(args_conflicts_with_subcommands = true, subcommand_negates_reqs = true)]
pub struct ExperimentArgs {
    /// `merge` or `report` instead of a run.
    #[command(subcommand)]
    pub action: Option<ExperimentAction>,
    /// The run.
    #[command(flatten)]
    pub run: ExperimentRunArgs,
}

/// What `host experiment` does besides running one.
#[derive(Clone, Debug, Subcommand)]
pub enum ExperimentAction {
    /// Join the output directories of the shards of one run (`--shard K/N`,
    /// every K from 0 to N-1) into the outputs an unsharded run writes.
    Merge {
        /// The shards' output directories.
        #[arg(required = true)]
        dirs: Vec<PathBuf>,
        /// Output directory [default: out/experiments/<name>].
        #[arg(long)]
        out: Option<PathBuf>,
    },
    /// From the published trials (<docs>/<document>/<name>/trials/): every
    /// experiment's table.md, trials.csv and figures, and the documents
    /// <docs>/reproduction.md and <docs>/robot-sensors.md from their
    /// templates (<docs>/<document>/template.md). Run from the repository
    /// root.
    Report {
        /// The docs directory.
        #[arg(long, default_value = "docs")]
        docs: PathBuf,
        /// Write nothing; fail if a document is not what the trials give.
        #[arg(long, conflicts_with = "scale")]
        check: bool,
        /// The scale the published trials ran at (another than 1 renders a
        /// quick run's page).
        #[arg(long, default_value_t = 1.0)]
        scale: f64,
        /// Only these documents: reproduction, robot-sensors [default: both].
        documents: Vec<String>,
    },
}

/// `host experiment NAME`'s options.
#[derive(Clone, Debug, Args)]
pub struct ExperimentRunArgs {
    /// annulus, transfer, letters, letters-generated, state-bits, obstacle,
    /// collisions (the files of experiments/, built in), or the path of a
    /// TOML file.
    #[arg(required = true)]
    pub experiment: Option<String>,
    /// Trials per arm.
    #[arg(long, default_value_t = 10)]
    pub trials: usize,
    /// Fraction of the thesis' step counts, for quick runs (e.g. 0.001).
    #[arg(long, default_value_t = 1.0)]
    pub scale: f64,
    /// Output directory [default: out/experiments/<name>, with --shard
    /// out/experiments/<name>/shard-K-of-N].
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Experiment seed, from which every trial's seed derives [default: the file's].
    #[arg(long)]
    pub seed: Option<u64>,
    /// Worker threads [default: one per core].
    #[arg(long)]
    pub threads: Option<usize>,
    /// Run only shard K of N (K from 0): every N-th trial, with the seeds of
    /// the whole run; `host experiment merge` joins the shards.
    #[arg(long)]
    pub shard: Option<Shard>,
    /// Another run's output directory (repeatable): its trials of the same
    /// settings (config hash) are copied instead of run.
    #[arg(long, value_name = "DIR")]
    pub reuse: Vec<PathBuf>,
}

impl ExperimentRunArgs {
    /// The run options these arguments give.
    pub fn options(&self) -> RunOptions {
        RunOptions {
            trials: self.trials,
            scale: self.scale,
            out: self.out.clone(),
            seed: self.seed,
            threads: self.threads,
            shard: self.shard,
            reuse: self.reuse.clone(),
        }
    }
}
