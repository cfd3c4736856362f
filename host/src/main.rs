//! `host`: parses the command line ([`cli`]) and runs each command in its
//! own function.

mod cli;

use anyhow::{Context, Result};
use clap::Parser;
use cli::learn::{ExperimentAction, ExperimentArgs, SearchArgs, TrainArgs};
use cli::robot::{FlashArgs, MonitorArgs, ReplayArgs};
use cli::screen::{DisplayArgs, FieldExportArgs, FieldGainArgs, ObserveArgs};
use cli::simulate::{BenchArgs, RenderArgs, RunArgs};
use cli::view::ViewArgs;
use cli::{Cli, Command, FieldCommand, PolicyCommand};
use host::run_summary::run_timed;
use sim::base::ranges;
use sim::render::RenderOptions;
use std::io::Write;
use std::path::Path;
use std::process::ExitCode;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;

fn main() -> ExitCode {
    end_quietly_on_a_closed_pipe();
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) => return cli::refused(&e),
    };
    match run(cli) {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e:#}");
            ExitCode::FAILURE
        }
    }
}

/// A reader that closes our output (`host policy inspect FILE | head -1`)
/// ends the program as it ends other Unix tools, instead of a panic in
/// `println!`: Rust ignores SIGPIPE, this restores its default action.
/// Sockets are unaffected (std sends with `MSG_NOSIGNAL`).
fn end_quietly_on_a_closed_pipe() {
    #[cfg(unix)]
    // SAFETY: called first in `main`, before any thread starts; setting a
    // signal's action to its default has no other precondition.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
}

fn run(cli: Cli) -> Result<()> {
    match cli.command {
        Command::Run(args) => simulate(args),
        Command::Render(args) => render(args),
        Command::Bench(args) => bench(args),
        Command::Train(args) => train(args),
        Command::Search(args) => search(args),
        Command::Shape(args) => shape(args),
        Command::Experiment(args) => experiment(args),
        Command::Policy(PolicyCommand::Inspect { file, summary }) => inspect_policy(&file, summary),
        Command::Policy(PolicyCommand::Gap(args)) => policy_gap(args),
        Command::Policy(PolicyCommand::GapTable { json, doc }) => gap_table(&json, &doc),
        Command::Monitor(args) => monitor(args),
        Command::Replay(args) => replay(args),
        Command::Flash(args) => flash(args),
        Command::Field(FieldCommand::Export(args)) => export_field(args),
        Command::Field(FieldCommand::Gain(args)) => field_gain(args),
        Command::Display(args) => display(args),
        Command::Observe(args) => observe(args),
        Command::View(args) => view(args),
    }
}

fn simulate(args: RunArgs) -> Result<()> {
    ranges::RUN_STEPS.check_count("host run --steps", args.steps)?;
    warn_policy_mismatch(&args.scenario)?;
    let (mut sim, mut controller) = args.scenario.scenario()?.build()?;
    let summary = run_timed(&mut sim, &mut controller, args.steps);
    if args.json {
        println!(
            "{}",
            serde_json::to_string(&summary).context("cannot encode the summary")?
        );
    } else {
        println!("{summary}");
    }
    Ok(())
}

