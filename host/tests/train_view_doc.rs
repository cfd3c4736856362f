//! docs/performance.md's training-view table is the one rendered from the
//! benchmark's published runs (docs/train-view.json).

mod train_view_table;

#[test]
fn the_performance_docs_training_view_table_is_rendered_from_its_published_runs() {
    let root = concat!(env!("CARGO_MANIFEST_DIR"), "/..");
    let json = std::fs::read_to_string(format!("{root}/docs/train-view.json")).unwrap();
    let results: serde_json::Value = serde_json::from_str(&json).unwrap();
    let doc = std::fs::read_to_string(format!("{root}/docs/performance.md")).unwrap();
    let table = train_view_table::render(&results);
    assert!(
        doc.contains(&table),
        "docs/performance.md does not hold the table of docs/train-view.json:\n{table}"
    );
}
