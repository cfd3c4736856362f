//! Simulating: the scenario flags `run`, `render` and `bench` share, and
//! their own options.

use anyhow::Result;
use clap::Args;
use host::bench::BenchVariant;
use sim::config::BroadPhase;
use sim::fields::source::FieldSource;
use sim::scenario::arena_choice::ArenaChoice;
use sim::scenario::sensor_choice::SensorChoice;
use sim::scenario::{ControllerChoice, Scenario};
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

/// What to simulate.
#[derive(Args)]
pub struct ScenarioArgs {
    /// oc, random or policy:FILE.
    #[arg(long, default_value = "oc")]
    pub controller: ControllerChoice,
    /// annulus, letter:T (our T, I, L, V, X, Z), thesis:T (the thesis' T, L, V, X, Z) or an image file (PNG, JPEG).
    #[arg(long, default_value = "annulus")]
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
    #[arg(long, default_value = "disc")]
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

/// `host run`'s options.
#[derive(Args)]
pub struct RunArgs {
    /// The scenario.
    #[command(flatten)]
    pub scenario: ScenarioArgs,
    /// Steps to run.
    #[arg(long, default_value_t = 200_000)]
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
    /// Steps to run before drawing (or to animate, with --gif).
    #[arg(long, default_value_t = 0)]
    pub steps: u64,
    /// PNG file to write.
    #[arg(long, required_unless_present = "gif")]
    pub out: Option<PathBuf>,
    /// Animated GIF file to write instead, one frame every --every steps.
    #[arg(long)]
    pub gif: Option<PathBuf>,
    /// Steps between GIF frames.
    #[arg(long, default_value_t = 100)]
    pub every: u64,
    /// Image side in pixels.
    #[arg(long, default_value_t = 800)]
    pub size: u32,
    /// Draw each robot's sensor discs and field points.
    #[arg(long)]
    pub footprints: bool,
}
