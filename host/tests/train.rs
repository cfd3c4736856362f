//! Training: determinism, exact resume from checkpoints, torn writes, and
//! the one-sensing-per-step contract a learner relies on.

use host::learn::QLearner;
use host::train::checkpoint::{self, CheckpointError};
use host::train::{TrainConfig, Trainer, TrainingState};
use shared::SensorReading;
use sim::episodes::reward::Reward;
use sim::scenario::choices::WorldChoices;
use sim::scenario::sensor_choice::SensorChoice;
use sim::{base::rng::SimRng, episodes::EpisodeStart, episodes::StepOutcome};
use sim::{control::Controller, control::Perception};
use std::io::Write;
use std::sync::Arc;

/// A small, quick run: 4 robots, 60 pucks, a short stuck limit so that
/// episodes end and reset within the test.
fn small(seed: u64) -> TrainConfig {
    TrainConfig {
        world: WorldChoices {
            stuck_limit: Some(700),
            robots: Some(4),
            pucks: Some(60),
            seed,
            ..Default::default()
        },
        ..TrainConfig::default()
    }
}

fn trainer(config: TrainConfig) -> Trainer<sim::scenario::sensor_setup::SelectedSensors> {
    Trainer::start(config, None).unwrap()
}

/// Trains `config` for `steps` straight, and for `first` steps, through a
/// checkpoint file, then the rest; both runs must end in the same state.
/// The checkpoint is written both in the current format and in the oldest
/// earlier format that holds the state (as earlier builds wrote it), and
/// the run resumes exactly from each. Returns that earlier format's
/// version, or the current one when none holds the state.
fn resumes_exactly(config: TrainConfig, first: u64, steps: u64) -> u16 {
    let mut straight = trainer(config.clone());
    straight.run(steps);
    let mut head = trainer(config.clone());
    head.run(first);
    let mut current = Vec::new();
    checkpoint::write_to(&mut current, &head.state()).unwrap();
    let mut earlier = Vec::new();
    let version = checkpoint::write_earlier_format(&mut earlier, &head.state())
        .unwrap()
        .unwrap_or(checkpoint::VERSION);
    drop(head);
    for bytes in [current, earlier].iter().filter(|b| !b.is_empty()) {
        let state = checkpoint::decode(bytes).unwrap();
        if u16::from(bytes[8]) == checkpoint::VERSION {
            assert_eq!(state.config, config, "the checkpoint keeps the settings");
        } else {
            // an earlier format may name a default (the arena) outright
            assert_eq!(
                state.config.scenario().unwrap(),
                config.scenario().unwrap(),
                "the checkpoint of format {} keeps the run's settings",
                bytes[8]
            );
        }
        let mut resumed = Trainer::restart(state).unwrap();
        resumed.run(steps - first);
        assert_eq!(resumed.learner().table(), straight.learner().table());
        assert_eq!(resumed.totals(), straight.totals());
        assert!(
            evolving(&resumed.state()) == evolving(&straight.state()),
            "world, generators or counters differ after format {}",
            bytes[8]
        );
        assert_eq!(resumed.policy().unwrap(), straight.policy().unwrap());
    }
    version
}

/// Everything that evolves: Q-values, visits, counters, world, generators.
fn evolving(state: &TrainingState) -> Vec<u8> {
    let mut bytes = postcard::to_stdvec(&state.sim).unwrap();
    bytes.extend(postcard::to_stdvec(&state.learner).unwrap());
    bytes
}

#[test]
fn same_seed_same_q_table() {
    let run = |seed| {
        let mut t = trainer(small(seed));
        t.run(3000);
        t.state()
    };
    let (a, b, c) = (run(4), run(4), run(5));
    assert_eq!(a.learner.table(), b.learner.table());
    assert_eq!(evolving(&a), evolving(&b));
    assert_ne!(
        a.learner.table(),
        c.learner.table(),
        "another seed learns another table"
    );
    assert!(
        a.sim.totals.stuck >= 3,
        "episodes ended and reset: {:?}",
        a.sim.totals
    );
    assert!(a.learner.table().states_visited() > 20);
}

#[test]
fn train_then_resume_equals_one_long_run() {
    let mut straight = trainer(small(9));
    straight.run(2500);

    let mut first = trainer(small(9));
    first.run(1400);
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("run.ckpt");
    checkpoint::save(&path, &first.state()).unwrap();
    drop(first);

    let state = checkpoint::load(&path).unwrap();
    let mut resumed = Trainer::restart(state).unwrap();
    resumed.run(1100);
    assert_eq!(resumed.learner().table(), straight.learner().table());
    assert_eq!(resumed.totals(), straight.totals());
    assert!(
        evolving(&resumed.state()) == evolving(&straight.state()),
        "world, generators or counters differ"
    );
    assert_eq!(resumed.policy().unwrap(), straight.policy().unwrap());
}

