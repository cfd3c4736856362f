//! `host train`: settings from a file and flags, a new or resumed run with
//! a progress bar (and with `--view` the live view's page, [`super::watch`]),
//! periodic atomic checkpoints, the policy blob, and a summary.

use super::checkpoint;
use super::config::{TrainConfig, TrainFlags};
use super::trainer::{Trainer, TrainingState};
use super::watch::TrainingView;
use crate::learn::{QTable, TableSummary};
use anyhow::{bail, Context, Result};
use indicatif::{HumanCount, ProgressBar, ProgressDrawTarget, ProgressState, ProgressStyle};
use shared::PolicyBlob;
use sim::base::ranges;
use sim::scenario::sensor_setup::SelectedSensors;
use std::fmt;
use std::io::{IsTerminal, Write};
use std::net::SocketAddr;
use std::path::{Path, PathBuf};
use std::time::Instant;

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
}

/// What a training session did.
#[derive(Clone, Debug, PartialEq)]
pub struct TrainReport {
    /// Steps run in this session.
    pub steps: u64,
    /// Steps since the run began (resumed sessions included).
    pub total_steps: u64,
    /// Formations since the run began.
    pub formations: u64,
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
}

impl fmt::Display for TrainReport {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        writeln!(
            f,
            "steps                {} (run total {})",
            self.steps, self.total_steps
        )?;
        writeln!(f, "formations           {}", self.formations)?;
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
        writeln!(f, "policy               {}", self.policy.display())?;
        write!(f, "checkpoint           {}", self.checkpoint.display())
    }
}

/// Runs `host train`.
pub fn train(args: &TrainRequest) -> Result<TrainReport> {
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
    run(&mut trainer, steps, view.as_mut())
}

/// A new run from the config file, the flags and `--init-from`.
fn start(args: &TrainRequest) -> Result<(Trainer<SelectedSensors>, u64)> {
    let mut config = match &args.config {
        Some(path) => TrainConfig::from_file(path)?,
        None => TrainConfig::default(),
    };
    args.flags.apply(&mut config)?;
    if args.randomise {
        config.noise = 1.0;
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
/// policy blob. Its hasher and actions must be the run's.
pub fn seed_table(path: &Path, config: &TrainConfig) -> Result<QTable> {
    // a checkpoint or a policy blob: no larger than the larger of the two
    let bytes = ranges::read_file(path, &ranges::CHECKPOINT_FILE)
        .with_context(|| format!("cannot read {}", path.display()))?;
    let learn = &config.learn;
    let (table, speeds) = if bytes.starts_with(&PolicyBlob::MAGIC) {
        let blob = sim::control::policy_file::decode(path, &bytes)?;
        let q = QTable::from_policy(blob.table(), blob.actions().len(), learn.initial_q);
        (q, Some(blob.actions().angular_speeds().to_vec()))
    } else {
        let state: TrainingState = checkpoint::decode(&bytes)
            .with_context(|| format!("checkpoint file {}", path.display()))?;
        (state.learner.table().clone(), None)
    };
    let (hasher, actions) = (table.hasher(), table.num_actions());
    if hasher != learn.hasher.0 || actions != learn.actions.len() {
        bail!(
            "{} was trained with hasher {hasher} and {actions} actions, but this run uses hasher {} and {} actions",
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

/// Runs `steps` steps with a progress bar, checkpointing on the way, then
/// writes the policy and the final checkpoint.
fn run(
    trainer: &mut Trainer<SelectedSensors>,
    steps: u64,
    mut view: Option<&mut TrainingView>,
) -> Result<TrainReport> {
    let out = trainer.config().output.clone();
    let name = trainer.config().name();
    let policy_path = out.dir.join(format!("{name}.policy"));
    let checkpoint_path = out.dir.join(format!("{name}.ckpt"));
    let bar = progress_bar(steps);
    let start = Instant::now();
    let mut done = 0;
    while done < steps {
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
    checkpoint::save(&checkpoint_path, &trainer.state())?;
    crate::policy_file::write(&policy_path, &trainer.policy()?)?;
    let totals = trainer.totals();
    let q = trainer.learner().table();
    Ok(TrainReport {
        steps,
        total_steps: totals.steps,
        formations: totals.formations,
        stuck: totals.stuck,
        steps_per_second: if seconds > 0.0 {
            steps as f64 / seconds
        } else {
            f64::INFINITY
        },
        states_visited: q.states_visited(),
        states_total: q.hasher().num_states(),
        table: q.summary(),
        selected: trainer.selected().map(|s| (s.step, s.formations)),
        policy: policy_path,
        checkpoint: checkpoint_path,
    })
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
