//! The training view's cost table (`examples/train_view_bench.rs` writes
//! the JSON, `docs/performance.md` holds the table, `tests/train_view_doc.rs`
//! checks they agree).

#![allow(dead_code, reason = "the example and the doc test each use part")]

/// The target: with no viewer, `--view` costs at most 5 % of the steps per second.
pub const TARGET: f64 = 0.95;

/// The markdown of a results file.
pub fn render(results: &serde_json::Value) -> String {
    let rate = |row: &serde_json::Value| -> Vec<f64> {
        row["steps_per_second"]
            .as_array()
            .into_iter()
            .flatten()
            .filter_map(|v| v.as_f64())
            .collect()
    };
    let rows = results["rows"].as_array().cloned().unwrap_or_default();
    let base = rows.first().map(|r| median(&rate(r))).unwrap_or(f64::NAN);
    let mut lines = vec![
        format!(
            "Measured at commit {} on {}, release build, `host train --steps {} --seed 1` (annulus, disc senses); {} rounds, each running the configurations one after another in a rotated order; medians.",
            results["commit"].as_str().unwrap_or(""),
            results["machine"].as_str().unwrap_or(""),
            results["steps"],
            results["rounds"],
        ),
        String::new(),
        "| run | training steps per second (each round) | median | of `host train` | target |".into(),
        "|---|---|---|---|---|".into(),
    ];
    for (k, row) in rows.iter().enumerate() {
        let runs = rate(row);
        let median = median(&runs);
        let each: Vec<String> = runs.iter().map(|r| format!("{r:.0}")).collect();
        let ratio = median / base;
        let target = match row["target"].as_bool() {
            Some(true) if ratio >= TARGET => "at least 0.95: met",
            Some(true) => "at least 0.95: NOT met",
            _ => "",
        };
        lines.push(format!(
            "| {} | {} | {median:.0} | {} | {target} |",
            row["run"].as_str().unwrap_or(""),
            each.join(", "),
            if k == 0 {
                "1".into()
            } else {
                format!("{ratio:.3}")
            },
        ));
    }
    lines.join("\n")
}

/// The median of `values` (the mean of the middle two for an even count).
pub fn median(values: &[f64]) -> f64 {
    let mut v = values.to_vec();
    v.sort_by(f64::total_cmp);
    match v.len() {
        0 => f64::NAN,
        n if n % 2 == 1 => v[n / 2],
        n => (v[n / 2 - 1] + v[n / 2]) / 2.0,
    }
}
