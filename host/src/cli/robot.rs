//! Real robots: `host monitor`, `host replay` and `host flash`.

use clap::Args;
use host::robot::replay::odometry::OdometrySettings;
use shared::StateHasher;
use sim::base::ranges;
use std::path::PathBuf;

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
    /// How the wheel encoders' counts become motion.
    #[command(flatten)]
    pub odometry: OdometryArgs,
}

/// The geometry that turns wheel encoder counts into motion (`host replay`,
/// `host view --log`).
#[derive(Args)]
pub struct OdometryArgs {
    /// Millimetres per simulator unit (a tenth of the robot radius; 6.5 for
    /// the Zumo in its 65 mm skirt on the TV arena).
    #[arg(long, default_value_t = 6.5)]
    pub mm_per_unit: f64,
    /// Wheel encoder counts per millimetre of track travel (909.7 / 119 on 75:1 motors).
    #[arg(long, default_value_t = 909.7 / 119.0)]
    pub counts_per_mm: f64,
    /// Distance between the tracks' centre lines, mm.
    #[arg(long, default_value_t = 85.0)]
    pub track_mm: f64,
}

impl OdometryArgs {
    /// The settings; errors name the flag out of its range.
    pub fn settings(&self) -> anyhow::Result<OdometrySettings> {
        ranges::UNIT_MM.check_as("--mm-per-unit", self.mm_per_unit)?;
        ranges::COUNTS_PER_MM.check(self.counts_per_mm)?;
        ranges::TRACK_MM.check(self.track_mm)?;
        Ok(OdometrySettings {
            mm_per_unit: self.mm_per_unit,
            counts_per_mm: self.counts_per_mm,
            track_mm: self.track_mm,
        })
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
    /// Flash a policy whose blob says it was trained for another sensor
    /// model than the robot's (refused otherwise).
    #[arg(long)]
    pub any_sensors: bool,
}

fn parse_hasher(s: &str) -> Result<StateHasher, String> {
    StateHasher::from_name(s)
        .ok_or_else(|| format!("{s:?} is not a hasher ({})", StateHasher::NAMES))
}
