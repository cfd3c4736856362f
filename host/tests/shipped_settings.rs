//! Every shipped configuration passes the table of plausible ranges
//! (`sim::base::ranges`, `docs/ranges.md`): each experiment of
//! `experiments/` (every arm's and pre-training's settings, built once, at
//! the thesis' scale and at the quick look's), every robot sensor file of
//! `experiments/robot-senses/` in every built-in arena, the letter images
//! of `experiments/fields/` and the policies of `policies/`.
//!
//! One test in its own binary: it works in the repository's root, where
//! the experiment files' paths (`robot:experiments/robot-senses/...`)
//! start.

use host::experiment::runner::check_settings;
use host::experiment::ExperimentSpec;
use host::train::TrainConfig;
use sim::fields::source::FieldSource;
use sim::scenario::arena_choice::ArenaChoice;
use sim::scenario::choices::WorldChoices;
use sim::scenario::sensor_choice::SensorChoice;
use std::path::{Path, PathBuf};

/// The files of `dir` whose names end in `ext`, sorted.
fn files(dir: &str, ext: &str) -> Vec<PathBuf> {
    let mut out: Vec<PathBuf> = std::fs::read_dir(dir)
        .unwrap_or_else(|e| panic!("cannot list {dir}: {e}"))
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|x| x == ext))
        .collect();
    out.sort();
    assert!(!out.is_empty(), "no *.{ext} in {dir}");
    out
}

#[test]
fn every_shipped_configuration_passes_the_table_of_plausible_ranges() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    std::env::set_current_dir(&root).unwrap();

    let experiments = files("experiments", "toml");
    for path in &experiments {
        let spec = ExperimentSpec::load(&path.display().to_string())
            .unwrap_or_else(|e| panic!("{}: {e:#}", path.display()));
        for scale in [1.0, 0.001] {
            if let Err(e) = check_settings(&spec, scale, spec.seed) {
                panic!("{} at scale {scale}: {e:#}", path.display());
            }
        }
    }
    assert!(experiments.len() >= 11, "{experiments:?}");

    let robot_files = files("experiments/robot-senses", "json");
    let mut sensors = vec!["disc".to_string(), "robot".to_string()];
    sensors.extend(robot_files.iter().map(|p| format!("robot:{}", p.display())));
    for arena in ["thesis", "tv75"] {
        for s in &sensors {
            let config = TrainConfig {
                world: WorldChoices {
                    arena: Some(arena.parse::<ArenaChoice>().unwrap()),
                    sensors: s.parse::<SensorChoice>().unwrap(),
                    ..Default::default()
                },
                ..TrainConfig::default()
            };
            if let Err(e) = config.prepare() {
                panic!("arena {arena}, sensors {s}: {e:#}");
            }
        }
    }

    for image in files("experiments/fields", "png") {
        if let Err(e) = FieldSource::Image(image.clone()).load() {
            panic!("{}: {e}", image.display());
        }
    }

    for policy in files("policies", "policy") {
        if let Err(e) = sim::control::policy_file::read(&policy) {
            panic!("{e}");
        }
    }
}