fn render(args: RenderArgs) -> Result<()> {
    use host::render::{animate, run_until_formed, write_png, Drawn};
    let every = args.every();
    ranges::RUN_STEPS.check_count("host render --steps", args.steps)?;
    ranges::FRAME_EVERY.check_count("host render --every", every)?;
    ranges::RENDER_SIZE.check_count("--size", u64::from(args.size))?;
    warn_policy_mismatch(&args.scenario)?;
    let (mut sim, mut controller) = args.scenario.scenario()?.build()?;
    let options = RenderOptions {
        size: args.size,
        footprints: args.footprints,
        band: args.band,
    };
    let legend = if args.band {
        "; the band's edge cyan, the pucks in it green"
    } else {
        ""
    };
    if let Some(path) = &args.gif {
        animate(&mut sim, &mut controller, args.steps, every, options, path)?;
        println!(
            "wrote {} ({} frames, one every {every} steps): at the end {}{legend}",
            path.display(),
            args.steps / every + 1,
            Drawn::now(&sim)
        );
    }
    if let Some(path) = &args.out {
        let (formed, drawn) = if args.until_formed {
            run_until_formed(&mut sim, &mut controller, args.steps)
        } else {
            if sim.totals().steps < args.steps {
                sim.run(&mut controller, args.steps);
            }
            (None, Drawn::now(&sim))
        };
        let (w, h) = write_png(formed.as_ref().unwrap_or(&sim), options, path)?;
        println!("wrote {} ({w} x {h}): {drawn}{legend}", path.display());
    }
    Ok(())
}

/// Warns on stderr when `--controller policy:FILE` was trained for another
/// sensor model or arena than the run's.
fn warn_policy_mismatch(scenario: &cli::scenario::ScenarioArgs) -> Result<()> {
    if let Some(warning) = scenario.policy_mismatch()? {
        eprintln!("warning: {warning}");
    }
    Ok(())
}

fn bench(args: BenchArgs) -> Result<()> {
    ranges::STEPS.check_count("host bench --steps", args.steps())?;
    println!("{}", host::bench::run(&args.variant()?, args.steps())?);
    Ok(())
}

fn train(args: TrainArgs) -> Result<()> {
    let mut request = args.request();
    let stop = Arc::new(AtomicBool::new(false));
    let flag = stop.clone();
    // Ctrl-C and SIGTERM: the state reached is written before exiting
    ctrlc::set_handler(move || flag.store(true, Ordering::SeqCst))
        .context("cannot install the Ctrl-C and SIGTERM handler")?;
    request.stop = Some(stop);
    let report = host::train::train(&request, |report| {
        println!("{report}");
        std::io::stdout()
            .flush()
            .context("cannot write the summary")
    })?;
    if report.interrupted {
        // 128 + SIGINT, as a shell reports a command stopped by Ctrl-C
        std::process::exit(130);
    }
    Ok(())
}

fn search(args: SearchArgs) -> Result<()> {
    let request = args.request();
    let mut progress = host::search::command::Progress::new(request.search.generations, 0);
    let report = host::search::search(&request, &mut |g| {
        progress.generation(g);
        Ok(())
    })?;
    progress.done();
    println!("{report}");
    Ok(())
}

fn shape(args: cli::shape::ShapeArgs) -> Result<()> {
    let report = host::shape::shape(&args.request()?)?;
    print!("{report}");
    Ok(())
}

fn policy_gap(args: cli::learn::GapArgs) -> Result<()> {
    use host::flashed::{measure_learner, measure_policy, GapReport};
    ranges::STEPS.check_count("--window", args.window)?;
    let mut config = match &args.config {
        Some(path) => host::train::TrainConfig::from_file(path)?,
        None => host::train::TrainConfig::default(),
    };
    args.flags.apply(&mut config)?;
    if args.randomise {
        config.world.noise = 1.0;
    }
    config.validate()?;
    let blob = args
        .policy
        .as_deref()
        .map(sim::control::policy_file::read)
        .transpose()?;
    let mut report = GapReport::load(&args.json)?;
    let mut rows = Vec::new();
    for &seed in &args.seeds {
        config.world.seed = seed;
        let row = match &blob {
            Some(blob) => measure_policy(&args.label, blob, &config, args.window)?,
            None => measure_learner(&args.label, &config, args.window)?,
        };
        eprintln!("{}: seed {seed}: {row:?}", args.label);
        rows.push(row);
    }
    // as a shell would take it back: arguments with spaces quoted
    let command: Vec<String> = std::env::args()
        .skip(1)
        .map(|a| if a.contains(' ') { format!("'{a}'") } else { a })
        .collect();
    report.replace(&args.label, format!("host {}", command.join(" ")), rows);
    report.save(&args.json)
}

