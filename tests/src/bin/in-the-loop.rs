//! `in-the-loop`: the simulated world driven by the firmware's release ELF,
//! one simavr instance per robot (`tests::in_the_loop`,
//! `docs/in-the-loop.md`).
//!
//! ```sh
//! cargo run --release -p tests --bin in-the-loop -- --elf ELF --policy FILE \
//!     --field F --steps N --seed S --json
//! ```
//! The world's flags are `host run`'s (`--field`, `--arena`, `--robots`,
//! `--pucks`, `--noise`, `--seed`; the sensors are the robot's). `--policy`
//! is the blob the ELF was built with (checked: the ELF must embed its
//! table). Prints `host run`'s summary with the loop's counters, as text
//! or one JSON object; with `--compare`, also `host run`'s own summary of
//! the same scenario driven by the simulator's policy controller (as
//! `simulator`). The firmware's busy wait for the next period is
//! fast-forwarded (`Zumo::skip_waits`: the same frames, counters and
//! world) unless `--simulate-waits` is given.

use anyhow::{Context, Result};
use clap::Parser;
use host::run_summary::run_timed;
use serde::Serialize;
use sim::fields::source::FieldSource;
use sim::scenario::arena_choice::ArenaChoice;
use std::path::PathBuf;
use std::process::ExitCode;
use tests::in_the_loop::{InTheLoop, LoopSummary, World};

/// The firmware in the loop of the simulated world.
#[derive(Parser)]
#[command(name = "in-the-loop")]
struct Args {
    /// The firmware's release ELF (scripts/build-firmware).
    #[arg(long)]
    elf: PathBuf,
    /// The policy blob the ELF embeds.
    #[arg(long)]
    policy: PathBuf,
    /// The field, as `host run --field` takes it.
    #[arg(long, default_value = "annulus")]
    field: FieldSource,
    /// The arena, as `host run --arena` [default: tv75].
    #[arg(long)]
    arena: Option<ArenaChoice>,
    /// Number of robots [default: the arena's].
    #[arg(long)]
    robots: Option<usize>,
    /// Number of pucks [default: the arena's].
    #[arg(long)]
    pucks: Option<usize>,
    /// Real-world noise in multiples of the default, as `host run --noise`.
    #[arg(long, default_value_t = 0.0)]
    noise: f64,
    /// Seed of every random choice.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Steps (control periods) to run.
    #[arg(long)]
    steps: u64,
    /// Print one JSON object instead of text.
    #[arg(long)]
    json: bool,
    /// Also run the same scenario with the simulator's policy controller.
    #[arg(long)]
    compare: bool,
    /// Simulate the firmware's busy wait for the next period cycle by
    /// cycle instead of fast-forwarding it (the same results, slower).
    #[arg(long)]
    simulate_waits: bool,
}

/// What `--json` prints: the settings, the loop's summary, `host run`'s.
#[derive(Serialize)]
struct Output {
    field: String,
    policy: PathBuf,
    elf: PathBuf,
    seed: u64,
    robots: Option<usize>,
    noise: f64,
    #[serde(flatten)]
    run: LoopSummary,
    #[serde(skip_serializing_if = "Option::is_none")]
    simulator: Option<host::run_summary::RunSummary>,
}

fn main() -> ExitCode {
    match run(Args::parse()) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("in-the-loop: {e:#}");
            ExitCode::FAILURE
        }
    }
}

fn run(args: Args) -> Result<()> {
    let policy = sim::control::policy_file::read(&args.policy)
        .with_context(|| format!("reading the policy {}", args.policy.display()))?;
    tests::equivalence::check_elf_embeds(&args.elf, &policy, "scripts/build-firmware")?;
    let scenario = World {
        field: args.field.clone(),
        arena: args.arena,
        robots: args.robots,
        pucks: args.pucks,
        noise: args.noise,
        seed: args.seed,
    }
    .scenario()?;
    let simulator = if args.compare {
        let (mut sim, mut controller) = scenario.build_with_policy(policy.clone())?;
        Some(run_timed(&mut sim, &mut controller, args.steps))
    } else {
        None
    };
    let mut in_the_loop = InTheLoop::new(&args.elf, &policy, &scenario)
        .with_context(|| format!("starting the firmware {}", args.elf.display()))?;
    in_the_loop.skip_waits(!args.simulate_waits);
    let summary = in_the_loop.run(args.steps)?;
    let output = Output {
        field: args.field.to_string(),
        policy: args.policy,
        elf: args.elf,
        seed: args.seed,
        robots: args.robots,
        noise: args.noise,
        run: summary,
        simulator,
    };
    if args.json {
        println!("{}", serde_json::to_string(&output)?);
    } else {
        println!("{}", serde_json::to_string_pretty(&output)?);
    }
    Ok(())
}
