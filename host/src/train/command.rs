//! `host train`: settings from a file and flags, a new or resumed run with
//! a progress bar (and with `--view` the live view's page, [`super::watch`]),
//! periodic atomic checkpoints, the policy blob, and a summary beside
//! orbital construction's formations on the same settings.
//!
//! Nothing is lost. A new run whose `<name>.policy` or `<name>.ckpt`
//! already exists keeps them as `<name>.N.policy` and `<name>.N.ckpt` (the
//! smallest N free for both) and says so on stderr; a resumed run replaces
//! the files of the checkpoint it continues. When the request's stop flag
//! is raised (Ctrl-C or SIGTERM, installed by `main`), the run stops at the
//! next chunk boundary and writes the policy and checkpoint of the state
//! reached, atomically, as at the end. With `--view` the page keeps serving
//! the final state until the stop flag is raised.

use super::checkpoint;
use super::config::{TrainConfig, TrainFlags};
use super::trainer::{Trainer, TrainingState};
use super::watch::TrainingView;
use crate::learn::{QTable, TableSummary};
use anyhow::{bail, Context, Result};
use indicatif::{HumanCount, ProgressBar, ProgressDrawTarget, ProgressState, ProgressStyle};
use shared::PolicyBlob;
use sim::base::ranges;
use sim::control::orbital::{OrbitalConfig, OrbitalConstruction};
use sim::scenario::sensor_setup::SelectedSensors;
use std::fmt;
use std::io::{IsTerminal, Write};
use std::net::SocketAddr;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

/// Steps between progress-bar updates.
const PROGRESS_CHUNK: u64 = 20_000;

/// What `host train` is asked to do (the CLI's flags, as plain settings).
#[derive(Clone, Debug, Default)]
pub struct TrainRequest {
    /// TOML file with any of the settings; the flags win over it.
    pub config: Option<PathBuf>,
    /// Settings given one by one.
    pub flags: TrainFlags,
    /// The default real-world noise (`--randomise`, the same as `--noise 1`).
    pub randomise: bool,
    /// Continue a run from its checkpoint, with its settings.
    pub resume: Option<PathBuf>,
    /// Start from the Q-table of a checkpoint, or from a policy blob.
    pub init_from: Option<PathBuf>,
    /// Serve the run on the live view's page at this address ([`watch`]).
    pub view: Option<SocketAddr>,
    /// Raised to stop: training ends at the next chunk with its files
    /// written, and a view stops serving.
    pub stop: Option<Arc<AtomicBool>>,
}

/// What a training session did.
#[derive(Clone, Debug, PartialEq)]
pub struct TrainReport {
    /// Steps run in this session.
    pub steps: u64,
    /// Steps this session was asked to run (more than `steps` when
    /// interrupted).
    pub planned: u64,
    /// Stopped by the stop flag before `planned` steps.
    pub interrupted: bool,
    /// Steps since the run began (resumed sessions included).
    pub total_steps: u64,
    /// Formations since the run began.
    pub formations: u64,
    /// Orbital construction's formations on the run's settings and seed in
    /// as many steps (`None` when interrupted).
    pub orbital_formations: Option<u64>,
    /// Stuck episodes since the run began.
    pub stuck: u64,
    /// Speed of this session.
    pub steps_per_second: f64,
    /// States with at least one update.
    pub states_visited: usize,
    /// States of the hasher.
    pub states_total: usize,
    /// The table at the end: actions taken, values, ties.
    pub table: TableSummary,
    /// With policy selection: the training step of the policy written and
    /// its formations in the evaluation.
    pub selected: Option<(u64, u64)>,
    /// The policy blob written.
    pub policy: PathBuf,
    /// The checkpoint written.
    pub checkpoint: PathBuf,
    /// Earlier results this run would have replaced, and where they are
    /// kept.
    pub kept: Vec<(PathBuf, PathBuf)>,
    /// What it trained for: the field, the sensors and the arena.
    pub trained_for: String,
}

