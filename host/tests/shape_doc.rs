//! docs/shape.md's table of runs on shapes the project never saw is what
//! their report cards (`docs/shape/*.report.json`, written by `host shape`)
//! give.

use serde_json::Value;
use std::path::Path;

/// The lines around the table.
const BEGIN: &str = "<!-- shape-runs begin: generated from docs/shape/*.report.json by host/tests/shape_doc.rs (the test prints it); do not edit -->";
const END: &str = "<!-- shape-runs end -->";

/// Formations per million at `level` (`default` or `2x`) of `who`.
fn level(card: &Value, who: &str, level: &str) -> f64 {
    card[who][level]
        .as_f64()
        .unwrap_or_else(|| panic!("report card without {who}.{level}"))
}

/// The table the cards in `dir` give, in file-name order.
fn table(dir: &Path) -> String {
    let mut files: Vec<_> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.to_string_lossy().ends_with(".report.json"))
        .collect();
    files.sort();
    assert!(!files.is_empty(), "no report cards in {}", dir.display());
    let mut out = String::from(
        "| shape | pucks | start | generations | result | result, 2x | OC | OC, 2x | general | general, 2x | result / general | kept at 2x |\n\
         | --- | ---: | --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |\n",
    );
    for file in files {
        let card: Value = serde_json::from_str(&std::fs::read_to_string(&file).unwrap()).unwrap();
        let (result, general) = (
            level(&card, "result", "default"),
            level(&card, "general", "default"),
        );
        let ratio = |a: f64, b: f64| {
            if b > 0.0 {
                format!("{:.2}", a / b)
            } else {
                "-".to_string()
            }
        };
        out += &format!(
            "| `{}` | {} | {} | {} | {:.0} | {:.0} | {:.0} | {:.0} | {:.0} | {:.0} | {} | {} |\n",
            card["field"].as_str().unwrap(),
            card["pucks"],
            card["start"].as_str().unwrap(),
            card["generations"],
            result,
            level(&card, "result", "2x"),
            level(&card, "oc", "default"),
            level(&card, "oc", "2x"),
            general,
            level(&card, "general", "2x"),
            ratio(result, general),
            ratio(level(&card, "result", "2x"), result),
        );
    }
    out
}

#[test]
fn the_shape_pages_table_of_unseen_shapes_is_what_their_report_cards_give() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let page = std::fs::read_to_string(root.join("docs/shape.md")).unwrap();
    let begin = page
        .find(BEGIN)
        .expect("docs/shape.md has the table's begin marker")
        + BEGIN.len()
        + 1;
    let end = page
        .find(END)
        .expect("docs/shape.md has the table's end marker");
    let expected = table(&root.join("docs/shape"));
    assert!(
        page[begin..end] == expected,
        "docs/shape.md's table differs from its report cards; between the markers it must read:\n{expected}"
    );
}
