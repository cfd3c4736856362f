//! Every arm's puck count on a screen arena is the puck rule's
//! (`sim::scenario::puck_rule`) unless the arm sets another with its reason
//! (`pucks_reason`); a count that differs without one is refused naming
//! the file and the arm; and trials hashed with the count left to the
//! arena still match their arms.

use host::experiment::plan::plans;
use host::experiment::spec::{ExperimentSpec, BUILT_IN};
use sim::scenario::puck_rule::rule_pucks;
use sim::scenario::Arena;
use std::path::Path;

fn root() -> &'static Path {
    Path::new(concat!(env!("CARGO_MANIFEST_DIR"), "/.."))
}

#[test]
fn every_arm_of_every_experiment_file_takes_the_rule_count_or_states_why_not() {
    // from the repository root, against which files name their arenas
    std::env::set_current_dir(root()).unwrap();
    let mut unexplained = Vec::new();
    let mut on_screens = 0;
    for (name, text) in BUILT_IN {
        let spec = ExperimentSpec::parse(name, text).unwrap();
        let raw: toml::Table = toml::from_str(text).unwrap();
        let written_in_defaults = raw.get("defaults").and_then(|d| d.get("pucks")).is_some();
        let raw_arms = raw["arms"].as_array().unwrap();
        for (arm, table) in spec.arms.iter().zip(raw_arms) {
            let Ok(arena @ Arena::Screen(_)) = arm.config.arena_choice().arena() else {
                continue;
            };
            on_screens += 1;
            let rule = rule_pucks(&arm.config.world.field, &arena).unwrap();
            let written = written_in_defaults || table.get("pucks").is_some();
            if arm.pucks_reason.is_none() && (arm.config.world.pucks != Some(rule) || written) {
                unexplained.push(format!(
                    "experiments/{name}.toml, arm {:?}: {:?} pucks, rule {rule}{}",
                    arm.name,
                    arm.config.world.pucks,
                    if written { ", written in the file" } else { "" }
                ));
            }
        }
    }
    assert!(on_screens > 200, "only {on_screens} arms on a screen");
    assert!(unexplained.is_empty(), "{unexplained:#?}");
}

const ON_THE_TV: &str = "title = \"t\"\n[defaults]\nsensors = \"robot\"\narena = \"tv75\"\nfield = \"letter:I\"\nsteps = 100\n[[arms]]\nname = \"I\"\ncontroller = \"oc\"\n";

#[test]
fn a_count_other_than_the_rules_needs_a_reason_and_the_error_names_file_and_arm() {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("odd.toml");
    let plain = ExperimentSpec::parse("x", ON_THE_TV).unwrap();
    assert_eq!(
        plain.arms[0].config.world.pucks,
        Some(11),
        "our I takes 11 on the TV"
    );
    std::fs::write(
        &path,
        ON_THE_TV.replace("steps = 100", "steps = 100\npucks = 12"),
    )
    .unwrap();
    let e = format!(
        "{:#}",
        ExperimentSpec::load(path.to_str().unwrap()).unwrap_err()
    );
    assert!(
        e.contains("odd.toml") && e.contains("arm \"I\"") && e.contains("pucks_reason"),
        "{e}"
    );
    let explained = ON_THE_TV.replace(
        "controller = \"oc\"",
        "controller = \"oc\"\npucks = 12\npucks_reason = \"as many as the annulus\"",
    );
    let spec = ExperimentSpec::parse("x", &explained).unwrap();
    assert_eq!(spec.arms[0].config.world.pucks, Some(12));
    let stray = ON_THE_TV.replace(
        "controller = \"oc\"",
        "controller = \"oc\"\npucks_reason = \"x\"",
    );
    let e = format!("{:#}", ExperimentSpec::parse("x", &stray).unwrap_err());
    assert!(e.contains("pucks_reason without pucks"), "{e}");
}

#[test]
fn a_trial_hashed_with_the_count_left_to_the_arena_is_still_its_arms() {
    let annulus = ON_THE_TV.replace("letter:I", "annulus");
    let spec = ExperimentSpec::parse("x", &annulus).unwrap();
    assert_eq!(spec.arms[0].config.world.pucks, Some(12));
    let plan = &plans(&spec, 1, 1.0, 1)[0];
    // the same arm as hashed before the rule: the count unset
    let mut unset = spec.clone();
    unset.arms[0].config.world.pucks = None;
    let before = &plans(&unset, 1, 1.0, 1)[0];
    assert_ne!(plan.hash, before.hash);
    assert!(plan.matches(&before.hash));
    // our I's 11 is not the arena's 12: no other hash is its
    let spec = ExperimentSpec::parse("x", ON_THE_TV).unwrap();
    assert_eq!(plans(&spec, 1, 1.0, 1)[0].alias, None);
}
