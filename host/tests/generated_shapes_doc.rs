//! docs/generated-shapes.md's tables are what the general-shapes campaign's
//! evaluations (`docs/generated-shapes/evaluate-shapes*.jsonl`, written by
//! `host experiment experiments/campaigns/general-shapes.toml`) give.

use serde_json::Value;
use std::collections::BTreeMap;
use std::path::Path;

/// The lines around the tables.
const BEGIN: &str = "<!-- generated-shapes begin: generated from docs/generated-shapes/*.jsonl by host/tests/generated_shapes_doc.rs (the test prints it); do not edit -->";
const END: &str = "<!-- generated-shapes end -->";

/// The controllers as the evaluation names them, and as the table does.
const CONTROLLERS: [(&str, &str); 3] = [
    ("oc", "OC"),
    ("policy:policies/robot-general.policy", "general"),
    ("shapes-from-general", "searched"),
];

/// Formations summed over the seeds, by field and controller, in the
/// evaluation's order of fields.
type Sums = (Vec<String>, BTreeMap<(String, String), u64>);

fn sums(file: &Path) -> Sums {
    let text = std::fs::read_to_string(file).unwrap();
    let (mut fields, mut sums) = (Vec::new(), BTreeMap::new());
    for line in text.lines() {
        let run: Value = serde_json::from_str(line).unwrap();
        let field = run["field"].as_str().unwrap().to_string();
        let controller = run["controller"].as_str().unwrap();
        let controller = CONTROLLERS
            .iter()
            .find(|(c, _)| controller == *c || controller.ends_with(&format!("/{c}.policy")))
            .map_or(controller, |(_, name)| name)
            .to_string();
        assert_eq!(run["steps"], 250_000, "{line}");
        if !fields.contains(&field) {
            fields.push(field.clone());
        }
        *sums.entry((field, controller)).or_default() += run["formations"].as_u64().unwrap();
    }
    (fields, sums)
}

/// Which part of the distribution a field is.
fn split(field: &str) -> &'static str {
    match field.strip_prefix("gen:") {
        Some(shape) if shape.starts_with("hook:") || shape.starts_with("outline:") => "held out",
        Some(_) => "unseen seed",
        None => "report",
    }
}

/// The tables the evaluations in `dir` give.
fn tables(dir: &Path) -> String {
    let (fields, default) = sums(&dir.join("evaluate-shapes.jsonl"));
    let (_, twice) = sums(&dir.join("evaluate-shapes-2x.jsonl"));
    let get = |sums: &BTreeMap<(String, String), u64>, f: &str, c: &str| {
        sums.get(&(f.to_string(), c.to_string())).copied()
    };
    let show = |v: Option<u64>| v.map_or("-".to_string(), |v| v.to_string());
    let mut out = String::from(
        "| shape | split | OC | general | searched | general, 2x | searched, 2x |\n\
         | --- | --- | ---: | ---: | ---: | ---: | ---: |\n",
    );
    // per split: shapes; the general's and the searched table's shapes
    // with at least 25; shapes where OC forms 20 or more, and where each
    // table forms at least OC's count there
    let mut summary: BTreeMap<&str, [u64; 6]> = BTreeMap::new();
    for f in &fields {
        out += &format!(
            "| `{f}` | {} | {} | {} | {} | {} | {} |\n",
            split(f),
            show(get(&default, f, "OC")),
            show(get(&default, f, "general")),
            show(get(&default, f, "searched")),
            show(get(&twice, f, "general")),
            show(get(&twice, f, "searched")),
        );
        let s = summary.entry(split(f)).or_default();
        s[0] += 1;
        s[1] += u64::from(get(&default, f, "general").unwrap_or(0) >= 25);
        s[2] += u64::from(get(&default, f, "searched").unwrap_or(0) >= 25);
        let oc = get(&default, f, "OC").unwrap_or(0);
        if oc >= 20 {
            s[3] += 1;
            s[4] += u64::from(get(&default, f, "general").unwrap_or(0) >= oc);
            s[5] += u64::from(get(&default, f, "searched").unwrap_or(0) >= oc);
        }
    }
    out += "\n| split | shapes | general: at least 25 | searched: at least 25 | OC: at least 20 | general: at least OC there | searched: at least OC there |\n\
            | --- | ---: | ---: | ---: | ---: | ---: | ---: |\n";
    for (split, s) in summary {
        out += &format!(
            "| {split} | {} | {} | {} | {} | {} | {} |\n",
            s[0], s[1], s[2], s[3], s[4], s[5]
        );
    }
    out
}

#[test]
fn the_generated_shapes_pages_tables_are_what_the_evaluations_give() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let page = std::fs::read_to_string(root.join("docs/generated-shapes.md")).unwrap();
    let begin = page.find(BEGIN).expect("the begin marker") + BEGIN.len() + 1;
    let end = page.find(END).expect("the end marker");
    let expected = tables(&root.join("docs/generated-shapes"));
    assert!(
        page[begin..end] == expected,
        "docs/generated-shapes.md's tables differ from the evaluations; between the markers they must read:\n{expected}"
    );
}
