//! Simulating: `run`, `render` and `bench` (the scenario flags the first
//! two share are in [`super::scenario`]).

use super::scenario::ScenarioArgs;
use clap::Args;
use host::bench::BenchVariant;
use sim::scenario::arena_choice::ArenaChoice;
use std::path::PathBuf;

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
    pub fn variant(&self) -> anyhow::Result<BenchVariant> {
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

/// `host run`'s options.
#[derive(Args)]
pub struct RunArgs {
    /// The scenario.
    #[command(flatten)]
    pub scenario: ScenarioArgs,
    /// Steps to run [default: 200,000].
    #[arg(long, default_value_t = 200_000, hide_default_value = true)]
    pub steps: u64,
    /// Print one JSON object instead of text.
    #[arg(long)]
    pub json: bool,
}

/// `host render`'s options.
#[derive(Args)]
pub struct RenderArgs {
    /// The scenario.
    #[command(flatten)]
    pub scenario: ScenarioArgs,
    /// Steps to run before drawing (or to animate, with --gif; with
    /// --until-formed, at most) [default: 200,000].
    #[arg(long, default_value_t = 200_000, hide_default_value = true)]
    pub steps: u64,
    /// PNG file to write.
    #[arg(long, required_unless_present = "gif")]
    pub out: Option<PathBuf>,
    /// Draw the world at the moment the shape first forms (or at the end
    /// of --steps if it never does, which the printed line says).
    #[arg(long, conflicts_with = "gif")]
    pub until_formed: bool,
    /// Animated GIF file to write instead, one frame every --every steps.
    #[arg(long)]
    pub gif: Option<PathBuf>,
    /// Steps between GIF frames [default: --steps / 100, at least 1].
    #[arg(long)]
    pub every: Option<u64>,
    /// Image width in pixels (the height follows the arena's shape).
    #[arg(long, default_value_t = 800)]
    pub size: u32,
    /// Draw each robot's sensor discs and field points.
    #[arg(long)]
    pub footprints: bool,
    /// Outline the target band (cyan), where Eval wants every puck, and
    /// draw the pucks in it green.
    #[arg(long)]
    pub band: bool,
}

impl RenderArgs {
    /// Steps between GIF frames: --every, or 100 frames over --steps.
    pub fn every(&self) -> u64 {
        self.every.unwrap_or((self.steps / 100).max(1))
    }
}
