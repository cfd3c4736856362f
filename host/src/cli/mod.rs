//! The command line: every `clap` type of `host`, by concern, and the
//! conversions from flags into the libraries' plain settings (`main.rs`
//! gives each command its own function).

#[cfg(test)]
mod flag_ranges;
pub mod learn;
pub mod robot;
pub mod scenario;
pub mod screen;
pub mod shape;
pub mod simulate;
pub mod view;

use clap::{Parser, Subcommand};
use learn::{ExperimentArgs, SearchArgs, TrainArgs};
use robot::{FlashArgs, MonitorArgs, ReplayArgs};
use screen::{DisplayArgs, FieldExportArgs, FieldGainArgs, ObserveArgs};
use simulate::{BenchArgs, RenderArgs, RunArgs};
use std::path::PathBuf;
use std::process::ExitCode;
use view::ViewArgs;

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
    Run(RunArgs),
    /// Draw the world (after --steps steps) as a PNG, or animate an episode.
    Render(RenderArgs),
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
    /// Search the policy table directly (cross-entropy method, docs/policy-search.md):
    /// candidates scored by their formations on common worlds, the result
    /// kept only if it forms more on validation worlds; writes
    /// <out>/<name>.policy and <out>/<name>.search.json.
    Search(SearchArgs),
    /// From a picture to a flashable policy and its report card
    /// (docs/shape.md): checks the image and its puck count, searches from
    /// the best of the general table and orbital construction within a
    /// time budget (resumable), and writes <out>/<name>.policy,
    /// .report.json, .report.md and .png.
    Shape(shape::ShapeArgs),
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
    /// Build the firmware with a policy and flash it with avrdude (the
    /// robot's USB port touched at 1200 baud into its bootloader, or a double
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
    /// Serve a live view of a simulation running in this process: the
    /// world on a canvas, play, pause, step, speed, reset and settings
    /// (docs/view.md).
    View(ViewArgs),
}

#[derive(Subcommand)]
pub enum FieldCommand {
    /// Write the exact panel image the simulator's arena model assumes
    /// (one pixel per panel pixel, pre-compensated for the display's gamma).
    Export(FieldExportArgs),
    /// Measure the panel's brightness gain from a robot's logs at the
    /// display's marks, for evening out what it shows (docs/display.md,
    /// "Flat-field correction").
    Gain(FieldGainArgs),
}

#[derive(Subcommand)]
pub enum PolicyCommand {
    /// Print a blob's header and its state -> action table (a column for
    /// the role, for a hasher with the role bit).
    Inspect {
        /// The policy blob file.
        file: PathBuf,
        /// Only the header: hasher, actions, provenance and how many states
        /// choose each action (per role, for a hasher with the role bit).
        #[arg(long)]
        summary: bool,
    },
    /// Measure what a flashed policy keeps of what was learned
    /// (docs/flashed.md): train, then formations of the final window of
    /// learning, of the final table frozen and of the exported blob, per
    /// seed, into a JSON report; with --policy, the blob's only.
    Gap(learn::GapArgs),
    /// Render docs/flashed.md's tables from the report `policy gap` wrote.
    GapTable {
        /// The report.
        #[arg(long)]
        json: PathBuf,
        /// The doc whose generated part is replaced.
        #[arg(long)]
        doc: PathBuf,
    },
}

/// Shows the error of a command line `clap` did not accept and gives the
/// exit code `docs/ranges.md` documents: 0 for `--help` and `--version`;
/// 1 for a refused value (one that does not parse, or is not one of the
/// choices), as for a value refused after parsing; 2 for a command line
/// that cannot be read (an unknown flag, a missing argument).
pub fn refused(e: &clap::Error) -> ExitCode {
    use clap::error::ErrorKind;
    // nothing more can be said if stderr is closed
    let _ = e.print();
    match e.kind() {
        ErrorKind::DisplayHelp | ErrorKind::DisplayVersion => ExitCode::SUCCESS,
        ErrorKind::InvalidValue | ErrorKind::ValueValidation | ErrorKind::InvalidUtf8 => {
            ExitCode::FAILURE
        }
        _ => ExitCode::from(2),
    }
}
