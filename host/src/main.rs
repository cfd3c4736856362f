use anyhow::{Context, Result};
use clap::{Args, Parser, Subcommand};
use host::bench::BenchVariant;
use host::render::RenderOptions;
use host::scenario::{run_timed, ControllerChoice, Scenario};
use host::sensor_choice::SensorChoice;
use host::sim::{BroadPhase, FieldSource};
use shared::StateHasher;
use std::io::Write;
use std::path::PathBuf;
use std::process::ExitCode;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

/// Simulate, train and inspect policies for Zumo puck-construction swarms;
/// flash robots, record and replay their logs.
#[derive(Parser)]
#[command(version, about)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
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
    /// 250 pucks, annulus, orbital construction), single-threaded.
    Bench {
        /// All-pairs contact and sensor checks, like the original simulator.
        #[arg(long)]
        naive: bool,
        /// 64 robots and 1,000 pucks (arena enlarged to the same density).
        #[arg(long)]
        scale: bool,
        /// Steps to time.
        #[arg(long, default_value_t = 1_000_000)]
        steps: u64,
    },
    /// Learn a policy with Q-learning: writes <out>/<name>.policy (the greedy
    /// blob for the firmware) and <out>/<name>.ckpt (the complete training
    /// state), and prints formations, stuck episodes, speed and state
    /// coverage. With no arguments: annulus, 8 robots, 250 pucks, Original
    /// hasher, 2,000,000 steps, into out/.
    Train(host::train::TrainArgs),
    /// Run one of the thesis' experiments (trials in parallel, resumable)
    /// and write CSV, JSON, a markdown table beside the thesis' numbers and
    /// PNG figures into --out.
    Experiment(host::experiment::ExperimentArgs),
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
}

/// `host monitor`'s options (docs/robot-logs.md).
#[derive(Args)]
struct MonitorArgs {
    /// Serial port of the robot's TTL adapter or radio, e.g. /dev/ttyUSB0.
    #[arg(long, required_unless_present = "list")]
    port: Option<String>,
    /// Baud rate (the firmware sends 115200 8N1).
    #[arg(long, default_value_t = host::robot::monitor::DEFAULT_BAUD)]
    baud: u32,
    /// Recorded-log file to write (refused if it exists, unless --append).
    #[arg(long, required_unless_present = "list")]
    out: Option<PathBuf>,
    /// Add to an existing recorded log instead of refusing it.
    #[arg(long)]
    append: bool,
    /// Stop after recording this many frames (for scripts and tests).
    #[arg(long)]
    frames: Option<u64>,
    /// List the serial ports and exit.
    #[arg(long)]
    list: bool,
}

/// `host replay`'s options (docs/robot-logs.md).
#[derive(Args)]
struct ReplayArgs {
    /// Recorded log from `host monitor`, or a raw capture of the serial line.
    #[arg(long)]
    log: PathBuf,
    /// The policy blob the robot was flashed with.
    #[arg(long)]
    policy: PathBuf,
    /// The policy's training checkpoint (`host train`'s .ckpt), or a JSON
    /// file of visit counts per state (docs/robot-logs.md): reports the
    /// states the robot met that training never visited.
    #[arg(long)]
    visits: Option<PathBuf>,
    /// Print one JSON object instead of text.
    #[arg(long)]
    json: bool,
}

/// `host flash`'s options (docs/robot-logs.md).
#[derive(Args)]
struct FlashArgs {
    /// The policy blob to embed.
    #[arg(long)]
    policy: PathBuf,
    /// The bootloader's serial port (appears after a double press of reset), e.g. /dev/ttyACM0.
    #[arg(long)]
    port: Option<String>,
    /// Build for this hasher; the policy must use it (default: the policy's own).
    #[arg(long, value_parser = parse_hasher)]
    hasher: Option<StateHasher>,
    /// The zumo-swarm checkout to build in (default: the one around the current directory).
    #[arg(long)]
    repo: Option<PathBuf>,
    /// Validate and print the exact commands; build and write nothing.
    #[arg(long)]
    dry_run: bool,
}

fn parse_hasher(s: &str) -> Result<StateHasher, String> {
    StateHasher::from_name(s).ok_or_else(|| format!("{s:?} is not a hasher (original, original-obstacle, bits7, bits9)"))
}

/// What to simulate.
#[derive(Args)]
struct ScenarioArgs {
    /// oc, random or policy:FILE.
    #[arg(long, default_value = "oc", value_parser = parse_controller)]
    controller: ControllerChoice,
    /// annulus, letter:T (T, I, L, V, X, Z) or an image file (PNG, JPEG).
    #[arg(long, default_value = "annulus", value_parser = parse_field)]
    field: FieldSource,
    /// Number of robots.
    #[arg(long, default_value_t = 8)]
    robots: usize,
    /// Number of pucks.
    #[arg(long, default_value_t = 250)]
    pucks: usize,
    /// Seed of every random choice.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// All-pairs contact checks instead of the spatial grid (same results).
    #[arg(long)]
    naive: bool,
    /// Sensor model: disc (the reference model's discs), disc-thesis (with
    /// the thesis' larger, robots-only obstacle discs), robot (the Zumo's
    /// photo-transistors and Pixy camera, through the firmware's arithmetic)
    /// or robot:CONFIG.json (the same with settings from a JSON file;
    /// docs/robot-sensors.md).
    #[arg(long, default_value = "disc", value_parser = parse_sensors)]
    sensors: SensorChoice,
}