#[test]
fn a_run_with_the_thesis_authors_settings_resumes_exactly_from_a_format_2_checkpoint() {
    let authors = TrainConfig {
        world: WorldChoices {
            // the border formats 1 to 3 knew
            walls: Some(sim::config::Walls::Segments),
            ..small(11).world
        },
        formation_check: host::train::config::FormationCheck {
            every: 300,
            stale: true,
        },
        success: sim::config::SuccessSignal::EvalPrime,
        obstacle_discs: Some(host::train::config::ObstacleDiscs {
            radius: 2.0,
            sees: sim::config::disc_sensors::ObstacleTargets::AnyBody,
        }),
        ..small(11)
    };
    assert_eq!(
        resumes_exactly(authors, 1400, 2500),
        2,
        "format 1 cannot hold these settings"
    );
}

#[test]
fn a_noisy_run_of_the_robot_senses_on_the_tv_s_discs_resumes_exactly_from_a_format_3_checkpoint() {
    let discs = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../experiments/arenas/tv75-disc.toml");
    let noisy = TrainConfig {
        world: WorldChoices {
            stuck_limit: Some(900),
            sensors: SensorChoice::Robot(None),
            arena: Some(sim::scenario::arena_choice::ArenaChoice::File(discs)),
            noise: 1.0,
            seed: 12,
            ..Default::default()
        },
        ..TrainConfig::default()
    };
    // resumed mid-episode, with camera links, held blocks and a latency
    // frame in flight, after episode resets that drew new robot motions
    assert_eq!(resumes_exactly(noisy, 1700, 2600), 3);
}

#[test]
fn a_clamping_border_with_near_ties_and_batched_updates_resumes_exactly_from_a_format_4_checkpoint()
{
    let rules = TrainConfig {
        world: WorldChoices {
            stuck_limit: Some(800),
            walls: Some(sim::config::Walls::Clamp),
            ..small(13).world
        },
        learn: host::learn::LearnConfig {
            tie_tolerance: 0.001,
            updates: host::learn::Updates::Batched,
            ..Default::default()
        },
        ..small(13)
    };
    assert_eq!(resumes_exactly(rules.clone(), 1300, 2700), 4);
    // each setting changes the run: none is silently dropped
    let base = {
        let mut t = trainer(small(13));
        t.run(10_000);
        t.learner().table().clone()
    };
    for changed in [
        TrainConfig {
            world: WorldChoices {
                walls: Some(sim::config::Walls::Segments),
                ..small(13).world
            },
            ..small(13)
        },
        TrainConfig {
            learn: host::learn::LearnConfig {
                tie_tolerance: 0.05,
                ..Default::default()
            },
            ..small(13)
        },
        TrainConfig {
            learn: host::learn::LearnConfig {
                updates: host::learn::Updates::Batched,
                ..Default::default()
            },
            ..small(13)
        },
    ] {
        let what = format!(
            "walls {:?}, learner {:?}",
            changed.world.walls, changed.learn
        );
        let mut t = trainer(changed);
        t.run(10_000);
        assert_ne!(t.learner().table(), &base, "{what} changed nothing");
    }
}

#[test]
fn decaying_exploration_is_the_same_per_seed_and_resumes_exactly_from_a_format_5_checkpoint() {
    let decaying = TrainConfig {
        learn: host::learn::LearnConfig {
            epsilon: 0.3,
            ..Default::default()
        },
        epsilon_decay: Some(2000),
        ..small(17)
    };
    // resumed mid-period (1,500) and across the end of the decay (2,000)
    assert_eq!(resumes_exactly(decaying.clone(), 1500, 2600), 5);
    let run = |config: TrainConfig| {
        let mut t = trainer(config);
        t.run(3000);
        (t.learner().table().clone(), t.learner().exploration())
    };
    let (table, epsilon) = run(decaying.clone());
    assert_eq!(epsilon, 0.0, "no exploration after the decay");
    assert_eq!(run(decaying.clone()).0, table, "same seed, same table");
    let constant = TrainConfig {
        epsilon_decay: None,
        ..decaying.clone()
    };
    assert_ne!(run(constant).0, table, "the decay changes the run");
    assert_eq!(decaying.exploration_at(0), 0.3);
    assert!((decaying.exploration_at(1999) - 0.3 * 0.5).abs() < 1e-12);
    assert_eq!(decaying.exploration_at(5000), 0.0);
}

