//! docs/policy-search.md's results table says what
//! docs/policy-search/results.json holds (the JSON the publish stage of
//! experiments/campaigns/policy-search.toml writes; `host experiment
//! report` renders the page's tables from it).

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

fn results() -> serde_json::Value {
    let text = std::fs::read_to_string(root().join("docs/policy-search/results.json")).unwrap();
    serde_json::from_str(&text).unwrap()
}

/// A controller's formations per million steps over its report seeds.
fn per_million(controller: &serde_json::Value) -> f64 {
    let formations: Vec<f64> = controller["formations"]
        .as_array()
        .unwrap()
        .iter()
        .map(|f| f.as_f64().unwrap())
        .collect();
    let steps = controller["steps_per_seed"].as_f64().unwrap();
    formations.iter().sum::<f64>() * 1e6 / (steps * formations.len() as f64)
}

#[test]
fn every_measured_cell_of_the_policy_search_page_is_the_published_figure() {
    let root = root();
    let page = std::fs::read_to_string(root.join("docs/policy-search.md")).unwrap();
    let results = results();
    let shapes = results["shapes"].as_object().unwrap();
    assert!(
        shapes.len() >= 7,
        "every shape of the TV: {:?}",
        shapes.keys()
    );
    let mut cells = 0;
    for (field, controllers) in shapes {
        for (name, c) in controllers.as_object().unwrap() {
            let per_million = per_million(c);
            let prefix = format!("| {field} | {name} | ");
            let row = page
                .lines()
                .find(|l| l.starts_with(&prefix))
                .unwrap_or_else(|| panic!("no row {prefix}"));
            let shown: f64 = row[prefix.len()..]
                .split('|')
                .next()
                .unwrap()
                .trim()
                .replace(',', "")
                .parse()
                .unwrap();
            assert!((shown - per_million).abs() < 0.051, "{row}: {per_million}");
            cells += 1;
        }
    }
    assert!(cells >= 14, "{cells}");
}

/// The general policy is chosen on the shapes it was searched on alone,
/// by the search's own measure, never on the shapes it is evaluated on.
#[test]
fn the_shipped_general_policy_is_the_general_table_that_ranks_first_on_the_shapes_it_was_searched_on(
) {
    let results = results();
    // every general search's fields, as their logs name them
    let mut searched_on: Vec<&str> = Vec::new();
    for search in results["searches"].as_array().unwrap() {
        if search["name"].as_str().unwrap().starts_with("general") {
            for field in search["field"].as_str().unwrap().split(" + ") {
                if !searched_on.contains(&field) {
                    searched_on.push(field);
                }
            }
        }
    }
    assert!(!searched_on.is_empty(), "no general search's log");
    // run -> (shapes measured, sum of ln(1 + formations per million))
    let mut measure: BTreeMap<String, (usize, f64)> = BTreeMap::new();
    for &field in &searched_on {
        for c in results["shapes"][field].as_object().unwrap().values() {
            let policy = Path::new(c["policy"].as_str().unwrap());
            let run = policy.file_stem().unwrap().to_str().unwrap();
            if run.starts_with("general") {
                let m = measure.entry(run.to_string()).or_default();
                m.0 += 1;
                m.1 += per_million(c).ln_1p();
            }
        }
    }
    let best = measure
        .iter()
        .filter(|(_, (shapes, _))| *shapes == searched_on.len())
        .max_by(|a, b| a.1 .1.total_cmp(&b.1 .1))
        .map(|(run, _)| run.clone())
        .expect("general tables in the quick evaluation");
    let shipped = std::fs::read(root().join("policies/robot-general.policy")).unwrap();
    let ranked_first =
        std::fs::read(root().join(format!("docs/policy-search/runs/{best}.policy"))).unwrap();
    assert!(
        shipped == ranked_first,
        "policies/robot-general.policy is not {best}, the general table that ranks first: {measure:?}"
    );
}

/// Every table of the page, the held-out shapes' and the targets' among
/// them, is what the renderer gives from the published JSON.
#[test]
fn the_policy_search_pages_tables_are_what_the_renderer_gives_from_its_json() {
    let checked = host::experiment::campaign::publish::check_pages(&root().join("docs")).unwrap();
    assert!(
        checked.iter().any(|p| p.ends_with("policy-search.md")),
        "{checked:?}"
    );
}

/// The tables name each controller as the campaign's stage that made it.
#[test]
fn every_published_controller_is_named_by_the_label_of_the_stage_that_made_its_table() {
    let campaign = host::experiment::campaign::Campaign::load(
        &root().join("experiments/campaigns/policy-search.toml"),
    )
    .unwrap();
    let results = results();
    let mut named = 0;
    for controllers in results["shapes"].as_object().unwrap().values() {
        for (name, c) in controllers.as_object().unwrap() {
            let policy = c["policy"].as_str().unwrap();
            if policy == "oc" {
                assert_eq!(name, "orbital construction");
                continue;
            }
            let run = Path::new(policy).file_stem().unwrap().to_str().unwrap();
            let stage = campaign
                .stage(run)
                .unwrap_or_else(|| panic!("no stage {run}"));
            assert_eq!(name, &stage.label, "{run}");
            named += 1;
        }
    }
    assert!(named > 100, "{named}");
}
