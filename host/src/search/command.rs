//! `host search`: the cross-entropy search over a run's table, with
//! elitism on validation worlds, writing the result's policy blob and a
//! JSON log of the generations (both atomically).
//!
//! Each generation: candidate 0 is the best table so far (the result),
//! the rest are drawn from the distribution; all are scored on the
//! generation's fitness worlds (the same seeds for every candidate); the
//! distribution moves towards the `elites` best; the best candidate other
//! than the result is scored on the validation worlds, and becomes the
//! result only if it forms more there than the result did (or as many, at
//! a higher mean Eval) and, with a `hold_share`, forms at least that share
//! of the start table's count there on every field and noise level. So the
//! result never forms fewer than the start table on the validation worlds.
//! Scores: [`Score`].

use super::cem::{random_table, Categorical};
use super::config::{default_world, SearchConfig, Start, DEFAULT_DISTIL_STEPS};
use super::fitness::{fitness_seeds, validation_seeds, Score, Scorer};
use crate::experiment::plan::mix;
use crate::train::command::seed_table;
use crate::train::config::field_label;
use crate::train::distil::distil_orbital;
use crate::train::{TrainConfig, TrainFlags};
use anyhow::{bail, Context, Result};
use rand::SeedableRng;
use serde::{Deserialize, Serialize};
use shared::{PolicyBlob, PolicyTable, Provenance};
use sim::base::rng::SimRng;
use std::path::PathBuf;
use std::time::{Duration, Instant};

/// Mixed into the seed for drawing candidates.
const SAMPLE_STREAM: u64 = 0x5A3B_1E00_0000_0001;
/// Mixed into the seed for the random start table.
const RANDOM_START_STREAM: u64 = 0x4A4D_0000_0000_0001;

/// What `host search` is asked to do.
#[derive(Clone, Debug)]
pub struct SearchRequest {
    /// TOML file of a training config: the world searched in (its missing
    /// keys a training config's defaults); the flags win. Without it the
    /// world is [`default_world`]'s.
    pub config: Option<PathBuf>,
    /// The world's settings given one by one.
    pub flags: TrainFlags,
    /// The search's settings.
    pub search: SearchConfig,
}

/// One generation of the log.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct Generation {
    /// 0 for the first.
    pub generation: u64,
    /// Every candidate's score on the fitness worlds (candidate 0: the
    /// result so far).
    pub fitness: Vec<Score>,
    /// The fitness worlds' seeds.
    pub fitness_seeds: Vec<u64>,
    /// The challenger (the best candidate other than the result).
    pub challenger: usize,
    /// Its score on the validation worlds.
    pub challenger_validation: Score,
    /// The result's score on the validation worlds after this generation.
    pub result_validation: Score,
    /// Whether the challenger became the result.
    pub replaced: bool,
    /// Mean entropy of the distribution after the update, bits per state.
    pub entropy: f64,
    /// Steps simulated so far (fitness and validation).
    pub steps: u64,
}

/// The JSON log: the settings, the start, every generation, the result.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
pub struct SearchLog {
    /// The world's settings.
    pub world: TrainConfig,
    /// The search's settings.
    pub search: SearchConfig,
    /// The validation worlds' seeds.
    pub validation_seeds: Vec<u64>,
    /// The start table's score on them.
    pub start_validation: Score,
    /// Steps of orbital construction distilled for the start (not counted
    /// in `steps`).
    pub distil_steps: u64,
    /// The generations.
    pub generations: Vec<Generation>,
    /// The result's score on the validation worlds.
    pub result_validation: Score,
    /// Steps simulated (fitness and validation).
    pub steps: u64,
    /// The result's packed table ([`PolicyTable::packed`]).
    pub result: Vec<u8>,
}

impl SearchLog {
    /// Generations whose challenger scored more than the result on the
    /// validation worlds and was refused for the hold share.
    pub fn refused(&self) -> usize {
        let mut before = &self.start_validation;
        let mut refused = 0;
        for g in &self.generations {
            refused += usize::from(!g.replaced && g.challenger_validation.beats(before));
            before = &g.result_validation;
        }
        refused
    }
}

