//! docs/generated-shapes.md's tables are what the campaigns' evaluations
//! give: the general-shapes campaign's
//! (`docs/generated-shapes/evaluate-shapes*.jsonl`, written by `host
//! experiment experiments/campaigns/general-shapes.toml`) and the
//! general-state campaign's (`docs/generated-shapes/evaluate-states.jsonl`
//! and its tables, `state-*.policy`, written by `host experiment
//! experiments/campaigns/general-state.toml`) and the general-policy
//! campaign's (`docs/generated-shapes/evaluate-policy*.jsonl`, written by
//! `host experiment experiments/campaigns/general-policy.toml`) and the
//! general-hold campaign's search log
//! (`docs/generated-shapes/general-hold.search.json`, written by `host
//! experiment experiments/campaigns/general-hold.toml`).

use serde_json::Value;
use std::collections::BTreeMap;
use std::path::Path;

/// The lines around the general-shapes campaign's tables.
const BEGIN: &str = "<!-- generated-shapes begin: generated from docs/generated-shapes/*.jsonl by host/tests/generated_shapes_doc.rs (the test prints it); do not edit -->";
const END: &str = "<!-- generated-shapes end -->";

/// The lines around the general-policy campaign's tables.
const POLICY_BEGIN: &str = "<!-- general-policy begin: generated from docs/generated-shapes/evaluate-policy*.jsonl by host/tests/generated_shapes_doc.rs (the test prints it); do not edit -->";
const POLICY_END: &str = "<!-- general-policy end -->";

/// The lines around the general-hold campaign's tables.
const HOLD_BEGIN: &str = "<!-- general-hold begin: generated from docs/generated-shapes/general-hold.search.json by host/tests/generated_shapes_doc.rs (the test prints it); do not edit -->";
const HOLD_END: &str = "<!-- general-hold end -->";

/// The lines around the annulus-first lineage's table.
const ANNULUS_FIRST_BEGIN: &str = "<!-- annulus-first begin: generated from docs/generated-shapes/evaluate-after-annulus.jsonl by host/tests/generated_shapes_doc.rs (the test prints it); do not edit -->";
const ANNULUS_FIRST_END: &str = "<!-- annulus-first end -->";

/// The lines around the general-state campaign's tables.
const STATES_BEGIN: &str = "<!-- general-state begin: generated from docs/generated-shapes/evaluate-states.jsonl and state-*.policy by host/tests/generated_shapes_doc.rs (the test prints it); do not edit -->";
const STATES_END: &str = "<!-- general-state end -->";

/// The controllers as the evaluations name them, and as the tables do
/// (each evaluation runs one searched table).
const CONTROLLERS: [(&str, &str); 4] = [
    ("oc", "OC"),
    ("policy:policies/robot-general.policy", "general"),
    ("shapes-from-general", "searched"),
    ("general-role", "searched"),
];

/// The general-state campaign's tables (stage names, also their files in
/// docs/generated-shapes/), in the table's order.
const STATES: [&str; 5] = [
    "state-original",
    "state-bits9",
    "state-obstacle",
    "state-role",
    "state-bits9-role",
];

/// Formations summed over the seeds, by field and controller, in the
/// evaluation's order of fields.
type Sums = (Vec<String>, BTreeMap<(String, String), u64>);

fn sums(file: &Path) -> Sums {
    sums_named(file, &CONTROLLERS)
}

