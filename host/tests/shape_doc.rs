//! docs/shape.md's tables are what the runs give: the results on shapes
//! the project never saw their evaluations beside OC and the general table
//! (`docs/shape/drawn-runs/*.jsonl`, written by `host experiment
//! experiments/campaigns/shape-drawn.toml`), the runs on the report's
//! shapes their cards (`docs/shape/report/*.report.json`, written by `host
//! shape`) and the evaluations beside the shipped tables
//! (`docs/shape/report/*.jsonl`, written by `host experiment
//! experiments/campaigns/shape-report.toml`).

use serde_json::Value;
use std::path::Path;

/// The lines around the table of unseen shapes.
const BEGIN: &str = "<!-- shape-runs begin: generated from docs/shape/drawn-runs/*.jsonl by host/tests/shape_doc.rs (the test prints it); do not edit -->";
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

/// `a / b` to two places, `-` where `b` is 0.
fn ratio(a: u64, b: u64) -> String {
    if b > 0 {
        format!("{:.2}", a as f64 / b as f64)
    } else {
        "-".to_string()
    }
}

/// The table the evaluations in `dir` give (`NAME.jsonl` at the default
/// noise, `NAME-2x.jsonl` at twice it), in file-name order.
fn table(dir: &Path) -> String {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter_map(|n| n.strip_suffix(".jsonl").map(String::from))
        .filter(|n| !n.ends_with("-2x"))
        .collect();
    names.sort();
    assert!(!names.is_empty(), "no evaluations in {}", dir.display());
    let mut out = String::from(
        "| shape | result | result, 2x | OC | OC, 2x | general | general, 2x | result / OC | result / general | kept at 2x |\n\
         | --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: | ---: |\n",
    );
    for name in names {
        let runs = |suffix: &str| {
            std::fs::read_to_string(dir.join(format!("{name}{suffix}.jsonl"))).unwrap()
        };
        let (once, twice) = (runs(""), runs("-2x"));
        let result = format!("docs/shape/{name}.policy");
        let general = "policies/robot-general.policy";
        let (r, r2) = (evaluated(&once, &result), evaluated(&twice, &result));
        let (o, o2) = (evaluated(&once, "oc"), evaluated(&twice, "oc"));
        let (g, g2) = (evaluated(&once, general), evaluated(&twice, general));
        out += &format!(
            "| `docs/shape/drawn/{name}.png` | {r} | {r2} | {o} | {o2} | {g} | {g2} | {} | {} | {} |\n",
            ratio(r, o),
            ratio(r, g),
            ratio(r2, r),
        );
    }
    out
}

/// Formations summed over an evaluation's runs of `controller` (`oc` or
/// a policy file).
fn evaluated(runs: &str, controller: &str) -> u64 {
    let name = match controller {
        "oc" => "oc".to_string(),
        file => format!("policy:{file}"),
    };
    runs.lines()
        .map(|l| serde_json::from_str::<Value>(l).unwrap())
        .filter(|run| run["controller"] == name.as_str())
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
        let met = result as f64 >= 0.8 * shipped as f64;
        reached += usize::from(met);
        out += &format!(
            "| `{}` | {} | {} | {} | {:.0} | {:.0} | {result} | {shipped} | {} | {} |\n",
            card["field"].as_str().unwrap(),
            card["pucks"],
            card["start"].as_str().unwrap(),
            card["generations"],
            level(&card, "result", "default"),
            level(&card, "general", "default"),
            ratio(result, shipped),
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
fn the_shape_pages_table_of_unseen_shapes_is_what_their_evaluations_give() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    check_section(BEGIN, END, &table(&root.join("docs/shape/drawn-runs")));
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
