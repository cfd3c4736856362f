//! Campaigns (`host experiment FILE` of a file with `[[stages]]`): a small
//! one runs end to end and resumes; the shipped campaign names the shipped
//! tables; bad keys are named.

use host::experiment::campaign::file::{Campaign, Work};
use std::path::{Path, PathBuf};
use std::process::Command;

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// Two searches on the TV, the second continuing from the first, and an
/// evaluation of both beside OC.
const SMALL: &str = r#"
title = "small"
[defaults]
sensors = "robot"
arena = "tv75"
noise = 1.0
seed = 3
learn = { hasher = "original" }
distil_oc = 500000
population = 3
elites = 1
fitness_seeds = 1
fitness_steps = 50000
validation_seeds = 1
validation_steps = 50000
keep = 0.9
rate = 0.5
floor = 0.01
threads = 1

[[stages]]
name = "first"
kind = "search"
label = "the first search"
field = "thesis:V"
start = "oc"
generations = 2

[[stages]]
name = "second"
kind = "search"
from = "first"
field = "thesis:V"
seed = 4
generations = 2

[[stages]]
name = "report"
kind = "evaluate"
steps = 100000
seeds = [901, 902]
fields = ["thesis:V", "letter:I"]
controllers = ["oc", "first", "second"]
"#;

/// `host experiment FILE --out OUT --scale 0.02`'s stdout.
fn run_campaign(file: &Path, out: &Path, extra: &[&str]) -> String {
    let output = Command::new(env!("CARGO_BIN_EXE_host"))
        .arg("experiment")
        .arg(file)
        .arg("--out")
        .arg(out)
        .args(["--scale", "0.02"])
        .args(extra)
        .output()
        .unwrap();
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    String::from_utf8(output.stdout).unwrap()
}

/// Every output file of the small campaign, with its bytes.
fn outputs(out: &Path) -> Vec<(String, Vec<u8>)> {
    let mut files: Vec<(String, Vec<u8>)> = std::fs::read_dir(out)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.is_file())
        .map(|p| {
            let name = p.file_name().unwrap().to_string_lossy().into_owned();
            (name, std::fs::read(&p).unwrap())
        })
        .collect();
    files.sort();
    files
}

#[test]
fn a_campaign_of_two_searches_and_an_evaluation_runs_at_a_tiny_scale_and_a_rerun_skips_every_finished_stage(
) {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("small.toml");
    std::fs::write(&file, SMALL).unwrap();
    let out = dir.path().join("out");
    let first = run_campaign(&file, &out, &[]);
    assert!(first.contains("3 stages run, 0 skipped"), "{first}");
    let files = outputs(&out);
    let names: Vec<&str> = files.iter().map(|(n, _)| n.as_str()).collect();
    for name in [
        "first.policy",
        "first.search.json",
        "second.policy",
        "second.search.json",
        "report.jsonl",
    ] {
        assert!(names.contains(&name), "{name} in {names:?}");
    }
    // the second search started from the first's table
    let log: serde_json::Value = serde_json::from_slice(
        &files
            .iter()
            .find(|(n, _)| n == "second.search.json")
            .unwrap()
            .1,
    )
    .unwrap();
    assert_eq!(
        log["search"]["start"].as_str().unwrap(),
        out.join("first.policy").display().to_string()
    );
    assert_eq!(
        log["generations"].as_array().unwrap().len(),
        1,
        "2 x 0.02, at least 1"
    );
    // OC and both tables on the V, OC alone on the I: one line per seed
    let report = String::from_utf8(
        files
            .iter()
            .find(|(n, _)| n == "report.jsonl")
            .unwrap()
            .1
            .clone(),
    )
    .unwrap();
    let lines: Vec<serde_json::Value> = report
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    assert_eq!(lines.len(), 2 * 3 + 2, "{report}");
    assert!(lines
        .iter()
        .all(|l| l["steps"] == 2000 && l["formations"].is_u64()));
    assert_eq!(
        lines
            .iter()
            .filter(|l| l["field"] == "letter:I")
            .map(|l| l["controller"].as_str().unwrap())
            .collect::<Vec<_>>(),
        ["oc", "oc"]
    );

    let again = run_campaign(&file, &out, &[]);
    assert!(again.contains("0 stages run, 3 skipped"), "{again}");
    assert_eq!(outputs(&out), files, "a rerun changes nothing");

    // a stage killed before it finished (no hash) runs again, alone, and
    // writes what it wrote before
    std::fs::remove_file(out.join("report.done")).unwrap();
    let resumed = run_campaign(&file, &out, &[]);
    assert!(resumed.contains("1 stages run, 2 skipped"), "{resumed}");
    assert_eq!(outputs(&out), files);

    // --stages runs the stage named, and the stages it continues from
    let fresh = dir.path().join("fresh");
    let only = run_campaign(&file, &fresh, &["--stages", "second"]);
    assert!(only.contains("2 stages run, 0 skipped"), "{only}");
    assert!(!fresh.join("report.jsonl").exists());
    let same = |name: &str| std::fs::read(fresh.join(name)).unwrap();
    assert_eq!(
        same("second.policy"),
        files.iter().find(|(n, _)| n == "second.policy").unwrap().1
    );
}