#[test]
fn the_rewards_for_deep_learners_resume_exactly_from_a_format_6_checkpoint_and_change_the_run() {
    let with = |reward: Reward| TrainConfig {
        learn: host::learn::LearnConfig {
            reward,
            ..Default::default()
        },
        ..small(23)
    };
    let table = |reward: Reward| {
        let mut t = trainer(with(reward));
        t.run(3000);
        t.learner().table().clone()
    };
    let thesis = table(Reward::Thesis);
    for reward in [Reward::PerRobot, Reward::Success, Reward::SuccessShaped] {
        assert_eq!(resumes_exactly(with(reward), 1300, 2600), 6, "{reward}");
        assert_ne!(table(reward), thesis, "{reward} is not the thesis reward");
    }
    // the thesis' own rewards keep the formats earlier builds read
    assert!(resumes_exactly(with(Reward::Thesis), 1300, 2600) <= 5);
}

#[test]
fn n_step_returns_are_the_same_per_seed_resume_exactly_with_steps_waiting_and_change_the_run() {
    let n_step = |n: Option<u32>, updates: host::learn::Updates| TrainConfig {
        n_step: n,
        learn: host::learn::LearnConfig {
            updates,
            ..Default::default()
        },
        ..small(29)
    };
    let run = |config: TrainConfig| {
        let mut t = trainer(config);
        t.run(3000);
        let pending = !t.learner().pending().is_empty();
        (t.learner().table().clone(), pending)
    };
    for updates in [
        host::learn::Updates::Sequential,
        host::learn::Updates::Batched,
    ] {
        let four = n_step(Some(4), updates);
        // 1,301 steps in: every robot has steps waiting, which the
        // checkpoint keeps; the resumed run makes the straight run's updates
        assert_eq!(resumes_exactly(four.clone(), 1301, 2600), 7);
        let (table, pending) = run(four.clone());
        assert!(pending, "steps wait between updates");
        assert_eq!(run(four).0, table, "same seed, same table");
        let (one_step, none_waiting) = run(n_step(None, updates));
        assert!(!none_waiting);
        assert_ne!(one_step, table, "n-step returns change the run");
        assert_eq!(
            run(n_step(Some(1), updates)).0,
            one_step,
            "n_step 1 is one-step Q-learning"
        );
    }
    let mut bad = n_step(Some(65), host::learn::Updates::Sequential);
    let e = Trainer::start(bad.clone(), None).err().unwrap().to_string();
    assert!(e.contains("n_step = 65") && e.contains("[1, 64]"), "{e}");
    bad.n_step = Some(0);
    assert!(Trainer::start(bad, None).is_err());
}

#[test]
fn a_wedge_run_on_the_tv_with_the_robot_s_senses_resumes_exactly_from_a_format_5_checkpoint() {
    let wedge = TrainConfig {
        world: WorldChoices {
            sensors: SensorChoice::Robot(None),
            arena: Some(sim::scenario::arena_choice::ArenaChoice::Named(
                "tv75".into(),
            )),
            noise: 1.0,
            seed: 17,
            ..Default::default()
        },
        ..TrainConfig::default()
    };
    assert_eq!(resumes_exactly(wedge.clone(), 1100, 2500), 5);
    // the same run on discs is another run, of an older format
    let disc_arena = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../experiments/arenas/tv75-disc.toml");
    let disc = TrainConfig {
        world: WorldChoices {
            arena: Some(sim::scenario::arena_choice::ArenaChoice::File(disc_arena)),
            ..wedge.world.clone()
        },
        ..wedge.clone()
    };
    assert!(resumes_exactly(disc.clone(), 1100, 2500) < 5);
    let table = |config: TrainConfig| {
        let mut t = trainer(config);
        t.run(5_000);
        t.learner().table().clone()
    };
    assert_ne!(table(wedge), table(disc), "the wedge changed nothing");
}

