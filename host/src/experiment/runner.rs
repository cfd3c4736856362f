//! Running an experiment: the trials of the same settings that other runs
//! made copied (`--reuse`, [`ReusableTrials`]), the pre-trainings its
//! unfinished trials need, then those trials, in parallel (rayon), each
//! result written atomically when it finishes and skipped on a rerun when
//! its stored config hash matches; then the reports. A shard ([`Shard`])
//! runs every N-th trial of the plan, with the seeds of the whole run, and
//! leaves the reports to `merge`.
//!
//! Layout of the output directory:
//! - `pretrained/<hash>.ckpt`: pre-trained tables (checkpoints);
//! - `trials/<arm>/trial-<NN>.json`: one [`TrialResult`] per trial;
//! - `trials.csv`, `trials.json`, `table.md` and the PNG figures; or, for a
//!   shard, `shard.json` ([`ShardManifest`]).

use super::outputs;
use super::plan::{plans, PretrainPlan, TrialPlan};
use super::reuse::ReusableTrials;
use super::shard::{Shard, ShardManifest};
use super::spec::ExperimentSpec;
use super::trial::{self, TrialResult};
use super::watch::TrialView;
use crate::train::checkpoint;
use anyhow::{bail, Context, Result};
use rayon::prelude::*;
use sim::base::ranges;
use std::collections::BTreeMap;
use std::net::SocketAddr;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::time::Instant;

/// How to run an experiment (`host experiment` options).
#[derive(Clone, Debug, PartialEq)]
pub struct RunOptions {
    /// Trials per arm.
    pub trials: usize,
    /// Fraction of the file's step counts (runs and pre-trainings).
    pub scale: f64,
    /// Output directory; `None` for `out/experiments/<name>`.
    pub out: Option<PathBuf>,
    /// Experiment seed; `None` for the file's.
    pub seed: Option<u64>,
    /// Worker threads; `None` for one per core.
    pub threads: Option<usize>,
    /// Run only this share of the trials; `None` for all.
    pub shard: Option<Shard>,
    /// Other runs' output directories whose trials of the same settings
    /// are copied instead of run.
    pub reuse: Vec<PathBuf>,
    /// Run the trials one at a time, each on the live view's page at this
    /// address ([`TrialView`]); `None` for no view.
    pub view: Option<SocketAddr>,
}

impl Default for RunOptions {
    /// 10 trials at full scale, the default directory, seed and threads,
    /// unsharded, nothing reused.
    fn default() -> RunOptions {
        RunOptions {
            trials: 10,
            scale: 1.0,
            out: None,
            seed: None,
            threads: None,
            shard: None,
            reuse: Vec::new(),
            view: None,
        }
    }
}

/// What a run did.
#[derive(Clone, Debug, PartialEq)]
pub struct RunReport {
    /// The output directory.
    pub dir: PathBuf,
    /// Trials run now.
    pub trials_run: usize,
    /// Trials found finished in the output directory and skipped.
    pub trials_skipped: usize,
    /// Trials copied from other runs (`--reuse`).
    pub trials_reused: usize,
    /// Pre-trainings run now.
    pub pretrained_run: usize,
    /// Pre-trainings found finished and skipped.
    pub pretrained_skipped: usize,
    /// The report files written (a shard's manifest).
    pub outputs: Vec<PathBuf>,
    /// Wall time of the whole run.
    pub seconds: f64,
}

/// A file name for an arm: its name with anything but letters, digits,
/// `-` and `_` replaced by `_`.
pub fn slug(name: &str) -> String {
    name.chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || c == '-' || c == '_' {
                c
            } else {
                '_'
            }
        })
        .collect()
}

/// Progress lines, from any thread.
type Log<'a> = &'a (dyn Fn(&str) + Sync);

