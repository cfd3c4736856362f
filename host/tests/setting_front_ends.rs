//! Each front end against the one declaration of the settings. A training
//! run's settings are the fields of `TrainConfig` (and of the structs it
//! holds, `LearnConfig` among them): their serde form is at once the keys
//! of a settings file and the record of a checkpoint, their clap form the
//! flags of `host train`. The world's settings are the fields of
//! `WorldChoices`, which the training config, `host run` and the live view
//! hand on whole to the scenario. These tests find every setting in each
//! front end (the flags, the file keys, the checkpoint's fields, the view's
//! URL parameters and page controls, Python's keyword arguments) and fail
//! on a missing or an extra one; the settings a front end does not offer
//! are listed here, each with why. (Every numeric flag has its row in the
//! table of ranges: `host/src/cli/flag_ranges.rs` checks that.)

use clap::Args;
use host::train::{checkpoint, TrainConfig, TrainFlags, Trainer};
use serde_json::Value;
use sim::scenario::choices::WorldChoices;
use std::collections::BTreeSet;
use std::path::Path;

/// Flags whose id is not the last part of their key.
const RENAMED_FLAGS: [(&str, &str); 5] = [
    ("check_every", "formation_check.every"),
    ("stale_check", "formation_check.stale"),
    ("out", "output.dir"),
    ("select_every", "select"),
    ("select_steps", "select"),
];

/// Settings of files only, no flag: a list, and the settings of the thesis
/// author's runs, which experiment files set.
const FILE_ONLY: [&str; 3] = ["learn.actions", "obstacle_discs", "success"];

/// Python's keyword arguments that are no setting of a training run: the
/// environments' own (episode length, observation and action spaces) and
/// the robot sensor model's settings, which `host` reads from a file
/// (`--sensors robot:FILE.json`).
const PYTHON_OWN: [&str; 6] = [
    "robot_config",
    "max_steps",
    "thresholds",
    "observation",
    "action",
    "forward_speed",
];

/// The dotted keys of a value's leaves (a nested object's keys joined with
/// dots; anything else a leaf).
fn keys(value: &Value, prefix: &str, out: &mut BTreeSet<String>) {
    match value {
        Value::Object(map) => {
            for (k, v) in map {
                let key = if prefix.is_empty() {
                    k.clone()
                } else {
                    format!("{prefix}.{k}")
                };
                keys(v, &key, out);
            }
        }
        _ => {
            out.insert(prefix.to_string());
        }
    }
}

/// The checkpoint of 10 steps of `config` with 2 robots and 5 pucks: its
/// bytes, and its body (CBOR) as JSON.
fn checkpoint_of(config: TrainConfig) -> (Vec<u8>, Value) {
    let config = TrainConfig {
        world: WorldChoices {
            robots: Some(2),
            pucks: Some(5),
            ..config.world.clone()
        },
        ..config
    };
    let mut t = Trainer::start(config, None).unwrap();
    t.run(10);
    let mut bytes = Vec::new();
    checkpoint::write_to(&mut bytes, &t.state()).unwrap();
    let body: ciborium::Value = ciborium::from_reader(&bytes[18..bytes.len() - 4]).unwrap();
    let body = serde_json::to_value(&body).unwrap();
    (bytes, body)
}

/// The keys of a training settings file: the config's serde form.
fn file_keys() -> BTreeSet<String> {
    let mut out = BTreeSet::new();
    keys(
        &serde_json::to_value(TrainConfig::default()).unwrap(),
        "",
        &mut out,
    );
    out
}

/// The settings of the world, by name.
fn world_settings() -> BTreeSet<String> {
    let Value::Object(map) = serde_json::to_value(WorldChoices::default()).unwrap() else {
        panic!("the world's settings are not a struct");
    };
    map.keys().cloned().collect()
}

/// `host train`'s setting flags: (id, key of the setting it sets).
fn flags() -> Vec<(String, String)> {
    let file = file_keys();
    TrainFlags::augment_args(clap::Command::new("train"))
        .get_arguments()
        .map(|a| {
            let id = a.get_id().to_string();
            let key = match RENAMED_FLAGS.iter().find(|(f, _)| *f == id) {
                Some((_, key)) => key.to_string(),
                None => {
                    let of: Vec<&String> = file
                        .iter()
                        .filter(|k| k.rsplit('.').next() == Some(id.as_str()))
                        .collect();
                    assert_eq!(of.len(), 1, "flag --{id}: keys {of:?}");
                    of[0].clone()
                }
            };
            (id, key)
        })
        .collect()
}

#[test]
fn every_training_setting_is_a_file_key_a_flag_and_a_field_of_the_checkpoint() {
    let file = file_keys();
    let flagged: BTreeSet<String> = flags().into_iter().map(|(_, key)| key).collect();
    let unflagged: Vec<&String> = file.difference(&flagged).collect();
    assert_eq!(
        unflagged, FILE_ONLY,
        "settings without a flag (a new setting needs `#[arg(long)]`, or a place in FILE_ONLY)"
    );
    assert!(
        flagged.is_subset(&file),
        "flags of no setting: {:?}",
        flagged.difference(&file).collect::<Vec<_>>()
    );
    // the checkpoint's record of the settings: the same keys
    let (_, body) = checkpoint_of(TrainConfig::default());
    let mut recorded = BTreeSet::new();
    keys(&body["config"], "", &mut recorded);
    assert_eq!(
        recorded, file,
        "the checkpoint records the settings by name"
    );
}

