//! docs/policy-search.md's results table says what
//! docs/policy-search/results.json holds (the JSON `scripts/policy-search`
//! publishes; `scripts/policy-search-publish.py` renders the page).

use std::path::Path;

#[test]
fn every_measured_cell_of_the_policy_search_page_is_the_published_figure() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let page = std::fs::read_to_string(root.join("docs/policy-search.md")).unwrap();
    let text = std::fs::read_to_string(root.join("docs/policy-search/results.json")).unwrap();
    let results: serde_json::Value = serde_json::from_str(&text).unwrap();
    let shapes = results["shapes"].as_object().unwrap();
    assert!(
        shapes.len() >= 7,
        "every shape of the TV: {:?}",
        shapes.keys()
    );
    let mut cells = 0;
    for (field, controllers) in shapes {
        for (name, c) in controllers.as_object().unwrap() {
            let formations: Vec<f64> = c["formations"]
                .as_array()
                .unwrap()
                .iter()
                .map(|f| f.as_f64().unwrap())
                .collect();
            let steps = c["steps_per_seed"].as_f64().unwrap();
            let per_million =
                formations.iter().sum::<f64>() * 1e6 / (steps * formations.len() as f64);
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