/// Runs the experiment: pre-trainings, then trials, then the reports.
pub fn run(spec: &ExperimentSpec, options: &RunOptions, log: Log<'_>) -> Result<RunReport> {
    check_options(spec, options)?;
    let started = Instant::now();
    let default_dir = Path::new("out/experiments").join(&spec.name);
    let dir = match (&options.out, options.shard) {
        (Some(dir), _) => dir.clone(),
        (None, Some(shard)) => default_dir.join(shard.dir_name()),
        (None, None) => default_dir,
    };
    let seed = options.seed.unwrap_or(spec.seed);
    let mut plans = plans(spec, options.trials, options.scale, seed);
    if let Some(shard) = options.shard {
        plans = shard.share(plans);
    }
    log(&format!(
        "experiment {}: {} arms x {} trials, scale {}, seed {seed}{}, writing to {}",
        spec.name,
        spec.arms.len(),
        options.trials,
        options.scale,
        options.shard.map_or_else(String::new, |s| format!(
            ", shard {s}: {} trials",
            plans.len()
        )),
        dir.display()
    ));
    crate::atomic::check_writable(&dir)?;
    let workers = Workers::new(options.threads)?;
    // a shard's manifest first, so that merge can name an unfinished shard
    let manifest = match options.shard {
        Some(shard) => {
            Some(ShardManifest::new(spec, shard, options.trials, options.scale, seed).write(&dir)?)
        }
        None => None,
    };
    let mut finished: Vec<Option<TrialResult>> = plans.iter().map(|p| finished(&dir, p)).collect();
    let skipped = finished.iter().flatten().count();
    let trials_reused = copy_reused(&plans, &mut finished, &options.reuse, &dir, log)?;
    let (pretrained_run, pretrained_skipped) =
        run_pretrainings(&plans, &finished, &dir, &workers, log)?;
    let (results, trials_run) = match options.view {
        None => run_trials(&plans, finished, &dir, &workers, log)?,
        Some(bind) => run_trials_watched(&plans, finished, &dir, TrialView::new(bind), log)?,
    };
    let outputs = match manifest {
        Some(path) => vec![path],
        None => outputs::write(spec, &dir, &results, options.scale, seed)?,
    };
    Ok(RunReport {
        dir,
        trials_run,
        trials_skipped: skipped,
        trials_reused,
        pretrained_run,
        pretrained_skipped,
        outputs,
        seconds: started.elapsed().as_secs_f64(),
    })
}

/// Refuses options that cannot run: trials, scale or threads outside their
/// ranges ([`sim::base::ranges`]), arms whose directories would collide,
/// and any trial's or pre-training's settings that cannot be simulated
/// (each arm's field, arena and sensor files loaded once): all before the
/// first step.
fn check_options(spec: &ExperimentSpec, options: &RunOptions) -> Result<()> {
    ranges::TRIALS.check_count("--trials", options.trials as u64)?;
    ranges::SCALE.check(options.scale)?;
    if let Some(threads) = options.threads {
        ranges::THREADS.check_count("--threads", threads as u64)?;
    }
    let mut slugs = BTreeMap::new();
    for arm in &spec.arms {
        if let Some(other) = slugs.insert(slug(&arm.name), &arm.name) {
            bail!(
                "arms {other:?} and {:?} would share the directory trials/{}",
                arm.name,
                slug(&arm.name)
            );
        }
    }
    check_settings(spec, options.scale, options.seed.unwrap_or(spec.seed))
}

/// Checks every trial's and pre-training's settings of `spec` at `scale`
/// against the plausible ranges and builds each once (its field, arena and
/// sensor files loaded), and reads every arm's policy file: what
/// [`run`] does before its first step. Errors name the arm.
pub fn check_settings(spec: &ExperimentSpec, scale: f64, seed: u64) -> Result<()> {
    for plan in plans(spec, 1, scale, seed) {
        let configs = std::iter::once(&plan.config).chain(plan.pretrain.iter().map(|p| &p.config));
        for config in configs {
            config
                .validate()
                .and_then(|()| config.prepare().map(drop))
                .with_context(|| format!("arm {:?}", plan.arm))?;
        }
        if let Some(policy) = &plan.policy {
            sim::control::policy_file::read(policy)
                .with_context(|| format!("arm {:?}", plan.arm))?;
        }
    }
    Ok(())
}

/// The worker threads: a pool of the given size, or rayon's global one.
struct Workers(Option<rayon::ThreadPool>);

impl Workers {
    fn new(threads: Option<usize>) -> Result<Workers> {
        let pool = match threads {
            Some(n) => Some(
                rayon::ThreadPoolBuilder::new()
                    .num_threads(n)
                    .build()
                    .context("cannot start worker threads")?,
            ),
            None => None,
        };
        Ok(Workers(pool))
    }

