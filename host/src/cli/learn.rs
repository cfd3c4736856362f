//! Learning: `host train` and `host experiment`.

use super::screen::{parse_bind, Bind};
use clap::{ArgMatches, Args, FromArgMatches, Subcommand};
use host::experiment::shard::Shard;
use host::experiment::RunOptions;
use host::search::{SearchConfig, SearchRequest};
use host::train::{TrainFlags, TrainRequest};
use std::marker::PhantomData;
use std::ops::Deref;
use std::path::PathBuf;

/// `host train`'s options.
#[derive(Clone, Debug, Args)]
pub struct TrainArgs {
    /// TOML file with any of the settings (docs/training.md); flags override it.
    #[arg(long)]
    pub config: Option<PathBuf>,
    /// The settings flags: every field of a training config.
    #[command(flatten)]
    pub flags: TrainFlags,
    /// Train with the default real-world noise (domain randomisation, the
    /// same as --noise 1; docs/robot-sensors.md).
    #[arg(long, conflicts_with = "noise")]
    pub randomise: bool,
    /// Continue a run from its checkpoint, with its settings, for --steps more steps.
    #[arg(long, conflicts_with_all = ["config", "init_from"])]
    pub resume: Option<PathBuf>,
    /// Start from the Q-table of a checkpoint (the thesis' RL2), or from a
    /// policy blob (its actions preferred); hasher and actions must match,
    /// but a blob of a coarser state starts a finer one lifted.
    #[arg(long)]
    pub init_from: Option<PathBuf>,
    /// Show the run on the live view's page at this address, IP or IP:PORT
    /// (port 0: any free one): the world it learns in and beside it the
    /// exported policy acting (docs/view.md). The address is the first line printed.
    #[arg(long, value_name = "ADDRESS", num_args = 0..=1, default_missing_value = "127.0.0.1:8077", value_parser = parse_bind)]
    pub view: Option<Bind>,
}

impl TrainArgs {
    /// The request these flags make.
    pub fn request(self) -> TrainRequest {
        TrainRequest {
            config: self.config,
            flags: self.flags,
            randomise: self.randomise,
            resume: self.resume,
            init_from: self.init_from,
            view: self.view.map(|b| b.or_port(8077)),
            stop: None,
        }
    }
}

/// `host search`'s options.
#[derive(Clone, Debug, Args)]
pub struct SearchArgs {
    /// TOML file of a training config: the world searched in (docs/training.md;
    /// its missing keys a training config's defaults); flags override it.
    #[arg(long)]
    pub config: Option<PathBuf>,
    /// The world's settings: a training config's fields but those only
    /// the learner uses (the table's hasher, the field, sensors, arena,
    /// counts, noise, seed, --out and --name).
    #[command(flatten, next_help_heading = "The world searched in")]
    pub flags: FlagsOf<Search>,
    /// The search's settings.
    #[command(flatten, next_help_heading = "The search")]
    pub search: SearchConfig,
}

impl SearchArgs {
    /// The request these flags make.
    pub fn request(self) -> SearchRequest {
        SearchRequest {
            config: self.config,
            flags: self.flags.0,
            search: self.search,
        }
    }
}

/// `host policy gap`'s arguments: a training run's settings, as `host
/// train` takes them, and what to measure.
#[derive(Clone, Debug, Args)]
pub struct GapArgs {
    /// The rows' label in the report (e.g. annulus, L).
    #[arg(long)]
    pub label: String,
    /// Steps of the final window of training, and of each frozen and
    /// flashed run [default: 1,000,000].
    #[arg(long, default_value_t = 1_000_000, hide_default_value = true)]
    pub window: u64,
    /// The seeds, one training run each (comma-separated).
    #[arg(long, value_delimiter = ',', required = true)]
    pub seeds: Vec<u64>,
    /// The JSON report: this label's rows are replaced, others kept.
    #[arg(long)]
    pub json: PathBuf,
    /// Measure this policy blob (flashed only) instead of training.
    #[arg(long)]
    pub policy: Option<PathBuf>,
    /// TOML file with any of the training settings; flags override it.
    #[arg(long)]
    pub config: Option<PathBuf>,
    /// The training settings flags (but the output's and --seed: --seeds).
    #[command(flatten)]
    pub flags: FlagsOf<Gap>,
    /// The default real-world noise (the same as --noise 1).
    #[arg(long, conflicts_with = "noise")]
    pub randomise: bool,
}