#[test]
fn every_shipped_tables_stage_names_the_shipped_blobs_run_hasher_and_field_and_every_learned_table_is_shipped_by_one(
) {
    let mut shipped = Vec::new();
    let mut files: Vec<PathBuf> = std::fs::read_dir(root().join("experiments/campaigns"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    files.sort();
    for file in files {
        let campaign = Campaign::load(&file).unwrap();
        for stage in &campaign.stages {
            let Some(ships) = &stage.ships else { continue };
            let world = match &stage.work {
                Work::Search { world, .. } | Work::Train { world } => world,
                other => panic!("{}: ships from {other:?}", stage.name),
            };
            let blob = sim::control::policy_file::read(&root().join(ships)).unwrap();
            let what = format!("{} ({})", ships.display(), file.display());
            assert_eq!(blob.provenance().name.as_str(), stage.name, "{what}");
            assert_eq!(blob.hasher(), world.learn.hasher.0, "{what}");
            assert_eq!(
                blob.provenance().field.as_str(),
                world.world.field.to_string(),
                "{what}"
            );
            shipped.push(ships.file_name().unwrap().to_string_lossy().into_owned());
        }
    }
    // every table in policies/ but the hand-written one
    let mut learned: Vec<String> = std::fs::read_dir(root().join("policies"))
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".policy") && n != "oc-heuristic.policy")
        .collect();
    learned.sort();
    shipped.sort();
    assert_eq!(shipped, learned);
}

#[test]
fn an_evaluate_stage_runs_a_policy_file_on_every_field_generated_shapes_included() {
    let dir = tempfile::tempdir().unwrap();
    let policy = root().join("policies/robot-general.policy");
    let file = dir.path().join("files.toml");
    std::fs::write(
        &file,
        format!(
            r#"
title = "a shipped table on two shapes"
[defaults]
sensors = "robot"
arena = "tv75"
[[stages]]
name = "report"
kind = "evaluate"
steps = 100000
seeds = [901]
fields = ["thesis:V", "gen:ring:0"]
controllers = [{:?}]
"#,
            policy.display().to_string()
        ),
    )
    .unwrap();
    let out = dir.path().join("out");
    run_campaign(&file, &out, &[]);
    let report = std::fs::read_to_string(out.join("report.jsonl")).unwrap();
    let lines: Vec<serde_json::Value> = report
        .lines()
        .map(|l| serde_json::from_str(l).unwrap())
        .collect();
    let runs: Vec<(&str, &str)> = lines
        .iter()
        .map(|l| {
            (
                l["field"].as_str().unwrap(),
                l["controller"].as_str().unwrap(),
            )
        })
        .collect();
    let controller = format!("policy:{}", policy.display());
    assert_eq!(
        runs,
        [
            ("thesis:V", controller.as_str()),
            ("gen:ring:0", controller.as_str())
        ]
    );
}

#[test]
fn a_stage_continuing_from_a_later_or_unknown_stage_is_refused() {
    let later = SMALL.replace("from = \"first\"", "from = \"report\"");
    let error = format!("{:#}", Campaign::parse("small", &later).unwrap_err());
    assert!(
        error.contains("stage \"second\"") && error.contains("from = \"report\""),
        "{error}"
    );
}