    /// Runs `job` (which uses rayon's parallel iterators) on these workers.
    fn run(&self, job: &(dyn Fn() -> Result<()> + Sync)) -> Result<()> {
        match &self.0 {
            Some(p) => p.install(job),
            None => job(),
        }
    }
}

/// Copies into `dir` the unfinished trials that the runs in `reuse` made
/// with the same settings, and marks them finished; returns how many.
fn copy_reused(
    plans: &[TrialPlan],
    finished: &mut [Option<TrialResult>],
    reuse: &[PathBuf],
    dir: &Path,
    log: Log<'_>,
) -> Result<usize> {
    if reuse.is_empty() {
        return Ok(0);
    }
    let reusable = ReusableTrials::load(reuse)?;
    let mut copied = 0;
    for (plan, done) in plans
        .iter()
        .zip(finished.iter_mut())
        .filter(|(_, f)| f.is_none())
    {
        if let Some(result) = reusable.result_for(plan) {
            write_result(&trial_path(dir, plan), &result)?;
            *done = Some(result);
            copied += 1;
        }
    }
    log(&format!(
        "reuse: {copied} trials copied from {} stored in the --reuse directories",
        reusable.stored()
    ));
    Ok(copied)
}

/// Runs each distinct pre-training that an unfinished trial needs and that
/// is not yet stored; returns how many ran and how many were found done.
fn run_pretrainings(
    plans: &[TrialPlan],
    finished: &[Option<TrialResult>],
    dir: &Path,
    workers: &Workers,
    log: Log<'_>,
) -> Result<(usize, usize)> {
    let mut distinct: BTreeMap<&str, &PretrainPlan> = BTreeMap::new();
    for (plan, _) in plans.iter().zip(finished).filter(|(_, f)| f.is_none()) {
        if let Some(p) = &plan.pretrain {
            distinct.insert(&p.hash, p);
        }
    }
    let (done, todo): (Vec<&PretrainPlan>, Vec<&PretrainPlan>) = distinct
        .values()
        .partition(|p| pretrained_table(dir, p).is_ok());
    if !distinct.is_empty() {
        log(&format!(
            "pre-training: {} tables for the trials to run, {} already done (skipped)",
            distinct.len(),
            done.len()
        ));
    }
    let count = AtomicUsize::new(0);
    workers.run(&|| {
        todo.par_iter().try_for_each(|p| {
            let t = trial::pretrain(&p.config)?;
            crate::atomic::create_dirs(&dir.join("pretrained"))?;
            checkpoint::save(&pretrained_path(dir, p), &t.state())?;
            let k = count.fetch_add(1, Ordering::Relaxed) + 1;
            log(&format!(
                "[{k}/{}] pre-trained {} steps: {} formations",
                todo.len(),
                p.config.steps,
                t.totals().formations
            ));
            Ok(())
        })
    })?;
    Ok((todo.len(), done.len()))
}

/// Runs every trial not yet stored (`finished`: the stored results, by
/// plan), each written atomically when it ends; returns every trial's result
/// in plan order and how many ran.
fn run_trials(
    plans: &[TrialPlan],
    finished: Vec<Option<TrialResult>>,
    dir: &Path,
    workers: &Workers,
    log: Log<'_>,
) -> Result<(Vec<TrialResult>, usize)> {
    let mut results = finished;
    let todo = unfinished(&results, log, "");
    let count = AtomicUsize::new(0);
    let fresh = std::sync::Mutex::new(Vec::new());
    workers.run(&|| {
        todo.par_iter().try_for_each(|&i| {
            let plan = &plans[i];
            let result = run_trial(plan, dir, &mut |_, _| Ok(()))?;
            let k = count.fetch_add(1, Ordering::Relaxed) + 1;
            log(&trial_line(k, todo.len(), plan, &result));
            if let Ok(mut f) = fresh.lock() {
                f.push((i, result));
            }
            Ok(())
        })
    })?;
    for (i, r) in fresh.into_inner().unwrap_or_default() {
        results[i] = Some(r);
    }
    Ok((results.into_iter().flatten().collect(), todo.len()))
}

