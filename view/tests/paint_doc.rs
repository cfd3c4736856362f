//! docs/performance.md's live-view table is the one rendered from the
//! benchmark's published runs (docs/view-paint.json).

mod paint;

#[test]
fn the_performance_docs_paint_table_is_rendered_from_its_published_runs() {
    let root = concat!(env!("CARGO_MANIFEST_DIR"), "/..");
    let json = std::fs::read_to_string(format!("{root}/docs/view-paint.json")).unwrap();
    let results: serde_json::Value = serde_json::from_str(&json).unwrap();
    let doc = std::fs::read_to_string(format!("{root}/docs/performance.md")).unwrap();
    let table = paint::render(&results);
    assert!(
        doc.contains(&table),
        "docs/performance.md does not hold the table of docs/view-paint.json:\n{table}"
    );
}