fn gap_table(json: &Path, doc: &Path) -> Result<()> {
    let report = host::flashed::GapReport::load(json)?;
    let text =
        std::fs::read_to_string(doc).with_context(|| format!("cannot read {}", doc.display()))?;
    let spliced = host::flashed::splice(&text, &host::flashed::render(&report))
        .with_context(|| format!("doc {}", doc.display()))?;
    host::atomic::write(doc, spliced.as_bytes())
}

fn inspect_policy(file: &Path, summary: bool) -> Result<()> {
    let blob = sim::control::policy_file::read(file)?;
    let text = if summary {
        host::inspect::summary(&blob)
    } else {
        host::inspect::render(&blob)
    };
    print!("{}", host::inspect::with_search_log(&text, &blob, file));
    Ok(())
}

fn replay(args: ReplayArgs) -> Result<()> {
    use host::robot::replay::{odometry, replay_files};
    let settings = args.odometry.settings()?;
    let report = replay_files(&args.log, &args.policy, args.visits.as_deref(), settings)?;
    if let Some(path) = &args.fit_profile {
        let file = odometry::merge_into_file(path, &report.motion)?;
        eprintln!(
            "replay: wrote {} ({} robots)",
            path.display(),
            file.robots.len()
        );
    }
    let text = if args.json {
        serde_json::to_string(&report).context("cannot encode the report")? + "\n"
    } else {
        report.to_string()
    };
    std::io::stdout()
        .write_all(text.as_bytes())
        .context("cannot write the report")
}

fn flash(args: FlashArgs) -> Result<()> {
    use host::robot::flash;
    if let Some(warning) = flash::check_trained_for(&args.policy, args.any_sensors)? {
        eprintln!("warning: {warning}");
    }
    let cwd = std::env::current_dir().context("cannot read the current directory")?;
    let plan = flash::FlashPlan::new(
        &args.policy,
        args.hasher,
        args.port,
        args.repo.as_deref(),
        &cwd,
    )?
    .for_robot(args.robot_id);
    if args.dry_run {
        return std::io::stdout()
            .write_all(plan.describe().as_bytes())
            .context("cannot write the commands");
    }
    let avrdude = flash::find_program("avrdude", std::env::var_os("PATH").as_deref());
    flash::flash(
        &plan,
        avrdude.as_deref(),
        flash::PORT_WAIT,
        &mut std::io::stdout(),
    )
}

fn export_field(args: FieldExportArgs) -> Result<()> {
    let arena = args.screen.arena.screen()?;
    let gain = args.gain.read()?;
    let picture = args.picture();
    let (w, h) = host::panel_file::export(
        &arena,
        &args.screen.field,
        picture,
        gain.as_ref(),
        &args.out,
    )?;
    let what = match picture {
        host::panel_file::Picture::White => "full white".to_string(),
        _ => args.screen.field.to_string(),
    };
    let flat = if gain.is_some() {
        ", evened out for the panel's gain"
    } else {
        ""
    };
    println!(
        "wrote {} ({w} x {h}: {what} on {}{flat})",
        args.out.display(),
        arena.name
    );
    Ok(())
}

fn field_gain(args: FieldGainArgs) -> Result<()> {
    let (arena, photo) = args.robot()?;
    let grid = host::flat_field::measure(&arena, args.marks.marks, &photo, &args.logs)?;
    let (least, most) = (
        grid.min(),
        grid.gains.iter().copied().fold(f64::NEG_INFINITY, f64::max),
    );
    host::flat_field::write(
        &args.out,
        &grid,
        &format!(
            "brightness gain of {}'s panel at {} marks, measured by host field gain from {} logs",
            arena.name,
            args.marks.marks,
            args.logs.len()
        ),
    )?;
    println!(
        "wrote {}: gains {least:.3} to {most:.3} of the mean at {} marks; `host display --gain {}` evens the panel out",
        args.out.display(),
        args.marks.marks,
        args.out.display()
    );
    Ok(())
}

