//! The paint benchmark's table (`examples/paint_bench.rs` writes the JSON,
//! `docs/performance.md` holds the table, `tests/paint_doc.rs` checks they
//! agree).

#![allow(dead_code, reason = "the example and the doc test each use part")]

/// The markdown of a results file.
pub fn render(results: &serde_json::Value) -> String {
    let mut lines = vec![
        format!(
            "Measured at commit {} on {}, {} build of the view, headless Chromium; {} rounds alternating the configurations, {} s each; medians.",
            results["commit"].as_str().unwrap_or(""),
            results["machine"].as_str().unwrap_or(""),
            results["profile"].as_str().unwrap_or(""),
            results["rounds"],
            results["seconds"],
        ),
        String::new(),
        "| world | speed | distinct states painted per second (each round) | median | server steps/s | target (>= 30) |".into(),
        "|---|---|---|---|---|---|".into(),
    ];
    for row in results["rows"].as_array().into_iter().flatten() {
        let runs: Vec<f64> = row["painted_per_second"]
            .as_array()
            .into_iter()
            .flatten()
            .filter_map(|v| v.as_f64())
            .collect();
        let median = median(&runs);
        let each: Vec<String> = runs.iter().map(|r| format!("{r:.1}")).collect();
        lines.push(format!(
            "| {} | {} | {} | {median:.1} | {:.0} | {} |",
            row["world"].as_str().unwrap_or(""),
            row["speed"].as_str().unwrap_or(""),
            each.join(", "),
            row["steps_per_second"].as_f64().unwrap_or(0.0),
            if median >= 30.0 { "met" } else { "NOT met" },
        ));
    }
    lines.join("\n") + "\n"
}

/// The median of `values` (0 for none).
pub fn median(values: &[f64]) -> f64 {
    let mut v = values.to_vec();
    v.sort_by(f64::total_cmp);
    match v.len() {
        0 => 0.0,
        n if n % 2 == 1 => v[n / 2],
        n => (v[n / 2 - 1] + v[n / 2]) / 2.0,
    }
}
