//! The held-out split of the generated shapes (`sim::fields::generated`,
//! `Family::HELD_OUT`) is held out: no search or training stage of any
//! campaign (`experiments/campaigns/`) scores on a shape of a held-out
//! family, so what the evaluations report on them is on shapes no learning
//! saw.

use sim::fields::generated::Family;
use sim::fields::source::FieldSource;
use std::path::Path;

/// The fields a stage learns on: its `field` (or the defaults') and its
/// `also_field`.
fn learned_on(stage: &toml::Table, defaults: &toml::Table) -> Vec<String> {
    let key = |k: &str| stage.get(k).or_else(|| defaults.get(k)).cloned();
    let mut fields: Vec<String> = key("field")
        .and_then(|v| v.as_str().map(String::from))
        .into_iter()
        .collect();
    if let Some(toml::Value::Array(also)) = key("also_field") {
        fields.extend(also.iter().filter_map(|v| v.as_str().map(String::from)));
    }
    fields
}

#[test]
fn no_search_or_training_stage_of_any_campaign_scores_on_a_held_out_shape() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../experiments/campaigns");
    let mut learned = 0;
    for entry in std::fs::read_dir(&dir).unwrap() {
        let path = entry.unwrap().path();
        let file: toml::Table = std::fs::read_to_string(&path).unwrap().parse().unwrap();
        let defaults = file
            .get("defaults")
            .and_then(|d| d.as_table())
            .cloned()
            .unwrap_or_default();
        for stage in file["stages"].as_array().unwrap() {
            let stage = stage.as_table().unwrap();
            if !matches!(stage["kind"].as_str(), Some("search" | "train")) {
                continue;
            }
            for name in learned_on(stage, &defaults) {
                let field: FieldSource = name.parse().unwrap();
                if let FieldSource::Generated(shape) = field {
                    assert!(
                        !shape.family.held_out(),
                        "{}: stage {} learns on {name}, a held-out shape",
                        path.display(),
                        stage["name"]
                    );
                    learned += 1;
                }
            }
        }
    }
    assert!(learned > 0, "some stage learns on generated shapes");
    assert!(Family::HELD_OUT.iter().all(|f| f.held_out()));
}
