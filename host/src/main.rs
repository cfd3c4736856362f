use anyhow::{Context, Result};
use clap::{Args, Parser, Subcommand};
use host::bench::BenchVariant;
use host::render::RenderOptions;
use host::scenario::{run_timed, ControllerChoice, Scenario};
use host::sim::{BroadPhase, FieldSource};
use std::io::Write;
use std::path::PathBuf;
use std::process::ExitCode;

/// Simulate, train and inspect policies for Zumo puck-construction swarms.
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
        }
    }
}

fn parse_controller(s: &str) -> Result<ControllerChoice, String> {
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
    }
}
