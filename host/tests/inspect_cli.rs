//! `host policy inspect` on a table searched on several shapes names them
//! all (from the search log whose result is that table), where the blob
//! records only the first.

use std::path::Path;
use std::process::Command;

fn inspect(dir: &Path, args: &[&str]) -> String {
    let out = Command::new(env!("CARGO_BIN_EXE_host"))
        .current_dir(dir)
        .args(["policy", "inspect"])
        .args(args)
        .output()
        .unwrap();
    assert!(out.status.success());
    String::from_utf8(out.stdout).unwrap()
}

#[test]
fn a_table_searched_on_seven_shapes_says_which() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("..");
    let text = inspect(&root, &["--summary", "policies/robot-general.policy"]);
    assert!(
        text.contains(
            "searched   on 7 fields: annulus, thesis:T, thesis:L, thesis:X, letter:T, letter:L, letter:X"
        ),
        "{text}"
    );
    // the line follows the field the blob records
    let field = text.lines().position(|l| l.starts_with("field")).unwrap();
    assert!(text.lines().nth(field + 1).unwrap().starts_with("searched"));

    // a log beside the blob counts only if its result is the blob's table
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    std::fs::copy(
        root.join("policies/robot-general.policy"),
        d.join("g.policy"),
    )
    .unwrap();
    let log = std::fs::read_to_string(
        root.join("docs/policy-search/runs/general-from-drawn-X-robust-more.search.json"),
    )
    .unwrap();
    let mut other: serde_json::Value = serde_json::from_str(&log).unwrap();
    other["result"][0] = serde_json::json!(other["result"][0].as_u64().unwrap() ^ 1);
    std::fs::write(
        d.join("general-from-drawn-X-robust-more.search.json"),
        other.to_string(),
    )
    .unwrap();
    let text = inspect(d, &["--summary", "g.policy"]);
    assert!(!text.contains("searched"), "{text}");
    std::fs::write(d.join("general-from-drawn-X-robust-more.search.json"), log).unwrap();
    let text = inspect(d, &["g.policy"]);
    assert!(text.contains("searched   on 7 fields"), "{text}");

    // a trained table has no search log
    let text = inspect(&root, &["--summary", "policies/robot-annulus-8bit.policy"]);
    assert!(!text.contains("searched"), "{text}");
}
