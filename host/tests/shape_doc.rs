//! docs/shape.md's tables are what the runs give: the runs on shapes the
//! project never saw their report cards (`docs/shape/*.report.json`,
//! written by `host shape`), the runs on the report's shapes their cards
//! (`docs/shape/report/*.report.json`) and the evaluations beside the
//! shipped tables (`docs/shape/report/*.jsonl`, written by `host experiment
//! experiments/campaigns/shape-report.toml`).

use serde_json::Value;
use std::path::Path;

/// The lines around the table of unseen shapes.
const BEGIN: &str = "<!-- shape-runs begin: generated from docs/shape/*.report.json by host/tests/shape_doc.rs (the test prints it); do not edit -->";
const END: &str = "<!-- shape-runs end -->";

/// The lines around the table of the report's shapes.
const REPORT_BEGIN: &str = "<!-- shape-report begin: generated from docs/shape/report/ by host/tests/shape_doc.rs (the test prints it); do not edit -->";
const REPORT_END: &str = "<!-- shape-report end -->";

/// Formations per million at `level` (`default` or `2x`) of `who`.
fn level(card: &Value, who: &str, level: &str) -> f64 {
    card[who][level]
        .as_f64()
        .unwrap_or_else(|| panic!("report card without {who}.{level}"))
}

/// The report cards in `dir`, in file-name order.
fn cards(dir: &Path) -> Vec<std::path::PathBuf> {
    let mut files: Vec<_> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.to_string_lossy().ends_with(".report.json"))
        .collect();
    files.sort();
    assert!(!files.is_empty(), "no report cards in {}", dir.display());
    files
}

/// The table the cards in `dir` give, in file-name order.
fn table(dir: &Path) -> String {
    let files = cards(dir);
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

/// Formations summed over an evaluation's runs of `controller`.
fn evaluated(runs: &str, controller: &str) -> u64 {
    runs.lines()
        .map(|l| serde_json::from_str::<Value>(l).unwrap())
        .filter(|run| run["controller"] == format!("policy:{controller}"))
        .map(|run| {
            assert_eq!(run["steps"], 250_000);
            run["formations"].as_u64().unwrap()
        })
        .sum()
}

/// The table of the report's shapes: each card beside its evaluation.
fn report_table(dir: &Path) -> String {
    let mut out = String::from(
        "| shape | pucks | start | generations | result | general | result, report seeds | shipped table, report seeds | result / shipped | at least 0.8 |\n\
         | --- | ---: | --- | ---: | ---: | ---: | ---: | ---: | ---: | --- |\n",
    );
    let mut reached = 0;
    let files = cards(dir);
    for file in &files {
        let card: Value = serde_json::from_str(&std::fs::read_to_string(file).unwrap()).unwrap();
        let name = file
            .file_name()
            .unwrap()
            .to_string_lossy()
            .replace(".report.json", "");
        let runs = std::fs::read_to_string(dir.join(format!("{name}.jsonl"))).unwrap();
        let result = evaluated(&runs, &format!("docs/shape/report/{name}.policy"));
        let shipped = evaluated(&runs, &format!("policies/robot-search-{name}.policy"));
        let ratio = result as f64 / shipped.max(1) as f64;
        let met = ratio >= 0.8;
        reached += usize::from(met);
        out += &format!(
            "| `{}` | {} | {} | {} | {:.0} | {:.0} | {result} | {shipped} | {ratio:.2} | {} |\n",
            card["field"].as_str().unwrap(),
            card["pucks"],
            card["start"].as_str().unwrap(),
            card["generations"],
            level(&card, "result", "default"),
            level(&card, "general", "default"),
            if met { "yes" } else { "no" },
        );
    }
    out += &format!(
        "\nAt least 0.8 of the shipped table on {reached} of {} shapes.\n",
        files.len()
    );
    out
}

/// Fails unless docs/shape.md reads `expected` between the lines `begin`
/// and `end`, printing what it must read.
fn check_section(begin: &str, end: &str, expected: &str) {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let page = std::fs::read_to_string(root.join("docs/shape.md")).unwrap();
    let from = page
        .find(begin)
        .unwrap_or_else(|| panic!("no marker {begin}"))
        + begin.len()
        + 1;
    let to = page.find(end).unwrap_or_else(|| panic!("no marker {end}"));
    assert!(
        &page[from..to] == expected,
        "docs/shape.md's table differs from its runs; between the markers it must read:\n{expected}"
    );
}

#[test]
fn the_shape_pages_table_of_unseen_shapes_is_what_their_report_cards_give() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    check_section(BEGIN, END, &table(&root.join("docs/shape")));
}

#[test]
fn the_shape_pages_table_of_the_reports_shapes_is_what_their_cards_and_evaluations_give() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    check_section(
        REPORT_BEGIN,
        REPORT_END,
        &report_table(&root.join("docs/shape/report")),
    );
}
