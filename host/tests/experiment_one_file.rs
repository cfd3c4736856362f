//! A new experiment is one file: a TOML with a `page` key, run at a tiny
//! scale by path and rendered by `host experiment report --experiments
//! DIR`, its page and its group's index written with no template, no list
//! and no script to edit.

use assert_cmd::Command;

fn host() -> Command {
    Command::cargo_bin("host").unwrap()
}

const TINY: &str = r#"title = "A tiny experiment"
page = "tiny-results"
trials = 2

[defaults]
field = "annulus"
robots = 3
pucks = 20
steps = 1_500

[[arms]]
name = "OC"
controller = "oc"

[[arms]]
name = "random"
controller = "random"
"#;

#[test]
fn a_new_experiment_file_runs_at_a_tiny_scale_and_renders_its_page() {
    let tmp = tempfile::tempdir().unwrap();
    let (experiments, docs) = (tmp.path().join("experiments"), tmp.path().join("docs"));
    // as experiments/ is laid out: campaigns (none here) in campaigns/
    std::fs::create_dir_all(experiments.join("campaigns")).unwrap();
    let file = experiments.join("tiny.toml");
    std::fs::write(&file, TINY).unwrap();
    let out = docs.join("tiny-results/tiny");
    let run = host()
        .arg("experiment")
        .arg(&file)
        .arg("--out")
        .arg(&out)
        .output()
        .unwrap();
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    // the file's trial count: 2 per arm
    for arm in ["OC", "random"] {
        let trials = std::fs::read_dir(out.join("trials").join(arm))
            .unwrap()
            .count();
        assert_eq!(trials, 2, "{arm}");
    }
    let report = |extra: &[&str]| {
        host()
            .current_dir(tmp.path())
            .args([
                "experiment",
                "report",
                "--docs",
                "docs",
                "--experiments",
                "experiments",
            ])
            .args(extra)
            .output()
            .unwrap()
    };
    let written = report(&[]);
    assert!(
        written.status.success(),
        "{}",
        String::from_utf8_lossy(&written.stderr)
    );
    let page = std::fs::read_to_string(docs.join("tiny-results/tiny.md")).unwrap();
    assert!(page.contains("# A tiny experiment"), "{page}");
    assert!(
        page.contains("| OC |") && page.contains("| random |"),
        "{page}"
    );
    assert!(page.contains("host experiment tiny"), "{page}");
    let index = std::fs::read_to_string(docs.join("tiny-results.md")).unwrap();
    assert!(index.contains("(tiny-results/tiny.md)"), "{index}");
    let checked = report(&["--check"]);
    assert!(
        checked.status.success(),
        "{}",
        String::from_utf8_lossy(&checked.stderr)
    );
    // a page edited by hand is not what the trials give
    std::fs::write(docs.join("tiny-results/tiny.md"), format!("{page}edited\n")).unwrap();
    let stale = report(&["--check"]);
    assert!(!stale.status.success());
    assert!(String::from_utf8_lossy(&stale.stderr).contains("tiny.md"));
}