impl ScenarioArgs {
    fn scenario(self) -> Scenario {
        Scenario {
            field: self.field,
            controller: self.controller,
            robots: self.robots,
            pucks: self.pucks,
            seed: self.seed,
            broad_phase: if self.naive { BroadPhase::Naive } else { BroadPhase::Grid },
            arena_size: None,
            sensors: self.sensors,
        }
    }
}

fn parse_controller(s: &str) -> Result<ControllerChoice, String> {
    s.parse()
}

fn parse_sensors(s: &str) -> Result<SensorChoice, String> {
    s.parse()
}

fn parse_field(s: &str) -> Result<FieldSource, String> {
    s.parse().map_err(|e: host::sim::FieldError| e.to_string())
}

#[derive(Subcommand)]
enum PolicyCommand {
    /// Print a blob's header and its state -> action table.
    Inspect {
        /// The policy blob file.
        file: PathBuf,
    },
}

fn main() -> ExitCode {
    match run(Cli::parse()) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::FAILURE
        }
    }
}

fn run(cli: Cli) -> Result<()> {
    match cli.command {
        Command::Run { scenario, steps, json } => {
            let (mut sim, mut controller) = scenario.scenario().build()?;
            let summary = run_timed(&mut sim, &mut controller, steps);
            if json {
                println!("{}", serde_json::to_string(&summary).context("cannot encode the summary")?);
            } else {
                println!("{summary}");
            }
            Ok(())
        }
        Command::Render { scenario, steps, out, gif, every, size, footprints } => {
            let (mut sim, mut controller) = scenario.scenario().build()?;
            let options = RenderOptions { size, footprints };
            if let Some(path) = gif {
                host::render::animate(&mut sim, &mut controller, steps, every, options, &path)?;
            }
            if let Some(path) = out {
                if sim.totals().steps < steps {
                    sim.run(&mut controller, steps);
                }
                host::render::write_png(&sim, options, &path)?;
            }
            Ok(())
        }
        Command::Bench { naive, scale, steps } => {
            let rate = host::bench::run(BenchVariant { naive, scale }, steps)?;
            println!("{rate:.0} steps/s");
            Ok(())
        }
        Command::Train(args) => {
            let report = host::train::train(&args)?;
            println!("{report}");
            Ok(())
        }
        Command::Experiment(args) => {
            let spec = host::experiment::ExperimentSpec::load(&args.experiment)?;
            // progress lines; a closed stdout must not stop the trials
            let log = |line: &str| {
                let _ = writeln!(std::io::stdout().lock(), "{line}");
            };
            let report = host::experiment::run(&spec, &args.options(), &log)?;
            println!(
                "done in {:.0} s: {} trials run, {} skipped; wrote {}",
                report.seconds,
                report.trials_run,
                report.trials_skipped,
                report.outputs.iter().map(|p| p.display().to_string()).collect::<Vec<_>>().join(", ")
            );
            Ok(())
        }
        Command::Policy(PolicyCommand::Inspect { file }) => {
            let blob = host::policy_file::read(&file)?;
            print!("{}", host::inspect::render(&blob));
            Ok(())
        }
        Command::Monitor(args) => monitor(args),
        Command::Replay(args) => {
            let report = host::robot::replay::replay_files(&args.log, &args.policy, args.visits.as_deref())?;
            let text = if args.json {
                serde_json::to_string(&report).context("cannot encode the report")? + "\n"
            } else {
                report.to_string()
            };
            std::io::stdout().write_all(text.as_bytes()).context("cannot write the report")
        }
        Command::Flash(args) => {
            use host::robot::flash;
            let cwd = std::env::current_dir().context("cannot read the current directory")?;
            let plan = flash::FlashPlan::new(&args.policy, args.hasher, args.port, args.repo.as_deref(), &cwd)?;
            if args.dry_run {
                return std::io::stdout().write_all(plan.describe().as_bytes()).context("cannot write the commands");
            }
            let avrdude = flash::find_program("avrdude", std::env::var_os("PATH").as_deref());
            flash::flash(&plan, avrdude.as_deref(), flash::PORT_WAIT, &mut std::io::stdout())
        }
    }
}

fn monitor(args: MonitorArgs) -> Result<()> {
    use host::robot::monitor::{self, MonitorOptions, SerialOpener, StatusPrinter};
    if args.list {
        for port in monitor::list_ports()? {
            println!("{port}");
        }
        return Ok(());
    }
    let (Some(port), Some(out)) = (args.port, args.out) else {
        anyhow::bail!("--port and --out are required");
    };
    let mut log = host::robot::log_file::LogWriter::create(&out, args.append)?;
    let stop = Arc::new(AtomicBool::new(false));
    let flag = stop.clone();
    ctrlc::set_handler(move || flag.store(true, Ordering::SeqCst)).context("cannot install the Ctrl-C handler")?;
    let mut printer = StatusPrinter::new(std::io::stderr(), &port);
    let options = MonitorOptions { max_frames: args.frames, ..MonitorOptions::default() };
    let mut opener = SerialOpener { port, baud: args.baud };
    let status = monitor::run(&mut opener, &mut log, &options, &stop, &mut |e| printer.show(&e))?;
    printer.finish(&status);
    Ok(())
}
