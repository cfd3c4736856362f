//! The every-shape report (`experiments/every-shape.toml`) and its noise
//! experiments (`experiments/t-noise.toml`, the T's table;
//! `experiments/held-out-noise.toml`, the general table) are measured on worlds
//! that no policy they report was trained, searched or selected on:
//! none of its trial seeds is a seed of a published search's fitness or
//! validation worlds (`docs/policy-search/runs/*.search.json`), nor a
//! training run's seed (1 to 6), its selection world's or its
//! distillation world's.

use host::experiment::{plan::trial_seed, spec::ExperimentSpec};
use host::search::fitness::{fitness_seeds, validation_seeds};
use host::train::{distil::DISTIL_STREAM, selection::EVALUATION_STREAM};
use serde_json::Value;
use std::collections::BTreeSet;
use std::path::Path;

/// Trials per arm of the published report (`scripts/robot-senses`).
const TRIALS: usize = 10;

fn number(log: &Value, path: &[&str]) -> u64 {
    let mut v = log;
    for key in path {
        v = &v[*key];
    }
    v.as_u64()
        .unwrap_or_else(|| panic!("search log without a number at {path:?}"))
}

/// Every world seed the published searches scored or validated on.
fn search_seeds(runs: &Path) -> BTreeSet<u64> {
    let mut seeds = BTreeSet::new();
    let mut logs = 0;
    for entry in std::fs::read_dir(runs).expect("docs/policy-search/runs") {
        let path = entry.expect("a directory entry").path();
        if !path.to_string_lossy().ends_with(".search.json") {
            continue;
        }
        let text = std::fs::read_to_string(&path).expect("a search log");
        let log: Value = serde_json::from_str(&text).expect("a JSON search log");
        let seed = number(&log, &["world", "seed"]);
        let per_generation = number(&log, &["search", "fitness_seeds"]) as usize;
        let generations = log["generations"].as_array().expect("generations").len();
        for g in 0..generations as u64 {
            seeds.extend(fitness_seeds(seed, g, per_generation));
        }
        let validation = number(&log, &["search", "validation_seeds"]) as usize;
        let logged: Vec<u64> =
            serde_json::from_value(log["validation_seeds"].clone()).expect("the validation seeds");
        assert_eq!(
            logged,
            validation_seeds(seed, validation),
            "{}",
            path.display()
        );
        seeds.extend(logged);
        logs += 1;
    }
    assert!(logs >= 7, "{logs} search logs: one per shape expected");
    seeds
}

#[test]
fn no_trial_of_the_every_shape_report_or_its_noise_experiments_runs_on_a_world_a_policy_was_trained_or_selected_on(
) {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let mut used = search_seeds(&root.join("docs/policy-search/runs"));
    for run in 1..=6u64 {
        used.extend([run, run ^ EVALUATION_STREAM, run ^ DISTIL_STREAM]);
    }
    for (name, arms) in [
        ("every-shape", 7 * 4),
        ("t-noise", 16),
        ("held-out-noise", 24),
    ] {
        let spec = ExperimentSpec::load(name).expect("a built-in experiment");
        for arm in &spec.arms {
            for t in 0..TRIALS {
                let seed = trial_seed(spec.seed, &arm.name, t);
                assert!(
                    !used.contains(&seed),
                    "{name}: {} trial {t} runs on seed {seed}, which a search or training run used",
                    arm.name
                );
            }
        }
        assert!(spec.arms.len() >= arms, "{name}: {} arms", spec.arms.len());
    }
}