/// What a search did.
#[derive(Clone, Debug, PartialEq)]
pub struct SearchReport {
    /// The log also written as JSON.
    pub log: SearchLog,
    /// The policy blob written.
    pub policy: PathBuf,
    /// The JSON log written.
    pub log_file: PathBuf,
    /// Wall time of the search (the start's distillation excluded).
    pub elapsed: Duration,
    /// Cores the worlds ran on: the search's threads, at most the machine's.
    pub cores: usize,
}

impl SearchReport {
    /// Steps simulated per second of wall time per core: the search's
    /// speed on this machine (not part of the log, which is its result).
    pub fn steps_per_core_second(&self) -> f64 {
        self.log.steps as f64 / self.elapsed.as_secs_f64().max(1e-9) / self.cores.max(1) as f64
    }
}

impl std::fmt::Display for SearchReport {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let l = &self.log;
        writeln!(f, "generations          {}", l.generations.len())?;
        writeln!(f, "steps simulated      {}", l.steps)?;
        writeln!(
            f,
            "validation           start {} formations (mean Eval {:.4}), result {} ({:.4}) on {} worlds of {} steps",
            l.start_validation.formations,
            l.start_validation.eval,
            l.result_validation.formations,
            l.result_validation.eval,
            l.validation_seeds.len(),
            l.search.validation_steps
        )?;
        if l.search.hold_share > 0.0 {
            writeln!(
                f,
                "hold share           {}: {} of {} challengers that scored more refused",
                l.search.hold_share,
                l.refused(),
                l.generations.len()
            )?;
        }
        writeln!(
            f,
            "speed                {:.0} steps/s per core ({} core{}, {:.1} s)",
            self.steps_per_core_second(),
            self.cores,
            if self.cores == 1 { "" } else { "s" },
            self.elapsed.as_secs_f64()
        )?;
        writeln!(f, "policy               {}", self.policy.display())?;
        write!(f, "log                  {}", self.log_file.display())
    }
}

/// A search's progress on stderr: in a terminal one line rewritten after
/// each generation, otherwise (a pipe, a file) one line per generation;
/// each says the generation, the result's validation score so far and the
/// time left at the pace of the generations run so far.
pub struct Progress {
    total: u64,
    resumed: u64,
    started: Instant,
    terminal: bool,
    live: bool,
}

impl Progress {
    /// Progress of `total` generations, the first `resumed` of them run
    /// earlier.
    pub fn new(total: u64, resumed: u64) -> Progress {
        use std::io::IsTerminal;
        Progress {
            total,
            resumed,
            started: Instant::now(),
            terminal: std::io::stderr().is_terminal(),
            live: false,
        }
    }

    /// The line after generation `g`.
    pub fn line(&self, g: &Generation) -> String {
        let run = (g.generation + 1).saturating_sub(self.resumed).max(1);
        let left = self.total.saturating_sub(g.generation + 1);
        let pace = self.started.elapsed().as_secs_f64() / run as f64;
        let secs = (pace * left as f64).round() as u64;
        format!(
            "generation {}/{}  best {} formations (mean Eval {:.4}) on the validation worlds  time left {}m{:02}s",
            g.generation + 1,
            self.total,
            g.result_validation.formations,
            g.result_validation.eval,
            secs / 60,
            secs % 60
        )
    }

    /// Shows generation `g`.
    pub fn generation(&mut self, g: &Generation) {
        let line = self.line(g);
        if self.terminal {
            eprint!("\r\x1b[K{line}");
            self.live = true;
        } else {
            eprintln!("{line}");
        }
    }

    /// Ends the live line in a terminal.
    pub fn done(&mut self) {
        if std::mem::take(&mut self.live) {
            eprintln!();
        }
    }
}

/// The worlds' settings: the file, then the flags, on the run's field and
/// then on each `--also-field`, each at the run's noise and then at each
/// `--also-noise`; on a screen each shape's puck count by the puck rule
/// ([`sim::scenario::puck_rule`]) unless `--pucks` is given. The first is the run's own world.
#[cfg(test)]
fn worlds(request: &SearchRequest) -> Result<Vec<TrainConfig>> {
    worlds_from(base_world(request)?, &request.search)
}

/// The run's own world: the file's (or [`default_world`]), the flags
/// applied.
fn base_world(request: &SearchRequest) -> Result<TrainConfig> {
    let mut base = match &request.config {
        Some(path) => TrainConfig::from_file(path)?,
        None => default_world(),
    };
    request.flags.apply(&mut base)?;
    Ok(base)
}