/// The trials still to run, by plan index, said in the log (with `how`).
fn unfinished(results: &[Option<TrialResult>], log: Log<'_>, how: &str) -> Vec<usize> {
    let todo: Vec<usize> = (0..results.len())
        .filter(|&i| results[i].is_none())
        .collect();
    log(&format!(
        "trials: {}, {} already done (skipped){how}",
        results.len(),
        results.len() - todo.len()
    ));
    todo
}

/// The log line of the `k`-th of `n` trials run.
fn trial_line(k: usize, n: usize, plan: &TrialPlan, result: &TrialResult) -> String {
    format!(
        "[{k}/{n}] {} trial {}: {} formations, {} stuck, {} steps at {:.0} steps/s",
        plan.arm,
        plan.trial,
        result.formations,
        result.stuck,
        result.steps,
        result.steps_per_second
    )
}

/// [`run_trials`] one trial at a time, each shown on `view`.
fn run_trials_watched(
    plans: &[TrialPlan],
    finished: Vec<Option<TrialResult>>,
    dir: &Path,
    mut view: TrialView,
    log: Log<'_>,
) -> Result<(Vec<TrialResult>, usize)> {
    let mut results = finished;
    let todo = unfinished(&results, log, "; one at a time, on the view");
    for (k, &i) in todo.iter().enumerate() {
        let plan = &plans[i];
        let caption = format!(
            "{}: arm {}, trial {} ({} of {} to run)",
            plan.experiment,
            plan.arm,
            plan.trial,
            k + 1,
            todo.len()
        );
        let result = run_trial(plan, dir, &mut |running, step| {
            if step == 0 {
                if let Some(url) = view.start(running, caption.clone())? {
                    log(&format!("view: serving {url}"));
                }
            } else {
                view.show(running);
            }
            Ok(())
        })?;
        log(&trial_line(k + 1, todo.len(), plan, &result));
        results[i] = Some(result);
    }
    Ok((results.into_iter().flatten().collect(), todo.len()))
}

/// Runs one trial (from its stored pre-trained table, if it has one),
/// shown to `watch` ([`trial::run_watched`]), and writes its result.
fn run_trial(
    plan: &TrialPlan,
    dir: &Path,
    watch: &mut dyn FnMut(&trial::Running, u64) -> Result<()>,
) -> Result<TrialResult> {
    let seed_table = match &plan.pretrain {
        Some(p) => Some(pretrained_table(dir, p)?),
        None => None,
    };
    let result = trial::run_watched(plan, seed_table, watch)
        .with_context(|| format!("arm {} trial {}", plan.arm, plan.trial))?;
    write_result(&trial_path(dir, plan), &result)?;
    Ok(result)
}

/// Writes a trial's result file atomically, creating its arm's folder.
fn write_result(path: &Path, result: &TrialResult) -> Result<()> {
    let json = serde_json::to_vec_pretty(result).context("cannot encode a trial result")?;
    if let Some(arm) = path.parent() {
        crate::atomic::create_dirs(arm)?;
    }
    crate::atomic::write(path, &json)
}

/// Where a pre-trained table is stored in an output directory.
pub fn pretrained_path(dir: &Path, p: &PretrainPlan) -> PathBuf {
    dir.join("pretrained").join(format!("{}.ckpt", p.hash))
}

/// The stored pre-trained table, if it exists and is for this plan.
fn pretrained_table(dir: &Path, p: &PretrainPlan) -> Result<crate::learn::QTable> {
    let state = checkpoint::load(&pretrained_path(dir, p))?;
    if !super::plan::same_run(&state.config, &p.config) {
        bail!(
            "pre-trained table {} has other settings",
            pretrained_path(dir, p).display()
        );
    }
    Ok(state.learner.table().clone())
}

/// Where a trial's result is stored in an output directory.
pub fn trial_path(dir: &Path, plan: &TrialPlan) -> PathBuf {
    dir.join("trials")
        .join(slug(&plan.arm))
        .join(format!("trial-{:02}.json", plan.trial))
}

/// The stored result of a trial, if it exists and its hash matches.
pub fn finished(dir: &Path, plan: &TrialPlan) -> Option<TrialResult> {
    TrialResult::read_current(&trial_path(dir, plan)).filter(|r| plan.matches(&r.config_hash))
}