impl fmt::Display for TrainReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(
            f,
            "steps                {} (run total {})",
            self.steps, self.total_steps
        )?;
        match self.orbital_formations {
            Some(oc) => writeln!(
                f,
                "formations           {} (orbital construction: {oc} in as many steps, same settings and seed)",
                self.formations
            )?,
            None => writeln!(f, "formations           {}", self.formations)?,
        }
        writeln!(f, "stuck episodes       {}", self.stuck)?;
        writeln!(f, "steps per second     {:.0}", self.steps_per_second)?;
        writeln!(
            f,
            "states visited       {} of {}",
            self.states_visited, self.states_total
        )?;
        let shares: Vec<String> = self
            .table
            .action_shares
            .iter()
            .map(|s| format!("{s:.3}"))
            .collect();
        writeln!(
            f,
            "actions taken        {} (share of each action id)",
            shares.join(" ")
        )?;
        if let Some([min, p10, p25, p50, p75, p90, max]) = self.table.value_percentiles {
            writeln!(
                f,
                "values, visited      min {min:.3}, 10 % {p10:.3}, 25 % {p25:.3}, median {p50:.3}, 75 % {p75:.3}, 90 % {p90:.3}, max {max:.3}"
            )?;
        }
        writeln!(
            f,
            "tied best actions    in {} of the visited states",
            self.table.tied_states
        )?;
        if let Some((step, formations)) = self.selected {
            writeln!(
                f,
                "selected policy      of step {step}: {formations} formations in its evaluation"
            )?;
        }
        for (was, kept) in &self.kept {
            writeln!(
                f,
                "kept                 the previous {} as {}",
                was.display(),
                kept.display()
            )?;
        }
        writeln!(f, "trained for          {}", self.trained_for)?;
        writeln!(
            f,
            "for the robot        `host shape IMAGE --out DIR`: a policy for a shape of your own on the robots' senses on the TV, flashable (docs/shape.md)"
        )?;
        writeln!(f, "policy               {}", self.policy.display())?;
        write!(f, "checkpoint           {}", self.checkpoint.display())?;
        if self.interrupted {
            write!(
                f,
                "\ninterrupted          after {} of {} steps; `host train --resume {} --steps {}` runs the rest",
                self.steps,
                self.planned,
                self.checkpoint.display(),
                self.planned - self.steps
            )?;
        }
        Ok(())
    }
}

/// Runs `host train`, hands the report to `show`, then with `--view`
/// serves the final state until the stop flag is raised.
pub fn train(
    args: &TrainRequest,
    show: impl FnOnce(&TrainReport) -> Result<()>,
) -> Result<TrainReport> {
    let (mut trainer, steps) = match &args.resume {
        Some(path) => resume(args, path)?,
        None => start(args)?,
    };
    if args.resume.is_some() {
        // The output flags apply to a resumed run too.
        let mut config = trainer.config().clone();
        args.flags.apply(&mut config)?;
        *trainer.output_mut() = config.output;
    }
    trainer.config().validate()?;
    // a resumed run's output folder may be another than its checkpoint's
    crate::atomic::check_writable(&trainer.config().output.dir)?;
    let kept = keep_previous(trainer.config(), args.resume.as_deref())?;
    for (was, now) in &kept {
        eprintln!(
            "train: kept the previous {} as {}",
            was.display(),
            now.display()
        );
    }
    let mut view = match args.view {
        Some(bind) => {
            let view = TrainingView::start(bind, &trainer)?;
            // the first line, for whoever opens it (a script reads it)
            println!(
                "view: {} (the exported policy acting: {})",
                view.url(),
                view.greedy_url()
            );
            std::io::stdout()
                .flush()
                .context("cannot write the view's address")?;
            Some(view)
        }
        None => None,
    };
    let never = Arc::new(AtomicBool::new(false));
    let stop = args.stop.as_ref().unwrap_or(&never);
    let mut report = run(&mut trainer, steps, view.as_mut(), stop)?;
    report.kept = kept;
    show(&report)?;
    if let (Some(view), Some(stop)) = (view, &args.stop) {
        if !report.interrupted {
            println!(
                "view: training ended; {} keeps serving its final state until Ctrl-C",
                view.url()
            );
            std::io::stdout()
                .flush()
                .context("cannot write to stdout")?;
            while !stop.load(Ordering::SeqCst) {
                std::thread::sleep(Duration::from_millis(100));
            }
        }
    }
    Ok(report)
}

/// Moves aside a new run's earlier `<name>.policy` and `<name>.ckpt`, to
/// `<name>.N.policy` and `<name>.N.ckpt` with the smallest N free for
/// both; a resumed run replaces the files of the checkpoint it continues.
/// Returns each file moved and where to.
fn keep_previous(config: &TrainConfig, resumed: Option<&Path>) -> Result<Vec<(PathBuf, PathBuf)>> {
    let (dir, name) = (&config.output.dir, config.name());
    let path = |suffix: &str| dir.join(format!("{name}{suffix}"));
    let (policy, checkpoint) = (path(".policy"), path(".ckpt"));
    let same_run = resumed.is_some_and(|r| {
        matches!(
            (r.canonicalize(), checkpoint.canonicalize()),
            (Ok(a), Ok(b)) if a == b
        )
    });
    let present: Vec<&PathBuf> = [&policy, &checkpoint]
        .into_iter()
        .filter(|p| p.exists())
        .collect();
    if same_run || present.is_empty() {
        return Ok(Vec::new());
    }
    let free = (1u64..)
        .find(|n| !path(&format!(".{n}.policy")).exists() && !path(&format!(".{n}.ckpt")).exists())
        .unwrap_or(u64::MAX);
    let mut kept = Vec::new();
    for was in present {
        let suffix = if *was == policy { "policy" } else { "ckpt" };
        let now = path(&format!(".{free}.{suffix}"));
        std::fs::rename(was, &now).with_context(|| {
            format!(
                "cannot keep the previous {} as {}",
                was.display(),
                now.display()
            )
        })?;
        kept.push((was.clone(), now));
    }
    Ok(kept)
}