#[test]
fn published_checkpoints_of_earlier_builds_load_and_are_written_again_in_their_format_byte_for_byte(
) {
    // the published pre-trained tables of docs/reproduction were written by
    // earlier builds; tests/checkpoints keeps one of format 1 (a table the
    // annulus' RL2 started from until its rerun with the clamping border)
    let manifest = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
    let docs = manifest.join("../docs/reproduction");
    let mut files: Vec<_> = std::fs::read_dir(&docs)
        .unwrap()
        .flat_map(|e| {
            std::fs::read_dir(e.unwrap().path().join("pretrained"))
                .into_iter()
                .flatten()
        })
        .chain(std::fs::read_dir(manifest.join("tests/checkpoints")).unwrap())
        .map(|e| e.unwrap().path())
        .collect();
    files.sort();
    let mut versions = std::collections::BTreeMap::new();
    for path in files {
        let bytes = std::fs::read(&path).unwrap();
        versions
            .entry(u16::from_le_bytes([bytes[8], bytes[9]]))
            .or_insert((path, bytes));
    }
    assert!(
        versions.contains_key(&1),
        "no published format-1 checkpoint under {}",
        docs.display()
    );
    for (version, (path, bytes)) in &versions {
        assert!(
            *version < checkpoint::VERSION,
            "{} is of format {version}",
            path.display()
        );
        let state = checkpoint::decode(bytes).unwrap();
        let mut again = Vec::new();
        let written = checkpoint::write_earlier_format(&mut again, &state).unwrap();
        assert_eq!(written, Some(*version), "{}", path.display());
        assert!(&again == bytes, "{} is written differently", path.display());
        // and in the current format, the same state
        let mut current = Vec::new();
        checkpoint::write_to(&mut current, &state).unwrap();
        let back = checkpoint::decode(&current).unwrap();
        assert_eq!(back.config, state.config, "{}", path.display());
        assert!(
            evolving(&back) == evolving(&state),
            "{}: the current format changed the state",
            path.display()
        );
    }
}

/// A checkpoint of the current format whose body, as a CBOR value, was
/// changed by `edit`, framed (header and CRC) as a checkpoint again.
fn edited_checkpoint(state: &TrainingState, edit: impl FnOnce(&mut ciborium::Value)) -> Vec<u8> {
    let mut bytes = Vec::new();
    checkpoint::write_to(&mut bytes, state).unwrap();
    let mut value: ciborium::Value = ciborium::from_reader(&bytes[18..bytes.len() - 4]).unwrap();
    edit(&mut value);
    let mut body = Vec::new();
    ciborium::into_writer(&value, &mut body).unwrap();
    let mut framed = bytes[..10].to_vec();
    framed.extend((body.len() as u64).to_le_bytes());
    framed.extend(&body);
    let crc = crc::Crc::<u32>::new(&crc::CRC_32_ISO_HDLC).checksum(&framed);
    framed.extend(crc.to_le_bytes());
    framed
}

/// The field `key` of a struct's map in CBOR.
fn field<'a>(value: &'a mut ciborium::Value, key: &str) -> &'a mut ciborium::Value {
    let (_, inner) = value
        .as_map_mut()
        .unwrap()
        .iter_mut()
        .find(|(k, _)| k.as_text() == Some(key))
        .unwrap();
    inner
}

/// The map entries of `value`'s field `key` (a struct's map in CBOR).
fn entries<'a>(
    value: &'a mut ciborium::Value,
    key: &str,
) -> &'a mut Vec<(ciborium::Value, ciborium::Value)> {
    field(value, key).as_map_mut().unwrap()
}

#[test]
fn a_setting_a_checkpoint_lacks_takes_its_default() {
    let config = TrainConfig {
        n_step: Some(3),
        epsilon_decay: Some(5000),
        learn: host::learn::LearnConfig {
            tie_tolerance: 0.25,
            ..Default::default()
        },
        ..small(31)
    };
    let mut t = trainer(config.clone());
    t.run(200);
    let bytes = edited_checkpoint(&t.state(), |body| {
        let settings = field(body, "config");
        entries(settings, "learn").retain(|(k, _)| k.as_text() != Some("tie_tolerance"));
        settings
            .as_map_mut()
            .unwrap()
            .retain(|(k, _)| !matches!(k.as_text(), Some("n_step" | "epsilon_decay")));
    });
    let state = checkpoint::decode(&bytes).unwrap();
    assert_eq!(
        (state.config.n_step, state.config.epsilon_decay),
        (None, None),
        "absent settings take their defaults"
    );
    assert_eq!(state.config.learn.tie_tolerance, 0.0);
    assert_eq!(
        TrainConfig {
            n_step: Some(3),
            epsilon_decay: Some(5000),
            learn: host::learn::LearnConfig {
                tie_tolerance: 0.25,
                ..state.config.learn.clone()
            },
            ..state.config.clone()
        },
        config,
        "the settings present are kept"
    );
}