/// [`worlds`] from the run's own world `base`.
fn worlds_from(base: TrainConfig, settings: &SearchConfig) -> Result<Vec<TrainConfig>> {
    for &noise in &settings.also_noise {
        sim::base::ranges::NOISE.check_as("also-noise", noise)?;
    }
    let fields = std::iter::once(base.world.field.clone()).chain(settings.also_field.clone());
    let noises: Vec<f64> = std::iter::once(base.world.noise)
        .chain(settings.also_noise.iter().copied())
        .collect();
    fields
        .flat_map(|field| noises.iter().map(move |&noise| (field.clone(), noise)))
        .map(|(field, noise)| {
            let mut config = base.clone();
            config.world.field = field;
            config.world.noise = noise;
            config.world.pucks = config.world.pucks()?;
            config.validate()?;
            Ok(config)
        })
        .collect()
}

/// The start table and the steps distilled for it.
pub fn start_table(config: &TrainConfig, start: &Start) -> Result<(PolicyTable, u64)> {
    let (hasher, actions) = (config.learn.hasher.0, config.learn.actions.len());
    Ok(match start {
        Start::Orbital => {
            let steps = config.distil_oc.unwrap_or(DEFAULT_DISTIL_STEPS);
            (distil_orbital(config, steps)?, steps)
        }
        Start::Random => {
            let mut rng = SimRng::seed_from_u64(mix(config.world.seed ^ RANDOM_START_STREAM));
            (random_table(hasher, actions, &mut rng), 0)
        }
        Start::File(path) => (seed_table(path, config)?.greedy_policy(), 0),
    })
}

/// The run's own world (the first of [`worlds`]) and a scorer of every
/// world of the request, the settings checked.
pub fn scorer(request: &SearchRequest) -> Result<(TrainConfig, Scorer)> {
    scorer_of(base_world(request)?, &request.search)
}

/// [`scorer`] of the run's own world `base` (its field, noise and counts
/// as given) and `settings`.
pub fn scorer_of(base: TrainConfig, settings: &SearchConfig) -> Result<(TrainConfig, Scorer)> {
    let configs = worlds_from(base, settings)?;
    let config = configs[0].clone();
    settings.validate(config.learn.actions.len())?;
    let scorer = Scorer::new(&configs, settings.threads)?;
    Ok((config, scorer))
}

/// Runs `host search`, calling `each` after every generation.
pub fn search(request: &SearchRequest, each: &mut Each<'_>) -> Result<SearchReport> {
    let (config, scorer) = scorer(request)?;
    let settings = &request.search;
    crate::atomic::check_writable(&config.output.dir)?;
    let (start, distil_steps) = start_table(&config, &settings.start)?;
    let started = Instant::now();
    let log = run_from(&config, settings, &scorer, start, distil_steps, &[], each)?;
    let elapsed = started.elapsed();
    let machine = std::thread::available_parallelism().map_or(1, usize::from);
    let cores = scorer.threads().min(machine);
    let (policy, log_file) = write_result(&config, &scorer, &log)?;
    Ok(SearchReport {
        log,
        policy,
        log_file,
        elapsed,
        cores,
    })
}

/// Writes a search's result into the run's output directory:
/// `<name>.policy` (the blob records the senses and arena it was searched
/// for, so that `host flash` refuses a table searched with the discs'
/// senses) and `<name>.search.json` (the log), both atomically; returns
/// their paths.
pub fn write_result(
    config: &TrainConfig,
    scorer: &Scorer,
    log: &SearchLog,
) -> Result<(PathBuf, PathBuf)> {
    let name = config.name();
    let policy = config.output.dir.join(format!("{name}.policy"));
    let log_file = config.output.dir.join(format!("{name}.search.json"));
    let table = PolicyTable::from_packed(config.learn.hasher.0, &log.result)
        .context("the result does not fit the run's hasher")?;
    let provenance = Provenance::new(
        &field_label(&config.world.field),
        &name,
        log.steps,
        config.world.seed,
    )?;
    let blob = PolicyBlob::new(scorer.actions(), table, provenance)?
        .with_trained_for(config.trained_for());
    crate::policy_file::write(&policy, &blob)?;
    let json = serde_json::to_vec_pretty(&log).context("cannot encode the search log")?;
    crate::atomic::write(&log_file, &json)?;
    Ok((policy, log_file))
}

