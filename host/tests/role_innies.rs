//! One role assignment everywhere: a role-aware table (the role hashers)
//! runs with the innies a flashed swarm has, the robots of odd id
//! (`shared::Role::of_robot_id`), on every field: in `host run`, in a
//! learning run (and the orbital construction distilled for it), and in
//! the search's worlds; orbital construction itself keeps the thesis'
//! innies (half on the annulus, none on letters). A run's config hash
//! changes exactly where its innies did.

use host::experiment::plan::same_run;
use host::learn::StateHasherName;
use host::search::fitness::Scorer;
use host::train::TrainConfig;
use shared::{ActionId, PolicyTable, Role, State, StateHasher};
use sim::fields::source::FieldSource;
use sim::scenario::choices::{ScenarioChoices, WorldChoices};
use sim::scenario::{role_innies, ControllerChoice};
use std::path::PathBuf;

fn field(name: &str) -> FieldSource {
    name.parse().unwrap()
}

/// The TV world with the robot's senses on `name`, driven by `controller`.
fn tv(name: &str, controller: ControllerChoice) -> ScenarioChoices {
    ScenarioChoices {
        controller,
        world: WorldChoices {
            field: field(name),
            sensors: "robot".parse().unwrap(),
            ..WorldChoices::default()
        },
    }
}

fn policy(name: &str) -> ControllerChoice {
    ControllerChoice::Policy(
        PathBuf::from(env!("CARGO_MANIFEST_DIR"))
            .join("../policies")
            .join(name),
    )
}

#[test]
fn the_role_count_is_the_swarms_robots_of_odd_id() {
    for robots in 0..20usize {
        let odd = (0..robots)
            .filter(|&id| Role::of_robot_id(id as u8) == Role::Innie)
            .count();
        assert_eq!(role_innies(robots), odd);
    }
    assert_eq!(role_innies(5), 2, "ids 1 and 3 of 0 to 4");
}

#[test]
fn a_role_policy_runs_with_the_odd_ids_as_innies_on_every_field() {
    for name in ["annulus", "thesis:L", "gen:hook:100"] {
        let (sim, _) = tv(name, policy("robot-annulus-role.policy"))
            .scenario()
            .unwrap()
            .build()
            .unwrap();
        let world = &sim.config().world;
        assert_eq!((world.robots, world.innies), (5, 2), "{name}");
        let (sim, _) = tv(name, policy("robot-general.policy"))
            .scenario()
            .unwrap()
            .build()
            .unwrap();
        assert_eq!(
            sim.config().world.innies,
            0,
            "{name}: an 8-bit table has no roles"
        );
    }
    // orbital construction keeps the thesis' innies: none on a letter
    let (sim, _) = tv("thesis:L", ControllerChoice::Orbital)
        .scenario()
        .unwrap()
        .build()
        .unwrap();
    assert_eq!(sim.config().world.innies, 0);
}

/// A training config on the TV with the robot's senses on `name`.
fn training(name: &str, hasher: StateHasher) -> TrainConfig {
    let mut c = TrainConfig {
        world: WorldChoices {
            field: field(name),
            sensors: "robot".parse().unwrap(),
            robots: Some(5),
            ..Default::default()
        },
        ..TrainConfig::default()
    };
    c.learn.hasher = StateHasherName(hasher);
    c
}

#[test]
fn a_role_hasher_learning_run_has_them_on_every_field_unless_set() {
    for hasher in [StateHasher::OriginalRole, StateHasher::Bits9Role] {
        for name in ["annulus", "thesis:L"] {
            let c = training(name, hasher);
            assert_eq!(c.prepare().unwrap().config().world.innies, 2, "{name}");
            let set = TrainConfig {
                innies: Some(1),
                ..c
            };
            assert_eq!(set.prepare().unwrap().config().world.innies, 1, "{name}");
        }
    }
    let c = training("thesis:L", StateHasher::Original);
    assert_eq!(c.prepare().unwrap().config().world.innies, 0);
}

#[test]
fn a_runs_hash_changes_exactly_where_its_innies_did() {
    let with = |name: &str, innies| TrainConfig {
        innies,
        ..training(name, StateHasher::OriginalRole)
    };
    // on the annulus the flashed swarm's innies are orbital construction's
    assert!(same_run(&with("annulus", None), &with("annulus", Some(2))));
    // on a letter they are not: none set runs 2, as 2 set does, not as 0
    assert!(same_run(
        &with("thesis:L", None),
        &with("thesis:L", Some(2))
    ));
    assert!(!same_run(
        &with("thesis:L", None),
        &with("thesis:L", Some(0))
    ));
}

#[test]
fn the_search_scores_a_role_table_with_the_flashed_swarms_innies() {
    // the search's worlds of an 8-bit run on a letter, which has no innies
    // of its own; two role tables alike for outies, apart for innies
    let config = TrainConfig {
        world: WorldChoices {
            field: field("thesis:L"),
            robots: Some(6),
            pucks: Some(40),
            ..Default::default()
        },
        ..TrainConfig::default()
    };
    let scorer = Scorer::new(&[config], 1).unwrap();
    let mut same = PolicyTable::new(StateHasher::OriginalRole);
    let mut apart = PolicyTable::new(StateHasher::OriginalRole);
    for s in 0..256u16 {
        let outie = ActionId((s % 4) as u8);
        same.set(State(s), outie);
        same.set(State(s + 256), outie);
        apart.set(State(s), outie);
        apart.set(State(s + 256), ActionId(3 - (s % 4) as u8));
    }
    let scores = scorer.score(&[same, apart], &[7], 3000).unwrap();
    assert_ne!(scores[0], scores[1], "the innie half drives robots");
}