#[test]
fn a_checkpoint_with_an_unknown_or_mistyped_setting_is_refused_naming_the_file_and_the_setting() {
    let mut t = trainer(small(37));
    t.run(100);
    let dir = tempfile::tempdir().unwrap();
    // the refusal of a file `name` holding `bytes`
    let refusal = |name: &str, bytes: Vec<u8>| {
        let path = dir.path().join(name);
        std::fs::write(&path, bytes).unwrap();
        format!("{:#}", checkpoint::load(&path).unwrap_err())
    };
    let unknown = edited_checkpoint(&t.state(), |body| {
        entries(body, "config").push(("pucks_per_robot".into(), 3.into()));
    });
    let e = refusal("unknown.ckpt", unknown);
    assert!(
        e.contains("unknown.ckpt") && e.contains("pucks_per_robot"),
        "{e}"
    );
    let mistyped = edited_checkpoint(&t.state(), |body| {
        *field(field(body, "config"), "steps") = "many".into();
    });
    let e = refusal("mistyped.ckpt", mistyped);
    assert!(
        e.contains("mistyped.ckpt") && e.contains("setting steps: invalid type"),
        "{e}"
    );
}

#[test]
fn a_resume_refuses_a_changed_field() {
    let t = trainer(small(1));
    let letter = Arc::new(sim::fields::letters::Letter::T.field());
    let sensors = SensorChoice::Disc.build(&t.state().sim.config).unwrap();
    let e = Trainer::resume(t.state(), letter, sensors)
        .err()
        .unwrap()
        .to_string();
    assert!(
        e.contains("differs from the one the checkpoint trained on"),
        "{e}"
    );
}

/// Fails after `budget` bytes, like a full disk or a killed process.
struct FailingWriter<'a> {
    inner: &'a mut dyn Write,
    budget: usize,
}

impl Write for FailingWriter<'_> {
    fn write(&mut self, buf: &[u8]) -> std::io::Result<usize> {
        if self.budget == 0 {
            return Err(std::io::Error::other("disk full"));
        }
        let n = buf.len().min(self.budget);
        self.budget -= n;
        self.inner.write(&buf[..n])
    }
    fn flush(&mut self) -> std::io::Result<()> {
        self.inner.flush()
    }
}

#[test]
fn a_failing_writer_leaves_the_previous_checkpoint() {
    let mut t = trainer(small(2));
    t.run(500);
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("run.ckpt");
    checkpoint::save(&path, &t.state()).unwrap();
    let before = std::fs::read(&path).unwrap();

    t.run(500);
    let newer = t.state();
    for budget in [0, 10, 100, 5000] {
        let r = host::atomic::write_with(&path, |w| {
            checkpoint::write_to(&mut FailingWriter { inner: w, budget }, &newer)
        });
        assert!(r.is_err());
        assert_eq!(
            std::fs::read(&path).unwrap(),
            before,
            "torn after {budget} bytes"
        );
        assert_eq!(
            std::fs::read_dir(dir.path()).unwrap().count(),
            1,
            "temporary file left behind"
        );
    }
    assert_eq!(checkpoint::load(&path).unwrap().sim.totals.steps, 500);
}

#[test]
fn damaged_or_foreign_checkpoints_are_refused_with_the_reason() {
    let mut bytes = Vec::new();
    checkpoint::write_to(&mut bytes, &trainer(small(3)).state()).unwrap();
    assert!(checkpoint::decode(&bytes).is_ok());

    let short = checkpoint::decode(&bytes[..bytes.len() - 9]).unwrap_err();
    assert!(
        matches!(short, CheckpointError::Truncated { .. }),
        "{short}"
    );
    assert!(matches!(
        checkpoint::decode(&bytes[..5]),
        Err(CheckpointError::Truncated {
            needed: 18,
            found: 5
        })
    ));
    let mut long = bytes.clone();
    long.push(0);
    assert!(matches!(
        checkpoint::decode(&long),
        Err(CheckpointError::TrailingBytes { .. })
    ));
    let mut flipped = bytes.clone();
    flipped[40] ^= 1;
    assert!(matches!(
        checkpoint::decode(&flipped),
        Err(CheckpointError::CrcMismatch { .. })
    ));
    let mut version = bytes.clone();
    version[8] = 9;
    assert_eq!(
        checkpoint::decode(&version).unwrap_err(),
        CheckpointError::UnsupportedVersion(9)
    );
    assert_eq!(
        checkpoint::decode(b"PNG\x89 not a checkpoint at all").unwrap_err(),
        CheckpointError::WrongMagic
    );
    assert_eq!(
        checkpoint::decode(b"QPOL\x01").unwrap_err(),
        CheckpointError::PolicyBlob
    );

    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("cut.ckpt");
    std::fs::write(&path, &bytes[..100]).unwrap();
    let e = format!("{:#}", checkpoint::load(&path).unwrap_err());
    assert!(e.contains("cut.ckpt") && e.contains("truncated"), "{e}");
}