fn display(args: DisplayArgs) -> Result<()> {
    let display = host::display::Display::start(&args.settings()?)?;
    let url = display.url();
    // The first line names the address (scripts and tests read it).
    println!("display: serving {url}");
    println!("  field: {url}   calibration: {url}?mode=calibrate   grey patches: {url}?mode=grey");
    println!("  on the page: c calibration, f field, g grey patches, Enter or click full-screen, h help; here: Ctrl-C stops");
    std::io::stdout()
        .flush()
        .context("cannot write to stdout")?;
    display.serve();
    Ok(())
}

fn view(args: ViewArgs) -> Result<()> {
    if let (Some(log), Some(policy)) = (&args.log, &args.policy) {
        return view_log(log, policy, &args);
    }
    warn_policy_mismatch(&args.scenario)?;
    let view = view::View::start(args.options()?).map_err(anyhow::Error::msg)?;
    let url = view.url();
    // The first line names the address (scripts and tests read it).
    println!("view: serving {url}");
    println!(
        "  on the page: space play/pause, s step, 1 2 3 speed, r reset, n next seed, h help; here: Ctrl-C stops"
    );
    std::io::stdout()
        .flush()
        .context("cannot write to stdout")?;
    view.serve();
    Ok(())
}

fn view_log(log: &Path, policy: &Path, args: &ViewArgs) -> Result<()> {
    let played = host::robot::log_view::log_view(
        log,
        policy,
        &args.log_scenario()?,
        args.odometry.settings()?,
    )?;
    let bind = args.bind.or_port(args.port);
    let view = view::RecordingView::listen(bind, played.document, played.field_png)
        .map_err(anyhow::Error::msg)?;
    // The first line names the address (scripts and tests read it).
    println!("view: serving {}", view.url());
    println!(
        "  {} frames of {}, {} diverging from {}; on the page: space play/pause, left/right step, d next divergence, h help; here: Ctrl-C stops",
        played.frames,
        log.display(),
        played.diverged,
        policy.display()
    );
    std::io::stdout()
        .flush()
        .context("cannot write to stdout")?;
    view.serve();
    Ok(())
}

fn observe(args: ObserveArgs) -> Result<()> {
    let json = args.json;
    let observation = host::observe::observe(&args.settings()?)?;
    let text = if json {
        serde_json::to_string(&observation).context("cannot encode the observation")? + "\n"
    } else {
        observation.to_string()
    };
    std::io::stdout()
        .write_all(text.as_bytes())
        .context("cannot write the observation")
}