/// Which of a training config's flags a command other than `host train`
/// does not use, and the helps that say what others mean there.
pub trait FlagUse {
    /// The command, for the error on a flag it does not use.
    const COMMAND: &'static str;
    /// The ids of the flags it does not use: hidden from its help and
    /// refused when given.
    const UNUSED: &'static [&'static str];
    /// Helps replaced, by id.
    const HELPS: &'static [(&'static str, &'static str)];
}

/// The helps of `--sensors`, `--arena` and `--noise` where they default
/// to the robot's on the TV at the default noise (`host search`, `host
/// shape`).
pub const ROBOT_WORLD_HELPS: [(&str, &str); 3] = [
    (
        "sensors",
        "Sensor model: robot (the Zumo's photo-transistors and Pixy camera, through the firmware's arithmetic), robot:CONFIG.json, disc or disc-thesis (docs/robot-sensors.md) [default: robot]",
    ),
    (
        "arena",
        "The arena: tv75 (the thesis' 75\" TV lying flat), thesis (the reference model's square) or a FILE.toml of a screen arena [default: tv75]",
    ),
    (
        "noise",
        "Real-world noise in multiples of the default (0 none, 1 the default, 2 twice as much): the robots' motion and the robot senses' readings [default: 1]",
    ),
];

/// `host search`: no training steps, checkpoints or policy selection.
#[derive(Clone, Debug)]
pub enum Search {}

impl FlagUse for Search {
    const COMMAND: &'static str = "host search";
    // the learner's settings: the search learns no Q-values
    const UNUSED: &'static [&'static str] = &[
        "steps",
        "checkpoint_every",
        "select_every",
        "select_steps",
        "alpha",
        "gamma",
        "epsilon",
        "initial_q",
        "reward",
        "tie_tolerance",
        "updates",
        "epsilon_decay",
        "n_step",
    ];
    const HELPS: &'static [(&'static str, &'static str)] = &[
        (
            "out",
            "Directory of <name>.policy and <name>.search.json [default: out]",
        ),
        ROBOT_WORLD_HELPS[0],
        ROBOT_WORLD_HELPS[1],
        ROBOT_WORLD_HELPS[2],
    ];
}

/// `host policy gap`: writes no files, one run per --seeds.
#[derive(Clone, Debug)]
pub enum Gap {}

impl FlagUse for Gap {
    const COMMAND: &'static str = "host policy gap";
    const UNUSED: &'static [&'static str] = &["out", "name", "checkpoint_every", "seed"];
    const HELPS: &'static [(&'static str, &'static str)] = &[(
        "steps",
        "Steps of each training run, its last --window of them the learner's window [default: 2,000,000]",
    )];
}

/// A training config's flags as command `U` takes them ([`FlagUse`]).
#[derive(Clone, Debug)]
pub struct FlagsOf<U>(pub TrainFlags, PhantomData<U>);

impl<U> Deref for FlagsOf<U> {
    type Target = TrainFlags;

    fn deref(&self) -> &TrainFlags {
        &self.0
    }
}

impl<U: FlagUse> Args for FlagsOf<U> {
    fn augment_args(command: clap::Command) -> clap::Command {
        let mut command = TrainFlags::augment_args(command);
        for &id in U::UNUSED {
            let message = format!("{} does not use --{}", U::COMMAND, id.replace('_', "-"));
            let refuse = move |_: &str| Err::<String, String>(message.clone());
            command = command.mut_arg(id, |a| a.hide(true).value_parser(refuse));
        }
        for &(id, help) in U::HELPS {
            command = command.mut_arg(id, |a| a.help(help));
        }
        command
    }

    fn augment_args_for_update(command: clap::Command) -> clap::Command {
        FlagsOf::<U>::augment_args(command)
    }
}

impl<U> FromArgMatches for FlagsOf<U> {
    fn from_arg_matches(matches: &ArgMatches) -> Result<Self, clap::Error> {
        Ok(FlagsOf(TrainFlags::from_arg_matches(matches)?, PhantomData))
    }

    fn update_from_arg_matches(&mut self, matches: &ArgMatches) -> Result<(), clap::Error> {
        self.0.update_from_arg_matches(matches)
    }
}

/// `host experiment`'s arguments: an experiment to run, or `list`, `merge`
/// or `report`.
#[derive(Clone, Debug, Args)]
#[command(args_conflicts_with_subcommands = true, subcommand_negates_reqs = true)]
pub struct ExperimentArgs {
    /// `list`, `merge` or `report` instead of a run.
    #[command(subcommand)]
    pub action: Option<ExperimentAction>,
    /// The run.
    #[command(flatten)]
    pub run: ExperimentRunArgs,
}