/// Called after each generation with it (a resumed run's earlier
/// generations are not passed again).
pub type Each<'a> = dyn FnMut(&Generation) -> Result<()> + 'a;

/// The search from `start`: every generation, then the log.
pub fn run(
    config: &TrainConfig,
    settings: &SearchConfig,
    scorer: &Scorer,
    start: PolicyTable,
    distil_steps: u64,
) -> Result<SearchLog> {
    run_from(
        config,
        settings,
        scorer,
        start,
        distil_steps,
        &[],
        &mut |_| Ok(()),
    )
}

/// The search from `start`, continuing after the generations `done` of an
/// earlier run of the same settings (replayed from their logged scores
/// without simulating: each draws the same candidates and moves the
/// distribution as it did, so a resumed search ends where an unbroken one
/// does), calling `each` after every new generation.
pub fn run_from(
    config: &TrainConfig,
    settings: &SearchConfig,
    scorer: &Scorer,
    start: PolicyTable,
    distil_steps: u64,
    done: &[Generation],
    each: &mut Each<'_>,
) -> Result<SearchLog> {
    let actions = config.learn.actions.len();
    let validation = validation_seeds(config.world.seed, settings.validation_seeds);
    // every world is run once per field
    let fields = scorer.fields() as u64;
    let validation_cost = settings.validation_steps * validation.len() as u64 * fields;
    let fitness_cost = settings.fitness_steps * settings.fitness_seeds as u64 * fields;
    let start_validation = scorer
        .score(
            std::slice::from_ref(&start),
            &validation,
            settings.validation_steps,
        )?
        .remove(0);
    let mut steps = validation_cost;
    let mut distribution = Categorical::around(&start, actions, settings.keep);
    let (mut result, mut result_validation) = (start, start_validation.clone());
    let mut generations: Vec<Generation> = Vec::new();
    for g in 0..settings.generations {
        let mut rng = SimRng::seed_from_u64(mix(mix(config.world.seed ^ SAMPLE_STREAM) ^ g));
        let candidates: Vec<PolicyTable> = std::iter::once(result.clone())
            .chain((1..settings.population).map(|_| distribution.sample(&mut rng)))
            .collect();
        let seeds = fitness_seeds(config.world.seed, g, settings.fitness_seeds);
        let earlier = done.get(g as usize);
        if let Some(earlier) = earlier {
            if earlier.generation != g
                || earlier.fitness_seeds != seeds
                || earlier.fitness.len() != candidates.len()
            {
                bail!("generation {g} of the earlier run is not one of these settings");
            }
        }
        let fitness = match earlier {
            Some(earlier) => earlier.fitness.clone(),
            None => {
                steps += fitness_cost * candidates.len() as u64;
                scorer.score(&candidates, &seeds, settings.fitness_steps)?
            }
        };
        // best first; equal scores keep the candidates' order
        let mut ranked: Vec<usize> = (0..candidates.len()).collect();
        ranked.sort_by(|&a, &b| Score::best_first(&fitness[a], &fitness[b]));
        let elites: Vec<&PolicyTable> = ranked[..settings.elites]
            .iter()
            .map(|&i| &candidates[i])
            .collect();
        distribution.update(&elites, settings.rate, settings.floor);
        let challenger = ranked.iter().copied().find(|&i| i != 0).unwrap_or(1);
        let challenger_validation = match earlier {
            Some(earlier) => earlier.challenger_validation.clone(),
            None => {
                steps += validation_cost;
                scorer
                    .score(
                        std::slice::from_ref(&candidates[challenger]),
                        &validation,
                        settings.validation_steps,
                    )?
                    .remove(0)
            }
        };
        let replaced = challenger_validation.beats(&result_validation)
            && challenger_validation.holds(&start_validation, settings.hold_share);
        if replaced {
            result = candidates[challenger].clone();
            result_validation = challenger_validation.clone();
        }
        let generation = Generation {
            generation: g,
            fitness,
            fitness_seeds: seeds,
            challenger,
            challenger_validation,
            result_validation: result_validation.clone(),
            replaced,
            entropy: distribution.mean_entropy(),
            steps: earlier.map_or(steps, |e| e.steps),
        };
        if let Some(earlier) = earlier {
            if *earlier != generation {
                bail!("generation {g} of the earlier run is not one of these settings");
            }
            steps = earlier.steps;
        } else {
            each(&generation)?;
        }
        generations.push(generation);
    }
    Ok(SearchLog {
        world: config.clone(),
        search: settings.clone(),
        validation_seeds: validation,
        start_validation,
        distil_steps,
        generations,
        result_validation,
        steps,
        result: result.packed().to_vec(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use sim::fields::source::FieldSource;

    /// A small search on the TV with the robot's senses and noise.
    fn small(threads: usize, start: Start) -> SearchLog {
        small_over(threads, start, Vec::new())
    }

    /// The small search's settings, on one field at one noise level.
    fn small_settings(threads: usize, start: Start) -> SearchConfig {
        SearchConfig {
            start,
            generations: 3,
            population: 4,
            elites: 2,
            fitness_seeds: 2,
            fitness_steps: 8000,
            validation_seeds: 2,
            validation_steps: 8000,
            keep: 0.8,
            rate: 0.5,
            floor: 0.01,
            threads,
            also_field: Vec::new(),
            also_noise: Vec::new(),
            hold_share: 0.0,
        }
    }

    /// The small search's world: the robot's senses and noise on the TV.
    fn small_flags() -> TrainFlags {
        TrainFlags::parse([
            "--sensors",
            "robot",
            "--noise",
            "1",
            "--seed",
            "3",
            "--distil-oc",
            "20000",
        ])
        .unwrap()
    }

    /// [`small`], also scored on `also_field`.
    fn small_over(threads: usize, start: Start, also_field: Vec<FieldSource>) -> SearchLog {
        small_with(SearchConfig {
            also_field,
            ..small_settings(threads, start)
        })
    }

    /// The small search's world searched with `search`.
    fn small_with(search: SearchConfig) -> SearchLog {
        let request = SearchRequest {
            config: None,
            flags: small_flags(),
            search,
        };
        let configs = worlds(&request).unwrap();
        let config = configs[0].clone();
        assert_eq!(config.world.pucks, Some(12), "the annulus' count on the TV");
        let scorer = Scorer::new(&configs, request.search.threads).unwrap();
        let (table, distilled) = start_table(&config, &request.search.start).unwrap();
        run(&config, &request.search, &scorer, table, distilled).unwrap()
    }

    #[test]
    fn with_a_hold_share_the_result_keeps_that_share_of_the_start_on_every_field() {
        let search = |hold: f64| {
            small_with(SearchConfig {
                also_noise: vec![2.0],
                generations: 4,
                hold_share: hold,
                ..small_settings(2, Start::Orbital)
            })
        };
        let free = search(0.0);
        assert_eq!(free.start_validation.fields.len(), 2, "both noise levels");
        let held = search(1.0);
        for g in &held.generations {
            let holds = g.challenger_validation.holds(&held.start_validation, 1.0);
            assert_eq!(
                g.replaced,
                holds && g.challenger_validation.beats(&g_before(&held, g))
            );
        }
        assert!(held.result_validation.holds(&held.start_validation, 1.0));
        // the bar decides: a challenger the free search took fails it here
        assert!(
            free.generations
                .iter()
                .any(|g| g.replaced && !g.challenger_validation.holds(&free.start_validation, 1.0)),
            "the free search gave up a field somewhere: the test must see the bar act"
        );
        assert_ne!(free.generations, held.generations);
        // the first decision the two differ on is one the bar refused
        assert_eq!(
            free.refused(),
            0,
            "without a bar nothing that scores more is refused"
        );
        assert!(held.refused() >= 1);
    }

    /// The result's validation score before generation `g`.
    fn g_before(log: &SearchLog, g: &Generation) -> Score {
        match g.generation {
            0 => log.start_validation.clone(),
            n => log.generations[n as usize - 1].result_validation.clone(),
        }
    }

    #[test]
    fn a_search_gives_the_same_result_on_one_thread_and_on_two() {
        let one = small(1, Start::Orbital);
        let mut two = small(2, Start::Orbital);
        assert_eq!(two.search.threads, 2);
        two.search.threads = 1;
        assert_eq!(one, two);
        assert_eq!(one.generations.len(), 3);
        assert!(one
            .generations
            .iter()
            .any(|g| g.fitness.iter().any(|f| f.formations > 0)));
    }

    #[test]
    fn a_general_search_scores_every_field_with_its_pucks_the_same_on_any_thread_count() {
        let letter: FieldSource = "letter:I".parse().unwrap();
        let one = small_over(1, Start::Orbital, vec![letter.clone()]);
        let mut two = small_over(2, Start::Orbital, vec![letter.clone()]);
        two.search.threads = 1;
        assert_eq!(one, two);
        // the annulus alone scores differently: the I's worlds count too
        let alone = small(1, Start::Orbital);
        assert_eq!(one.steps, 2 * alone.steps, "two fields' worlds simulated");
        assert_ne!(one.start_validation, alone.start_validation);
        assert!(one.start_validation.formations >= alone.start_validation.formations);
        let request = SearchRequest {
            config: None,
            flags: TrainFlags::parse(["--sensors", "robot"]).unwrap(),
            search: SearchConfig {
                also_field: vec![letter],
                ..one.search.clone()
            },
        };
        let configs = worlds(&request).unwrap();
        assert_eq!(
            configs.iter().map(|c| c.world.pucks).collect::<Vec<_>>(),
            [Some(12), Some(11)],
            "each shape's own count on the TV"
        );
    }

    #[test]
    fn each_field_is_also_scored_at_each_extra_noise_and_a_bad_level_is_named() {
        let search = |also_noise: Vec<f64>| SearchRequest {
            config: None,
            flags: TrainFlags::parse(["--sensors", "robot", "--noise", "1"]).unwrap(),
            search: SearchConfig {
                also_field: vec!["letter:I".parse().unwrap()],
                also_noise,
                ..small_settings(1, Start::Random)
            },
        };
        let configs = worlds(&search(vec![2.0])).unwrap();
        let worlds_seen: Vec<_> = configs
            .iter()
            .map(|c| (field_label(&c.world.field), c.world.noise, c.world.pucks))
            .collect();
        assert_eq!(
            worlds_seen,
            [
                ("annulus".to_string(), 1.0, Some(12)),
                ("annulus".to_string(), 2.0, Some(12)),
                ("letter:I".to_string(), 1.0, Some(11)),
                ("letter:I".to_string(), 2.0, Some(11)),
            ],
            "the run's own world first, then every field at every level"
        );
        let error = worlds(&search(vec![-1.0])).unwrap_err().to_string();
        assert!(error.contains("also-noise"), "{error}");
    }

    #[test]
    fn a_search_resumed_after_its_first_generation_ends_as_an_unbroken_one() {
        let unbroken = small(2, Start::Random);
        let settings = small_settings(2, Start::Random);
        let request = SearchRequest {
            config: None,
            flags: small_flags(),
            search: settings.clone(),
        };
        let (config, scorer) = scorer(&request).unwrap();
        let (start, _) = start_table(&config, &settings.start).unwrap();
        let mut new = Vec::new();
        let resumed = run_from(
            &config,
            &settings,
            &scorer,
            start.clone(),
            0,
            &unbroken.generations[..1],
            &mut |g| {
                new.push(g.generation);
                Ok(())
            },
        )
        .unwrap();
        assert_eq!(new, [1, 2], "only the generations not run before");
        assert_eq!(resumed, unbroken);
        // a generation of other settings is not resumed from
        let mut other = unbroken.generations[0].clone();
        other.fitness_seeds[0] ^= 2;
        let e = run_from(&config, &settings, &scorer, start, 0, &[other], &mut |_| {
            Ok(())
        })
        .unwrap_err()
        .to_string();
        assert!(e.contains("generation 0 of the earlier run"), "{e}");
    }

    #[test]
    fn the_result_never_forms_fewer_than_the_start_on_the_validation_worlds() {
        for start in [Start::Orbital, Start::Random] {
            let log = small(2, start);
            assert!(log.result_validation.formations >= log.start_validation.formations);
            let mut best = log.start_validation.clone();
            for g in &log.generations {
                assert_eq!(g.replaced, g.challenger_validation.beats(&best));
                if g.replaced {
                    best = g.challenger_validation.clone();
                }
                assert_eq!(g.result_validation, best, "the best validated so far");
            }
            assert_eq!(log.result_validation, best);
        }
    }
}