/// Records what a learner would see: the readings each decision used and
/// the readings after each step.
struct Probe {
    decided: Vec<Vec<SensorReading>>,
    after: Vec<(Vec<SensorReading>, bool)>,
    starts: u64,
}

impl Controller for Probe {
    fn decide(&mut self, p: &Perception<'_>, turns: &mut [f32], rng: &mut SimRng) {
        self.decided.push(p.readings.to_vec());
        for t in turns.iter_mut() {
            *t = rand::RngExt::random_range(rng, -0.3..0.3);
        }
    }
    fn episode_start(&mut self, _start: &EpisodeStart<'_>) {
        self.starts += 1;
    }
    fn observe(&mut self, o: &StepOutcome<'_>) {
        self.after.push((o.readings.to_vec(), o.end.is_some()));
    }
}

#[test]
fn the_state_reached_is_the_state_decided_on_next() {
    let config = small(6).prepare().unwrap().config().clone();
    let field = Arc::new(sim::fields::ScalarField::annulus());
    let mut sim = sim::simulation::Simulation::new(config, field, 6).unwrap();
    let mut probe = Probe {
        decided: Vec::new(),
        after: Vec::new(),
        starts: 0,
    };
    sim.run(&mut probe, 2000);
    let ends = probe.after.iter().filter(|a| a.1).count();
    assert!(ends >= 2, "the test needs episode ends");
    assert_eq!(probe.starts, 1 + ends as u64, "one start per episode");
    for t in 0..1999 {
        let (reached, ended) = &probe.after[t];
        if *ended {
            assert_ne!(
                reached,
                &probe.decided[t + 1],
                "after a reset the next decision sees the new world"
            );
        } else {
            assert_eq!(reached, &probe.decided[t + 1], "step {t}");
        }
    }
}

#[test]
fn every_reward_variant_learns_something() {
    for reward in Reward::ALL {
        let mut config = small(7);
        config.learn.reward = reward;
        let mut t = trainer(config);
        t.run(300);
        let q: &QLearner = t.learner();
        assert!(q.table().states_visited() > 5, "{reward}");
        assert!(q.signal().is_finite());
    }
}

#[test]
fn policy_selection_keeps_the_best_evaluated_policy_without_disturbing_training_and_resumes_exactly(
) {
    let select = host::train::selection::SelectConfig {
        every: 600,
        steps: 400,
    };
    let selecting = TrainConfig {
        world: WorldChoices {
            // the border formats 1 to 3 knew
            walls: Some(sim::config::Walls::Segments),
            ..small(21).world
        },
        select: Some(select),
        ..small(21)
    };
    let mut with = trainer(selecting.clone());
    let mut without = trainer(TrainConfig {
        select: None,
        ..selecting.clone()
    });
    with.run(2400);
    without.run(2400);
    assert_eq!(
        with.learner().table(),
        without.learner().table(),
        "evaluations do not touch the training world"
    );
    assert!(
        evolving(&with.state()).starts_with(&postcard::to_stdvec(&without.state().sim).unwrap())
    );

    let best = with.selected().expect("four evaluations ran").clone();
    assert!(best.step % 600 == 0 && best.step <= 2400);
    assert_eq!(
        with.policy().unwrap().table().packed(),
        &best.packed[..],
        "the run's policy is the selected one"
    );
    assert_eq!(with.policy().unwrap().provenance().trainer_steps, best.step);
    // the selected policy formed at least as much as the last greedy one in the evaluation world
    let last = with.greedy_policy().unwrap();
    let evaluation = host::train::selection::Evaluation::new(
        select,
        &selecting.prepare().unwrap(),
        selecting.world.seed,
    )
    .unwrap();
    assert!(evaluation.formations(last) <= best.formations);

    assert_eq!(
        resumes_exactly(selecting, 1500, 2400),
        3,
        "formats 1 and 2 hold no selection"
    );
}