fn experiment(args: ExperimentArgs) -> Result<()> {
    let paths = |paths: &[std::path::PathBuf]| {
        paths
            .iter()
            .map(|p| p.display().to_string())
            .collect::<Vec<_>>()
            .join(", ")
    };
    match args.action {
        Some(ExperimentAction::Merge { dirs, out }) => {
            let report = host::experiment::merge::merge(&dirs, out.as_deref())?;
            println!(
                "merged {} shards into {}: {} trials, {} pre-trained tables; wrote {}",
                dirs.len(),
                report.dir.display(),
                report.trials,
                report.pretrained,
                paths(&report.outputs)
            );
            Ok(())
        }
        Some(ExperimentAction::List { page }) => {
            for (name, text) in host::experiment::spec::BUILT_IN {
                let spec = host::experiment::ExperimentSpec::parse(name, text)?;
                let on = spec.page.as_deref().unwrap_or("-");
                if page.as_deref().is_none_or(|p| p == on) {
                    println!("{name} {} {on}", spec.trials);
                }
            }
            Ok(())
        }
        Some(ExperimentAction::Report {
            docs,
            check,
            scale,
            experiments,
            documents,
        }) => {
            ranges::SCALE.check(scale)?;
            let log = |line: &str| eprintln!("{line}");
            let documents =
                host::experiment::report::documents(&documents, experiments.as_deref())?;
            if check {
                let checked = host::experiment::report::check(&docs, &documents, &log)?;
                println!("{} are what the published trials give", paths(&checked));
            } else {
                let written = host::experiment::report::write(&docs, &documents, scale, &log)?;
                println!("wrote {}", paths(&written));
            }
            Ok(())
        }
        None => {
            let name = args.run.experiment.as_deref().unwrap_or_default();
            if let Some(campaign) = host::experiment::campaign::Campaign::at(name)? {
                return run_campaign(&campaign, &args.run);
            }
            if !args.run.stages.is_empty() {
                anyhow::bail!("--stages: {name} is an experiment, not a campaign with [[stages]]");
            }
            let spec = host::experiment::ExperimentSpec::load(name)?;
            // progress lines; a closed stdout must not stop the trials
            let log = |line: &str| {
                let _ = writeln!(std::io::stdout().lock(), "{line}");
            };
            let report = host::experiment::run(&spec, &args.run.options(spec.trials), &log)?;
            println!(
                "done in {:.0} s: {} trials run, {} skipped, {} copied; wrote {}",
                report.seconds,
                report.trials_run,
                report.trials_skipped,
                report.trials_reused,
                paths(&report.outputs)
            );
            Ok(())
        }
    }
}

/// `host experiment FILE` of a campaign: its stages, into --out
/// [default: out/<campaign>].
fn run_campaign(
    campaign: &host::experiment::campaign::Campaign,
    args: &cli::learn::ExperimentRunArgs,
) -> Result<()> {
    let unused = [
        ("--seed", args.seed.is_some()),
        ("--threads", args.threads.is_some()),
        ("--shard", args.shard.is_some()),
        ("--reuse", !args.reuse.is_empty()),
        ("--view", args.view.is_some()),
    ];
    if let Some((flag, _)) = unused.iter().find(|(_, given)| *given) {
        anyhow::bail!(
            "{flag}: a campaign ({}) takes its seeds and settings from its file",
            campaign.name
        );
    }
    let options = host::experiment::campaign::run::CampaignOptions {
        out: args
            .out
            .clone()
            .unwrap_or_else(|| Path::new("out").join(&campaign.name)),
        scale: args.scale,
        stages: args.stages.clone(),
    };
    let log = |line: &str| {
        let _ = writeln!(std::io::stdout().lock(), "{line}");
    };
    let report = host::experiment::campaign::run(campaign, &options, &log)?;
    println!(
        "done in {:.0} s: {} stages run, {} skipped; outputs in {}",
        report.seconds,
        report.run.len(),
        report.skipped.len(),
        options.out.display()
    );
    Ok(())
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
    ranges::BAUD.check_count("--baud", u64::from(args.baud))?;
    if let Some(frames) = args.frames {
        ranges::MONITOR_FRAMES.check_count("--frames", frames)?;
    }
    let mut opener = SerialOpener {
        port: port.clone(),
        baud: args.baud,
    };
    // before the log is created: a port that can never be read leaves no file
    opener.check()?;
    let mut log = host::robot::log_file::LogWriter::create(&out, args.append)?;
    let stop = Arc::new(AtomicBool::new(false));
    let flag = stop.clone();
    ctrlc::set_handler(move || flag.store(true, Ordering::SeqCst))
        .context("cannot install the Ctrl-C handler")?;
    let mut printer = StatusPrinter::new(std::io::stderr(), &port);
    let options = MonitorOptions {
        max_frames: args.frames,
        ..MonitorOptions::default()
    };
    let status = monitor::run(&mut opener, &mut log, &options, &stop, &mut |e| {
        printer.show(&e)
    })?;
    printer.finish(&status);
    Ok(())
}