/// A new run from the config file, the flags and `--init-from`.
fn start(args: &TrainRequest) -> Result<(Trainer<SelectedSensors>, u64)> {
    let mut config = match &args.config {
        Some(path) => TrainConfig::from_file(path)?,
        None => TrainConfig::default(),
    };
    args.flags.apply(&mut config)?;
    if args.randomise {
        config.world.noise = 1.0;
    }
    config.validate()?;
    // before any step (a distillation or a pre-evaluation included)
    crate::atomic::check_writable(&config.output.dir)?;
    let seed_table = args
        .init_from
        .as_deref()
        .map(|path| seed_table(path, &config))
        .transpose()?;
    let steps = config.steps;
    Ok((Trainer::start(config, seed_table)?, steps))
}

/// A run continued from its checkpoint, with its own settings.
fn resume(args: &TrainRequest, path: &Path) -> Result<(Trainer<SelectedSensors>, u64)> {
    let mut given = args.flags.given_settings();
    if args.randomise {
        given.push("--randomise".into());
    }
    if !given.is_empty() {
        bail!(
            "--resume continues a run with the settings in its checkpoint; {} cannot change them",
            given.join(", ")
        );
    }
    let state = checkpoint::load(path)?;
    let steps = args.flags.steps().unwrap_or(state.config.steps);
    let trainer =
        Trainer::restart(state).with_context(|| format!("cannot resume {}", path.display()))?;
    Ok((trainer, steps))
}

/// The Q-table `--init-from` names: a checkpoint's, or one acting like a
/// policy blob (a blob of a coarser state lifted into the run's,
/// [`crate::learn::lift`]). Its hasher and actions must be the run's.
pub fn seed_table(path: &Path, config: &TrainConfig) -> Result<QTable> {
    // a checkpoint or a policy blob: no larger than the larger of the two
    let bytes = ranges::read_file(path, &ranges::CHECKPOINT_FILE)
        .with_context(|| format!("cannot read {}", path.display()))?;
    let learn = &config.learn;
    let (table, speeds) = if bytes.starts_with(&PolicyBlob::MAGIC) {
        let blob = sim::control::policy_file::decode(path, &bytes)?;
        // a greedy table of a coarser state starts a finer one, acting alike
        let policy = crate::learn::lift::lift(blob.table(), learn.hasher.0)
            .unwrap_or_else(|| blob.table().clone());
        let q = QTable::from_policy(&policy, blob.actions().len(), learn.initial_q);
        (q, Some(blob.actions().angular_speeds().to_vec()))
    } else {
        let state: TrainingState = checkpoint::decode(&bytes)
            .with_context(|| format!("checkpoint file {}", path.display()))?;
        (state.learner.table().clone(), None)
    };
    let (hasher, actions) = (table.hasher(), table.num_actions());
    if hasher != learn.hasher.0 || actions != learn.actions.len() {
        bail!(
            "{} was trained with hasher {hasher} and {actions} actions, but this run uses hasher {} and {} actions (a policy blob's table lifts only into a hasher with field bins at least as fine that reads every bit it reads)",
            path.display(),
            learn.hasher.0,
            learn.actions.len()
        );
    }
    if let Some(speeds) = speeds.filter(|s| s != &learn.actions) {
        bail!(
            "policy file {}: its actions {speeds:?} are not this run's {:?}",
            path.display(),
            learn.actions
        );
    }
    Ok(table)
}