/// What `host experiment` does besides running one.
#[derive(Clone, Debug, Subcommand)]
pub enum ExperimentAction {
    /// Join the output directories of the shards of one run (`--shard K/N`,
    /// every K from 0 to N-1) into the outputs an unsharded run writes.
    Merge {
        /// The shards' output directories.
        #[arg(required = true)]
        dirs: Vec<PathBuf>,
        /// Output directory [default: out/experiments/<name>].
        #[arg(long)]
        out: Option<PathBuf>,
    },
    /// The built-in experiments, one a line: the name, the trials per arm
    /// of its published run and its results page.
    List {
        /// Only the experiments of this results page (e.g. robot-sensors).
        #[arg(long)]
        page: Option<String>,
    },
    /// From the published trials (<docs>/<page>/<name>/trials/): every
    /// experiment's table.md, trials.csv, figures and page
    /// (<docs>/<page>/<name>.md), and each results page's index
    /// (<docs>/<page>.md), from their templates (<docs>/<page>/template.md,
    /// <docs>/<page>/<name>/template.md). Run from the repository root.
    Report {
        /// The docs directory.
        #[arg(long, default_value = "docs")]
        docs: PathBuf,
        /// Write nothing; fail if a document is not what the trials give.
        #[arg(long, conflicts_with = "scale")]
        check: bool,
        /// The scale the published trials ran at (another than 1 renders a
        /// quick run's page).
        #[arg(long, default_value_t = 1.0)]
        scale: f64,
        /// The experiments of the `*.toml` files in this directory (each
        /// file's `page` key) instead of the built-in ones.
        #[arg(long, value_name = "DIR")]
        experiments: Option<PathBuf>,
        /// Only these results pages (reproduction, robot-sensors)
        /// [default: every one].
        documents: Vec<String>,
    },
}

/// `host experiment NAME`'s options.
#[derive(Clone, Debug, Args)]
pub struct ExperimentRunArgs {
    /// A built-in experiment (a file of experiments/ by its stem; `host
    /// experiment list` names them) or the path of a TOML file (with
    /// `[[stages]]`: a campaign, experiments/campaigns/,
    /// docs/policy-search.md).
    #[arg(required = true)]
    pub experiment: Option<String>,
    /// Trials per arm [default: the file's `trials`, else 10].
    #[arg(long)]
    pub trials: Option<usize>,
    /// Fraction of the thesis' step counts, for quick runs (0.05: about a
    /// minute for the annulus, long enough for its arms to form shapes); of
    /// a campaign's step and generation counts.
    #[arg(long, default_value_t = 1.0)]
    pub scale: f64,
    /// Output directory [default: out/experiments/<name>, with --shard
    /// out/experiments/<name>/shard-K-of-N].
    #[arg(long)]
    pub out: Option<PathBuf>,
    /// Experiment seed, from which every trial's seed derives [default: the file's].
    #[arg(long)]
    pub seed: Option<u64>,
    /// Worker threads [default: one per core].
    #[arg(long)]
    pub threads: Option<usize>,
    /// Run only shard K of N (K from 0): every N-th trial, with the seeds of
    /// the whole run; `host experiment merge` joins the shards.
    #[arg(long)]
    pub shard: Option<Shard>,
    /// Another run's output directory (repeatable): its trials of the same
    /// settings (config hash) are copied instead of run.
    #[arg(long, value_name = "DIR")]
    pub reuse: Vec<PathBuf>,
    /// A campaign's stages to run (comma-separated), with the stages they
    /// continue from that are not finished [default: every stage].
    #[arg(long, value_delimiter = ',', value_name = "STAGES")]
    pub stages: Vec<String>,
    /// Run the trials one at a time, each shown on the live view's page at
    /// this address, IP or IP:PORT (port 0: any free one; docs/view.md);
    /// the line "view: serving URL" names it.
    #[arg(long, value_name = "ADDRESS", num_args = 0..=1, default_missing_value = "127.0.0.1:8077", value_parser = parse_bind)]
    pub view: Option<Bind>,
}

impl ExperimentRunArgs {
    /// The run options these arguments give, `file_trials` per arm unless
    /// `--trials` says.
    pub fn options(&self, file_trials: usize) -> RunOptions {
        RunOptions {
            trials: self.trials.unwrap_or(file_trials),
            scale: self.scale,
            out: self.out.clone(),
            seed: self.seed,
            threads: self.threads,
            shard: self.shard,
            reuse: self.reuse.clone(),
            view: self.view.map(|b| b.or_port(8077)),
        }
    }
}