#[test]
fn the_views_url_parameters_are_the_world_settings_and_the_page_has_a_control_for_each() {
    let offered: BTreeSet<String> = world_settings()
        .into_iter()
        .filter(|k| !view::settings::SERVER_KEEPS.contains(&k.as_str()))
        .chain(["controller".to_string()])
        .collect();
    let parameters: BTreeSet<String> = view::settings::keys().into_iter().collect();
    assert_eq!(parameters, offered, "the view's URL parameters");
    // the page's controls: its own, and a text field for each setting the
    // server names that it has none for
    let page = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../view/src/page.html"),
    )
    .unwrap();
    assert!(
        page.contains("keys = m.settings.map(([k]) => k);") && page.contains("addControls(keys);"),
        "the page takes its settings from the server's"
    );
    // every parameter reads back as the setting it names
    let settings = view::ViewSettings::default();
    let again = settings
        .with_query(
            &view::settings::encode_query(&settings.pairs()),
            &Default::default(),
            &[],
        )
        .unwrap();
    assert_eq!(again, settings);
    let named: BTreeSet<String> = settings.pairs().into_iter().map(|(k, _)| k).collect();
    assert_eq!(
        named, parameters,
        "the view writes every parameter it reads"
    );
}

/// The fields of Python's keyword arguments (`EnvArgs` of the native
/// module's settings).
fn python_keywords() -> BTreeSet<String> {
    let text = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../python/src/settings.rs"),
    )
    .unwrap();
    let start = text.find("pub struct EnvArgs {").unwrap();
    let end = start + text[start..].find("\n}").unwrap();
    text[start..end]
        .lines()
        .filter_map(|l| l.trim().strip_prefix("pub "))
        .filter_map(|l| l.split_once(':').map(|(name, _)| name.to_string()))
        .filter(|name| !name.contains(' '))
        .collect()
}

#[test]
fn pythons_keyword_arguments_are_the_settings_of_the_same_names() {
    let python = python_keywords();
    let file = file_keys();
    let world = world_settings();
    // the world's settings Python does not name itself reach it by name
    assert!(
        python.contains("world"),
        "Python's arguments have no catch-all of the world's settings"
    );
    let native =
        std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("../python/src/lib.rs"))
            .unwrap();
    assert!(
        native.contains("arena = None, **world") && native.contains("WorldChoices::names()"),
        "the native batch takes the other world settings as **world, and names them"
    );
    for name in python.iter().filter(|n| *n != "world") {
        let a_setting = world.contains(name)
            || file
                .iter()
                .any(|k| k.rsplit('.').next() == Some(name.as_str()));
        assert!(
            a_setting || PYTHON_OWN.contains(&name.as_str()),
            "Python's keyword {name} is no setting of that name, nor one of PYTHON_OWN"
        );
    }
    for own in PYTHON_OWN {
        assert!(
            python.contains(own),
            "PYTHON_OWN lists {own}, which Python does not take"
        );
    }
}

#[test]
fn the_stuck_limit_declared_only_as_a_world_setting_reaches_every_front_end_and_the_world() {
    // the stuck limit of the world a front end's settings build
    let limit = |w: &WorldChoices| {
        let choices = sim::scenario::choices::ScenarioChoices {
            controller: sim::scenario::ControllerChoice::Random,
            world: w.clone(),
        };
        let prepared = choices.scenario().unwrap().prepare().unwrap();
        prepared.config().episode.stuck_limit
    };
    // host train's flag and a settings file's key
    let mut flagged = TrainConfig::default();
    TrainFlags::parse(["--stuck-limit", "700"])
        .unwrap()
        .apply(&mut flagged)
        .unwrap();
    let filed = TrainConfig::from_toml("stuck_limit = 700\n").unwrap();
    assert_eq!(flagged, filed);
    assert_eq!(limit(&filed.world), 700);
    // the checkpoint's record, and the run it resumes
    let (bytes, body) = checkpoint_of(filed.clone());
    assert_eq!(body["config"]["stuck_limit"], 700);
    assert_eq!(
        checkpoint::decode(&bytes).unwrap().config.world.stuck_limit,
        Some(700)
    );
    // the view's URL parameter
    let view = view::ViewSettings::default()
        .with_query("stuck_limit=700", &Default::default(), &[])
        .unwrap();
    assert_eq!(limit(&view.world), 700);
    assert!(view::settings::keys().contains(&"stuck_limit".to_string()));
    // Python's keyword argument: the world's setting by name, as text
    // (python/tests/test_arguments.py sees it end an episode)
    let mut python = WorldChoices::default();
    python.set("stuck_limit", "700").unwrap();
    assert_eq!(limit(&python), 700);
}