/// Runs `steps` steps (fewer when `stop` is raised) with a progress bar,
/// checkpointing on the way, then writes the policy and the final
/// checkpoint; orbital construction runs beside it for the comparison.
fn run(
    trainer: &mut Trainer<SelectedSensors>,
    steps: u64,
    mut view: Option<&mut TrainingView>,
    stop: &Arc<AtomicBool>,
) -> Result<TrainReport> {
    let out = trainer.config().output.clone();
    let name = trainer.config().name();
    let policy_path = out.dir.join(format!("{name}.policy"));
    let checkpoint_path = out.dir.join(format!("{name}.ckpt"));
    let orbital = OrbitalRun::start(trainer.config(), trainer.totals().steps + steps)?;
    let bar = progress_bar(steps);
    let start = Instant::now();
    let mut done = 0;
    while done < steps && !stop.load(Ordering::SeqCst) {
        let total = trainer.totals().steps;
        let mut chunk = PROGRESS_CHUNK.min(steps - done);
        if out.checkpoint_every > 0 {
            chunk = chunk.min(out.checkpoint_every - total % out.checkpoint_every);
        }
        trainer.run(chunk);
        done += chunk;
        if out.checkpoint_every > 0
            && trainer.totals().steps % out.checkpoint_every == 0
            && done < steps
        {
            checkpoint::save(&checkpoint_path, &trainer.state())?;
        }
        if let Some(view) = view.as_deref_mut() {
            view.update(trainer)?;
        }
        let t = trainer.totals();
        bar.set_position(done);
        bar.set_message(format!(
            "formations {}  stuck {}  Eval {:.3}",
            t.formations,
            t.stuck,
            trainer.learner().signal()
        ));
    }
    let seconds = start.elapsed().as_secs_f64();
    bar.finish_and_clear();
    let interrupted = done < steps;
    checkpoint::save(&checkpoint_path, &trainer.state())?;
    crate::policy_file::write(&policy_path, &trainer.policy()?)?;
    let orbital_formations = orbital.finish(interrupted)?;
    let totals = trainer.totals();
    let q = trainer.learner().table();
    Ok(TrainReport {
        steps: done,
        planned: steps,
        interrupted,
        total_steps: totals.steps,
        formations: totals.formations,
        orbital_formations,
        stuck: totals.stuck,
        steps_per_second: if seconds > 0.0 {
            done as f64 / seconds
        } else {
            f64::INFINITY
        },
        states_visited: q.states_visited(),
        states_total: q.hasher().num_states(),
        table: q.summary(),
        selected: trainer.selected().map(|s| (s.step, s.formations)),
        policy: policy_path,
        checkpoint: checkpoint_path,
        kept: Vec::new(),
        trained_for: {
            let c = trainer.config();
            format!(
                "{}, sensors {}, arena {}",
                c.world.field,
                c.world.sensors,
                c.arena_choice()
            )
        },
    })
}

/// Orbital construction on a run's settings and seed, stepped on its own
/// thread for as many steps as the run will have had.
struct OrbitalRun {
    cancel: Arc<AtomicBool>,
    thread: JoinHandle<Result<u64>>,
}

impl OrbitalRun {
    fn start(config: &TrainConfig, steps: u64) -> Result<OrbitalRun> {
        let prepared = config.prepare()?;
        let mut sim = prepared.simulation(config.world.seed)?;
        let mut controller =
            OrbitalConstruction::new(OrbitalConfig::default(), &prepared.config().thresholds);
        let cancel = Arc::new(AtomicBool::new(false));
        let cancelled = cancel.clone();
        let thread = std::thread::Builder::new()
            .name("train-orbital".into())
            .spawn(move || {
                let mut left = steps;
                while left > 0 && !cancelled.load(Ordering::SeqCst) {
                    let chunk = PROGRESS_CHUNK.min(left);
                    sim.run(&mut controller, chunk);
                    left -= chunk;
                }
                Ok(sim.totals().formations)
            })
            .context("cannot start orbital construction's thread")?;
        Ok(OrbitalRun { cancel, thread })
    }

    /// Its formations, or `None` when cancelled (an interrupted run).
    fn finish(self, cancel: bool) -> Result<Option<u64>> {
        self.cancel.store(cancel, Ordering::SeqCst);
        let formations = self
            .thread
            .join()
            .map_err(|_| anyhow::anyhow!("orbital construction's thread panicked"))??;
        Ok((!cancel).then_some(formations))
    }
}

/// A bar on stderr with steps per second, hidden unless both stdout and
/// stderr are terminals.
fn progress_bar(steps: u64) -> ProgressBar {
    let target = if std::io::stdout().is_terminal() && std::io::stderr().is_terminal() {
        ProgressDrawTarget::stderr()
    } else {
        ProgressDrawTarget::hidden()
    };
    let bar = ProgressBar::with_draw_target(Some(steps), target);
    if let Ok(style) = ProgressStyle::with_template(
        "{bar:30} {percent:>3}%  {human_pos}/{human_len} steps  {rate}  {msg}",
    ) {
        bar.set_style(style.with_key(
            "rate",
            |state: &ProgressState, w: &mut dyn std::fmt::Write| {
                let _ = write!(w, "{} steps/s", HumanCount(state.per_sec().round() as u64));
            },
        ));
    }
    bar
}