/// [`sums`] with the controllers named by `names` (evaluation's name or
/// stage, table's name); others keep the evaluation's name.
fn sums_named(file: &Path, names: &[(&str, &str)]) -> Sums {
    let text = std::fs::read_to_string(file).unwrap();
    let (mut fields, mut sums) = (Vec::new(), BTreeMap::new());
    for line in text.lines() {
        let run: Value = serde_json::from_str(line).unwrap();
        let field = run["field"].as_str().unwrap().to_string();
        let controller = run["controller"].as_str().unwrap();
        let controller = names
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

/// The tables that the evaluation `evaluation` in `dir` gives, at the
/// default noise and (`evaluation-2x`) twice it.
fn tables(dir: &Path, evaluation: &str) -> String {
    let (fields, default) = sums(&dir.join(format!("{evaluation}.jsonl")));
    let (_, twice) = sums(&dir.join(format!("{evaluation}-2x.jsonl")));
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

/// Formations per shape (a row each, with its split) of the controllers
/// `names` (a column each, by the table's name).
fn per_shape((fields, sums): &Sums, names: &[(&str, &str)]) -> String {
    let mut out = format!(
        "| shape | split | {} |\n| --- | --- |{}\n",
        names
            .iter()
            .map(|(_, n)| *n)
            .collect::<Vec<_>>()
            .join(" | "),
        " ---: |".repeat(names.len())
    );
    for f in fields {
        let cells: Vec<String> = names
            .iter()
            .map(|(_, c)| {
                sums.get(&(f.clone(), c.to_string()))
                    .map_or("-".to_string(), |v| v.to_string())
            })
            .collect();
        out += &format!("| `{f}` | {} | {} |\n", split(f), cells.join(" | "));
    }
    out
}

/// The general-hold search's generations: each challenger's balance
/// against the start's, and the worlds (shape and noise level) where it
/// formed less than the hold share of the start's count, the report's
/// shapes by name with the share they kept.
fn hold_table(dir: &Path) -> String {
    let text = std::fs::read_to_string(dir.join("general-hold.search.json")).unwrap();
    let log: Value = serde_json::from_str(&text).unwrap();
    let search = &log["search"];
    let hold = search["hold_share"].as_f64().unwrap();
    let shapes: Vec<String> = std::iter::once(&log["world"]["field"])
        .chain(search["also_field"].as_array().unwrap())
        .map(|f| f.as_str().unwrap().to_string())
        .collect();
    let noises: Vec<String> = std::iter::once("default".to_string())
        .chain(
            search["also_noise"]
                .as_array()
                .unwrap()
                .iter()
                .map(|n| format!("{}x", n.as_f64().unwrap())),
        )
        .collect();
    let worlds: Vec<(String, String)> = shapes
        .iter()
        .flat_map(|s| noises.iter().map(move |n| (s.clone(), n.clone())))
        .collect();
    let counts = |score: &Value| -> Vec<u64> {
        score["fields"]
            .as_array()
            .unwrap()
            .iter()
            .map(|c| c.as_u64().unwrap())
            .collect()
    };
    let start = counts(&log["start_validation"]);
    assert_eq!(
        start.len(),
        worlds.len(),
        "a count per shape and noise level"
    );
    let start_balance = log["start_validation"]["balance"].as_f64().unwrap();
    let mut out = format!(
        "| generation | challenger's balance (start {start_balance:.2}) | replaced the result | worlds below {hold} of the start | report shapes below it (share kept) |\n\
         | ---: | ---: | --- | ---: | --- |\n"
    );
    for g in log["generations"].as_array().unwrap() {
        let challenger = &g["challenger_validation"];
        let below: Vec<(&(String, String), f64)> = counts(challenger)
            .iter()
            .zip(&start)
            .zip(&worlds)
            .filter(|((&mine, &theirs), _)| (mine as f64) < hold * theirs as f64)
            .map(|((&mine, &theirs), world)| (world, mine as f64 / theirs as f64))
            .collect();
        let report: Vec<String> = below
            .iter()
            .filter(|((shape, _), _)| split(shape) == "report")
            .map(|((shape, noise), share)| format!("`{shape}` {noise} {share:.2}"))
            .collect();
        out += &format!(
            "| {} | {:.2} | {} | {} of {} | {} |\n",
            g["generation"].as_u64().unwrap() + 1,
            challenger["balance"].as_f64().unwrap(),
            if g["replaced"].as_bool().unwrap() {
                "yes"
            } else {
                "no"
            },
            below.len(),
            worlds.len(),
            report.join(", ")
        );
    }
    out
}

/// The annulus-first lineage's table: its two tables per shape.
fn annulus_first_table(dir: &Path) -> String {
    let names = [
        ("general-role-annulus", "annulus first"),
        ("general-role-after-annulus", "then every shape"),
    ];
    per_shape(
        &sums_named(&dir.join("evaluate-after-annulus.jsonl"), &names),
        &names,
    )
}

/// The general-state campaign's tables: formations per shape of OC, the
/// shipped general table and each state's table; then per table its
/// hasher and entries and how it does on the splits.
fn state_tables(dir: &Path) -> String {
    let mut names = vec![
        ("oc", "OC"),
        ("policy:policies/robot-general.policy", "general"),
    ];
    names.extend(
        STATES
            .iter()
            .map(|s| (*s, s.strip_prefix("state-").unwrap())),
    );
    let (fields, sums) = sums_named(&dir.join("evaluate-states.jsonl"), &names);
    let get = |f: &str, c: &str| sums.get(&(f.to_string(), c.to_string())).copied();
    let mut out = per_shape(&(fields.clone(), sums.clone()), &names);
    out += "\n| table | state | entries | held out: at least 25 | unseen seeds: at least 25 | held out: sum of ln(1 + formations) | at least OC where OC forms 20 or more | report: at least the general table |\n\
            | --- | --- | ---: | ---: | ---: | ---: | ---: | ---: |\n";
    let of_split =
        |which: &str| -> Vec<&String> { fields.iter().filter(|f| split(f) == which).collect() };
    let (held, unseen, report) = (
        of_split("held out"),
        of_split("unseen seed"),
        of_split("report"),
    );
    let oc_forms: Vec<(&String, u64)> = fields
        .iter()
        .filter_map(|f| get(f, "OC").filter(|&oc| oc >= 20).map(|oc| (f, oc)))
        .collect();
    for (stage, name) in names.iter().skip(1) {
        let (state, entries) = if *name == "general" {
            blob_state(&dir.join("../../policies/robot-general.policy"))
        } else {
            blob_state(&dir.join(format!("{stage}.policy")))
        };
        let at_least = |shapes: &[&String], n: u64| {
            shapes
                .iter()
                .filter(|f| get(f, name).unwrap_or(0) >= n)
                .count()
        };
        let balance: f64 = held
            .iter()
            .map(|f| (get(f, name).unwrap_or(0) as f64).ln_1p())
            .sum();
        let over_oc = oc_forms
            .iter()
            .filter(|(f, oc)| get(f, name).unwrap_or(0) >= *oc)
            .count();
        let over_general = report
            .iter()
            .filter(|f| get(f, name).unwrap_or(0) >= get(f, "general").unwrap_or(0))
            .count();
        out += &format!(
            "| {name} | `{state}` | {entries} | {} of {} | {} of {} | {balance:.1} | {over_oc} of {} | {over_general} of {} |\n",
            at_least(&held, 25),
            held.len(),
            at_least(&unseen, 25),
            unseen.len(),
            oc_forms.len(),
            report.len(),
        );
    }
    out
}

/// A policy file's hasher name and its table's entries.
fn blob_state(file: &Path) -> (&'static str, usize) {
    let blob = shared::PolicyBlob::decode(&std::fs::read(file).unwrap()).unwrap();
    (blob.hasher().name(), blob.hasher().num_states())
}

/// The campaigns' outputs copied for the page.
fn data() -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../docs/generated-shapes")
}

/// Fails unless the page reads `expected` between the markers.
fn assert_between(begin: &str, end: &str, expected: &str) {
    let file = Path::new(env!("CARGO_MANIFEST_DIR")).join("../docs/generated-shapes.md");
    let page = std::fs::read_to_string(file).unwrap();
    let from = page.find(begin).expect("the begin marker") + begin.len() + 1;
    let to = page.find(end).expect("the end marker");
    assert!(
        page[from..to] == *expected,
        "docs/generated-shapes.md differs from the campaign's outputs; after {begin} it must read:\n{expected}"
    );
}

#[test]
fn the_general_state_tables_are_what_the_evaluation_gives() {
    assert_between(STATES_BEGIN, STATES_END, &state_tables(&data()));
}

#[test]
fn the_generated_shapes_pages_tables_are_what_the_evaluations_give() {
    assert_between(BEGIN, END, &tables(&data(), "evaluate-shapes"));
}

#[test]
fn the_general_policy_tables_are_what_its_evaluations_give() {
    assert_between(
        POLICY_BEGIN,
        POLICY_END,
        &tables(&data(), "evaluate-policy"),
    );
}

#[test]
fn the_general_hold_table_is_what_its_search_log_gives() {
    assert_between(HOLD_BEGIN, HOLD_END, &hold_table(&data()));
}

#[test]
fn the_annulus_first_table_is_what_its_evaluation_gives() {
    assert_between(
        ANNULUS_FIRST_BEGIN,
        ANNULUS_FIRST_END,
        &annulus_first_table(&data()),
    );
}