#[test]
fn a_stage_with_a_bad_key_gets_an_error_naming_the_file_the_stage_and_the_key() {
    let dir = tempfile::tempdir().unwrap();
    let file = dir.path().join("typo.toml");
    std::fs::write(
        &file,
        SMALL.replace("seed = 4\n", "seed = 4\ngeneratons = 3\n"),
    )
    .unwrap();
    let error = format!("{:#}", Campaign::load(&file).unwrap_err());
    assert!(
        error.contains(&file.display().to_string())
            && error.contains("stage \"second\"")
            && error.contains("generatons"),
        "{error}"
    );
    // a search setting in a stage that is no search
    std::fs::write(
        &file,
        SMALL.replace("steps = 100000\n", "steps = 100000\npopulation = 4\n"),
    )
    .unwrap();
    let error = format!("{:#}", Campaign::load(&file).unwrap_err());
    assert!(
        error.contains("stage \"report\"") && error.contains("population"),
        "{error}"
    );
    // a search setting left to `host search`'s default
    std::fs::write(&file, SMALL.replace("keep = 0.9\n", "")).unwrap();
    let error = format!("{:#}", Campaign::load(&file).unwrap_err());
    assert!(
        error.contains("stage \"first\"") && error.contains("keep"),
        "{error}"
    );
}

#[test]
fn a_publish_stage_writes_the_results_and_the_pages_tables_which_the_report_then_checks() {
    let dir = tempfile::tempdir().unwrap();
    let campaigns = dir.path().join("experiments/campaigns");
    std::fs::create_dir_all(&campaigns).unwrap();
    // scale 1 (a publish stage publishes nothing at another), tiny budgets
    let text = SMALL
        .replace("distil_oc = 500000", "distil_oc = 2000")
        .replace("fitness_steps = 50000", "fitness_steps = 1000")
        .replace("validation_steps = 50000", "validation_steps = 1000")
        .replace("generations = 2", "generations = 1")
        .replace("steps = 100000", "steps = 1000")
        + r#"
[[stages]]
name = "publish"
kind = "publish"
dir = "small"
evaluations = ["report"]
report_fields = ["thesis:V", "letter:I"]
targets = { ratio_field = "thesis:V", ratio = 1.15, least = 50.0, oc_at_least = 20.0 }
"#;
    let file = campaigns.join("small.toml");
    std::fs::write(&file, text).unwrap();
    let docs = dir.path().join("docs");
    std::fs::create_dir_all(&docs).unwrap();
    let page = "# Small\n\n<!-- results:begin -->\n<!-- results:end -->\nAfter.\n";
    std::fs::write(docs.join("small.md"), page).unwrap();
    let output = Command::new(env!("CARGO_BIN_EXE_host"))
        .current_dir(dir.path())
        .args(["experiment", "experiments/campaigns/small.toml"])
        .output()
        .unwrap();
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    for published in [
        "small/runs/first.policy",
        "small/runs/second.search.json",
        "small/runs/report.jsonl",
        "small/results.json",
    ] {
        assert!(docs.join(published).exists(), "{published}");
    }
    let rendered = std::fs::read_to_string(docs.join("small.md")).unwrap();
    assert!(
        rendered.contains("| thesis:V | orbital construction | ")
            && rendered.contains("| thesis:V | the first search | ")
            && rendered.contains("| second | thesis:V | robot | 1 | original | ")
            && rendered.ends_with("<!-- results:end -->\nAfter.\n"),
        "{rendered}"
    );
    let checked = host::experiment::campaign::publish::check_pages(&docs).unwrap();
    assert_eq!(checked, [docs.join("small.md")]);
    // a page whose tables are not the results' fails the check
    std::fs::write(
        docs.join("small.md"),
        rendered.replace("| thesis:V | orbital construction | ", "| thesis:V | OC | "),
    )
    .unwrap();
    let error = host::experiment::campaign::publish::check_pages(&docs)
        .unwrap_err()
        .to_string();
    assert!(error.contains("small.md"), "{error}");
}

#[test]
fn stages_are_refused_for_an_experiment_and_trial_flags_for_a_campaign() {
    let host = |args: &[&str]| {
        let output = Command::new(env!("CARGO_BIN_EXE_host"))
            .current_dir(root())
            .args(args)
            .output()
            .unwrap();
        assert!(!output.status.success(), "{args:?}");
        String::from_utf8(output.stderr).unwrap()
    };
    let error = host(&["experiment", "annulus", "--stages", "x"]);
    assert!(error.contains("--stages"), "{error}");
    let error = host(&[
        "experiment",
        "experiments/campaigns/policy-search.toml",
        "--seed",
        "3",
    ]);
    assert!(
        error.contains("--seed") && error.contains("policy-search"),
        "{error}"
    );
}
